"""One study run per output folder: a second run is refused with the holder named, and the
lock of a killed run is taken over."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from stewartid.errors import ConfigError
from stewartid.studies.lock import LOCK_NAME, study_lock

HOLD = ("import sys, time; from stewartid.studies.lock import study_lock\n"
        "with study_lock(sys.argv[1]):\n"
        "    print('held', flush=True); time.sleep(60)\n")


def _holding(folder: Path) -> subprocess.Popen:
    process = subprocess.Popen([sys.executable, "-c", HOLD, str(folder)],
                               stdout=subprocess.PIPE, text=True)
    assert process.stdout.readline().strip() == "held"
    return process


@pytest.mark.slow
def test_a_second_run_is_refused_naming_the_holder(tmp_path):
    holder = _holding(tmp_path)
    try:
        with pytest.raises(ConfigError, match=f"process {holder.pid}"), study_lock(tmp_path):
            pass
    finally:
        holder.kill()
        holder.wait()


@pytest.mark.slow
def test_the_lock_of_a_killed_run_is_taken_over(tmp_path):
    holder = _holding(tmp_path)
    os.kill(holder.pid, signal.SIGKILL)
    holder.wait()
    assert (tmp_path / LOCK_NAME).exists()  # the file stays; the lock went with the process
    with study_lock(tmp_path) as path:
        assert path.read_text().strip() == str(os.getpid())
    with study_lock(tmp_path):  # released on exit
        pass


@pytest.mark.slow
def test_the_command_refuses_a_locked_folder_in_one_line(tmp_path):
    spec = tmp_path / "study.toml"
    spec.write_text('[study]\nseeds = 1\nduration = 2.0\nmethods = ["ls"]\n')
    out = tmp_path / "out"
    holder = _holding(out)
    try:
        started = time.perf_counter()
        found = subprocess.run([sys.executable, "-m", "stewartid", "study", str(spec), "--out",
                                str(out), "--resume"], capture_output=True, text=True)
    finally:
        holder.kill()
        holder.wait()
    assert found.returncode == 2, found.stderr
    lines = [line for line in found.stderr.splitlines() if line.strip()]
    assert len(lines) == 1 and f"process {holder.pid}" in lines[0], found.stderr
    assert "Traceback" not in found.stderr
    assert time.perf_counter() - started < 30
