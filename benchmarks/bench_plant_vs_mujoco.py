"""Real-time factor of our hydraulic closed-loop plant beside MuJoCo on the same mechanism.

In one run, on the same machine: our plant (``stewartid.simulation``, hydraulic legs, PID
and inner force loop, RK4 at its default 0.5 ms) on the paper's 20 s roll experiment with
Coulomb 5 N m, and MuJoCo on the mechanism of ``stewartid.mujoco.model`` (42 joints closed by six
welds, ideal force actuators, the same servo's PD part in the motors' bias, gimbal damping
and Coulomb ``frictionloss``) along the same command: a bare ``mj_step`` loop that only
copies the precomputed command into ``ctrl``, with RK4 and implicitfast at 0.5 ms.

Run: ``python benchmarks/bench_plant_vs_mujoco.py [--repeats N]``. Needs the ``mujoco``
extra (``pip install "stewartid[mujoco]"``).
"""

from __future__ import annotations

import argparse
import os
import platform as host
import time

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import numpy as np  # noqa: E402

from stewartid.mujoco import model as mjcf  # noqa: E402
from stewartid.mujoco import state as mujoco_state
from stewartid.platform import load_platform  # noqa: E402
from stewartid.simulation import paper_experiments, simulate_experiment  # noqa: E402

DURATION = 20.0
MUJOCO_STEP = 5e-4


def cpu_model() -> str:
    """CPU model name from /proc/cpuinfo, or what the platform module knows."""
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return host.processor() or host.machine()


def time_plant(paper, excitation, repeats: int) -> tuple[float, float]:
    """Best wall and CPU times (s) of one 20 s hydraulic experiment (commands, loop, FK)."""
    simulate_experiment(paper, excitation, 0.5)  # numba compilation / cache load
    best, best_cpu = np.inf, np.inf
    for _ in range(repeats):
        start, start_cpu = time.perf_counter(), time.process_time()
        simulate_experiment(paper, excitation, DURATION)
        best = min(best, time.perf_counter() - start)
        best_cpu = min(best_cpu, time.process_time() - start_cpu)
    return best, best_cpu


def time_mujoco(paper, excitation, integrator: str, repeats: int,
                coulomb: bool = True) -> tuple[float, float, float, float]:
    """Best wall time (s) of the bare mj_step loop over 20 s, with the motion's size.

    Returns
    -------
    wall, cpu : float
        s, the stepping loop only.
    setup : float
        s, command table (inverse kinematics and feed-forward) and compilation.
    motion : float
        Largest roll angle (rad) seen every 0.125 s, to show the motion was carried out.
    """
    import mujoco

    start = time.perf_counter()
    model = mjcf.load_model(paper, integrator=integrator, timestep=MUJOCO_STEP, coulomb=coulomb)
    mujoco_state.add_leg_servo(paper, model)
    data = mujoco.MjData(model)
    n = int(round(DURATION / MUJOCO_STEP))
    q_cmd, qd_cmd, _ = excitation.evaluate((np.arange(n) + 0.5) * MUJOCO_STEP)
    ctrl = mujoco_state.servo_controls(paper, q_cmd, qd_cmd)
    q0, qd0, _ = excitation.evaluate(np.zeros(1))
    setup = time.perf_counter() - start
    best, best_cpu, motion = np.inf, np.inf, 0.0
    quat = mujoco_state.Indices(model).platform_qpos + 3
    for _ in range(repeats):
        mujoco.mj_resetData(model, data)
        mujoco_state.set_state(paper, model, data, q0[0], qd0[0])
        step = mujoco.mj_step
        seen = []
        start, start_cpu = time.perf_counter(), time.process_time()
        for k in range(n):
            data.ctrl[:] = ctrl[k]
            step(model, data)
            if k % 250 == 0:  # a 7-value copy, 160 times: nothing beside the steps
                seen.append(data.qpos[quat:quat + 4].copy())
        best = min(best, time.perf_counter() - start)
        best_cpu = min(best_cpu, time.process_time() - start_cpu)
        motion = max(abs(2.0 * np.arcsin(x[1])) for x in seen)  # roll (small angles)
    return best, best_cpu, setup, motion


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=2, help="runs of each, best kept")
    args = parser.parse_args()
    import mujoco

    paper = load_platform("paper").replace(friction__coulomb=5.0)
    excitation = paper_experiments(paper)[3]
    print(f"machine: {cpu_model()}, {os.cpu_count()} logical cores, "
          f"Python {host.python_version()}, MuJoCo {mujoco.__version__}")
    print("load average (1, 5, 15 min): " + ", ".join(f"{x:.2f}" for x in os.getloadavg()))
    print(f"load: paper platform, Coulomb 5 N m, '{excitation.name}' ({DURATION:g} s)")
    rows = []
    wall, cpu = time_plant(paper, excitation, args.repeats)
    rows.append(("stewartid plant, hydraulic, RK4 0.5 ms (whole experiment)", wall, cpu))
    for coulomb in (True, False):
        for integrator in ("RK4", "implicitfast"):
            wall, cpu, setup, motion = time_mujoco(paper, excitation, integrator, args.repeats,
                                              coulomb)
            friction = "frictionloss 5 N m" if coulomb else "no Coulomb rows"
            rows.append((f"MuJoCo {integrator} {MUJOCO_STEP * 1e3:g} ms, ideal actuators, "
                         f"{friction} (setup {setup:.2f} s, max |rx| {motion * 1e3:.1f} mrad)",
                         wall, cpu))
    print(f"{'':97s}{'wall':>8s} {'RTF':>6s} {'CPU':>7s} {'RTF':>6s}")
    for label, wall, cpu in rows:
        print(f"{label:97s}{wall:7.2f}s {DURATION / wall:5.1f}x {cpu:6.2f}s {DURATION / cpu:5.1f}x")
    print("RTF: simulated seconds per second (real-time factor), by wall-clock and CPU time.")


if __name__ == "__main__":
    main()
