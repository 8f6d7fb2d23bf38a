"""Time to identify six experiments of 20 s at 1 kHz with the physical model.

Data: our plant with the 2 t payload of ``tests/test_physical_model.py`` (Coulomb 30 N m,
reference sensor noise), every DOF at once in each experiment (a multisine); simulated once
and kept in the temporary folder. BLAS on one thread, as the command line runs it; the best
of three fits after a warm-up, wall and CPU time, in full and payload mode, unconstrained and
physically consistent, with the machine's load average. Run:
``python benchmarks/bench_physical.py``.
"""

from __future__ import annotations

import os
import pickle
import tempfile
import time
from pathlib import Path

import numpy as np
from threadpoolctl import threadpool_limits

from stewartid.physical.estimator import PhysicalIdentifier
from stewartid.platform import load_platform
from stewartid.simulation import (
    DEFAULT_AMPLITUDES,
    Sine,
    multisine_excitation,
    simulate_experiment,
)
from stewartid.simulation.sensors import reference_noise

#: Frequencies (Hz) of the multisine: DOF d of experiment k at HZ[(d + k) % 6].
HZ = (0.3, 0.45, 0.6, 0.75, 0.9, 1.05)
PAYLOAD = {"mass": 2000.0, "com": [-0.20, 0.30, -0.50],
           "inertia": [1800.0, 2200.0, 2600.0, -120.0, 80.0, 160.0]}
DURATION = 20.0
CACHE = Path(tempfile.gettempdir()) / "stewartid-bench-physical.pkl"


def records(loaded):
    """The six records, simulated on the first run and read back afterwards."""
    if CACHE.exists():
        return pickle.loads(CACHE.read_bytes())
    out = []
    for k in range(6):
        sines = [Sine(d, DEFAULT_AMPLITUDES[d] * 0.7, HZ[(d + k) % 6], 0.5 * d + k)
                 for d in range(6)]
        out.append(simulate_experiment(loaded, multisine_excitation(
            loaded, sines, name=f"exp{k + 1}"), DURATION, noise=reference_noise(loaded),
            rng=np.random.default_rng(k))[0])
    CACHE.write_bytes(pickle.dumps(out))
    return out


def best_of(runs, fit):
    """Best wall and CPU time (s) of ``runs`` calls of ``fit``, and its last result."""
    wall, cpu = [], []
    for _ in range(runs):
        start, start_cpu = time.perf_counter(), time.process_time()
        fitted = fit()
        wall.append(time.perf_counter() - start)
        cpu.append(time.process_time() - start_cpu)
    return min(wall), min(cpu), fitted


def main() -> None:
    paper = load_platform("paper")
    loaded = paper.replace(friction__coulomb=30.0,
                           **{f"payload__{key}": value for key, value in PAYLOAD.items()})
    data = records(loaded)
    bare = loaded.replace(payload=None)
    print(f"{len(data)} experiments x {data[0].duration:.0f} s at {data[0].sample_rate:.0f} Hz;"
          f" load average {os.getloadavg()[0]:.1f}")
    print("| mode | fit | wall (s) | CPU (s) | mass (kg) |")
    print("|---|---|---|---|---|")
    with threadpool_limits(limits=1, user_api="blas"):
        for mode, platform in (("full", loaded), ("payload", bare)):
            for consistent in (False, True):
                settings = {"payload": mode == "payload"}
                if consistent:
                    settings["consistent"] = True
                PhysicalIdentifier(**settings).fit(data[:1], platform)  # warm-up
                wall, cpu, fitted = best_of(3, lambda s=settings, p=platform:
                                            PhysicalIdentifier(**s).fit(data, p))
                mass = fitted.parameters_["payload.m" if mode == "payload" else "m"]
                print(f"| {mode} | {'consistent' if consistent else 'unconstrained'} | "
                      f"{wall:.2f} | {cpu:.2f} | {mass:.1f} |")
    print(f"load average after: {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
