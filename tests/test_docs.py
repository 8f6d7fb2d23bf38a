"""The documentation stays true: every public name has a docstring, every command shown in
README.md and docs/*.md names a command and options that exist, the getting-started page's
commands run as written, and the Python blocks of README.md and the getting-started page run.

Commands of other tools (``dask scheduler``) are not checked. Commands that are templates
(``paper|FILE.toml``, ``[--seeds 120]``, ``exp*.csv``) or long (``stewartid reproduce``,
``design --budget 120``, a study, the install commands) are checked against the command's
options only (install commands: the extras they name exist); the commands of
``docs/getting-started.md`` run in full.
"""

from __future__ import annotations

import importlib
import inspect
import os
import pkgutil
import re
import shlex
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest
import typer.main

import stewartid
from stewartid.cli.application import app

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
COMMAND = typer.main.get_command(app)
FENCE = re.compile(r"^```(\w*)[^\n]*\n(.*?)^```", re.S | re.M)


def blocks(page: Path, languages: tuple[str, ...]) -> list[str]:
    """The fenced code blocks of ``page`` in one of ``languages``, in page order."""
    return [body for language, body in FENCE.findall(page.read_text(encoding="utf-8"))
            if language in languages]


def shell_commands(block: str) -> list[str]:
    """The commands of a shell block: continuation lines joined, prompts and comments dropped,
    ``a && b`` split."""
    text = re.sub(r"\\\n\s*", " ", block)
    out = []
    for line in text.splitlines():
        line = re.sub(r"^\s*\$\s+", "", line).split(" #")[0].strip()
        if line and not line.startswith("#"):
            out.extend(part.strip() for part in line.split("&&"))
    return out


def all_commands() -> list[tuple[str, str]]:
    return [(page.name, command) for page in PAGES
            for block in blocks(page, ("bash", "console", "sh", "shell"))
            for command in shell_commands(block)]


def module_names() -> list[str]:
    return ["stewartid", *(info.name for info in pkgutil.walk_packages(
        stewartid.__path__, prefix="stewartid.")
        if not any(part.startswith("_") for part in info.name.split(".")))]


# -- docstrings ----------------------------------------------------------------------------

@pytest.mark.parametrize("name", module_names())
def test_every_public_name_has_a_docstring(name: str) -> None:
    module = importlib.import_module(name)
    assert (module.__doc__ or "").strip(), f"module {name} has no docstring"
    missing = []
    for public in getattr(module, "__all__", ()):
        value = getattr(module, public)
        if not (inspect.isclass(value) or inspect.isfunction(value) or inspect.ismodule(value)):
            continue  # constants are documented by the #: comment beside them
        doc = (value.__doc__ or "").strip()
        # a dataclass without a docstring gets its signature as __doc__
        if not doc or (inspect.isclass(value) and doc.startswith(f"{value.__name__}(")):
            missing.append(public)
    assert missing == [], f"{name}: public names without a docstring: {missing}"


def test_the_docstring_check_covers_the_packages() -> None:
    names = module_names()
    assert {"stewartid.identification.registry", "stewartid.studies.runner",
            "stewartid.design.optimise", "stewartid.reports.identification.report"} <= set(names)


# -- commands ------------------------------------------------------------------------------

def test_the_pages_show_commands() -> None:
    found = {page for page, _ in all_commands()}
    assert {"README.md", "getting-started.md", "logs.md", "design.md", "studies.md"} <= found


@pytest.mark.parametrize(("page", "command"), all_commands())
def test_a_documented_command_exists_with_its_options(page: str, command: str) -> None:
    words = shlex.split(command.replace("[", " ").replace("]", " "))
    while "=" in words[0] and not words[0].startswith("-"):
        words = words[1:]  # environment assignments
    if words[0] not in ("stewartid", "python", "pip"):
        pytest.skip(f"a command of another tool ({words[0]}): not checked")
    if words[:2] in (["pip", "install"], ["python", "-m"]) and "stewartid" not in words[:3]:
        extras = set(tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
                     ["optional-dependencies"])
        named = re.findall(r"\[(\w+)\]", command)
        assert set(named) <= extras, f"{page}: {command!r} names an extra that does not exist"
        return
    if words[0] == "python" and words[1].endswith(".py"):
        assert (ROOT / words[1]).is_file(), f"{page}: {command!r}: no such script"
        return
    if words[:3] == ["python", "-m", "stewartid"]:
        words = words[2:]
    assert words[0] == "stewartid", f"{page}: not a stewartid command: {command!r}"
    words = words[1:]
    root_options = {option for parameter in COMMAND.params for option in parameter.opts}
    while words and words[0] in root_options:
        words = words[1:]
    name = words[0].split("|")[0]
    assert name in COMMAND.commands, f"{page}: {command!r}: no command {name!r}"
    options = {option for parameter in COMMAND.commands[name].params
               for option in (*parameter.opts, *parameter.secondary_opts)}
    unknown = [word.split("=")[0] for word in words[1:]
               if word.startswith("--") and word.split("=")[0] not in options]
    assert unknown == [], f"{page}: {command!r}: {name} has no option {unknown}"


def run_python(code: str, folder: Path) -> subprocess.CompletedProcess:
    environment = {**os.environ, "PYTHONPATH": os.pathsep.join(
        [str(ROOT / "src"), os.environ.get("PYTHONPATH", "")]), "MPLBACKEND": "Agg"}
    return subprocess.run([sys.executable, "-c", code], cwd=folder, env=environment,
                          capture_output=True, text=True, timeout=600)


@pytest.mark.slow
def test_the_getting_started_commands_run(tmp_path: Path) -> None:
    page = ROOT / "docs" / "getting-started.md"
    commands = [command for block in blocks(page, ("bash",)) for command in shell_commands(block)
                if not command.startswith("pip ")]
    assert [c.split()[1] for c in commands] == ["simulate", "identify", "identify", "methods"]
    for command in commands:
        words = shlex.split(command)
        code = ("import sys; from stewartid.cli import main; "
                f"sys.argv = {words!r}; main({words[1:]!r})")
        done = run_python(code, tmp_path)
        assert done.returncode == 0, f"{command}: {done.stderr[-2000:]}"
    assert (tmp_path / "result.json").is_file()
    assert (tmp_path / "report" / "report.html").is_file()
    assert "trusted:" in done.stdout or (tmp_path / "report" / "report.md").is_file()


@pytest.mark.slow
@pytest.mark.parametrize("page", ["README.md", "docs/getting-started.md"])
def test_the_python_blocks_run(tmp_path: Path, page: str) -> None:
    (code,) = blocks(ROOT / page, ("python",))
    done = run_python(code, tmp_path)
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.strip()
