"""Benchmark of the platform model: one forward-dynamics evaluation, and vectorised inverse
kinematics with Jacobians over 100 000 poses.

Run: ``python benchmarks/bench_model.py`` (prints a Markdown table for docs/benchmarks.md).
"""

from __future__ import annotations

import platform as host
import time

import numpy as np
from numba import njit

from stewartid.model import compiled
from stewartid.model.dynamics import inverse_dynamics
from stewartid.model.kinematics import inverse_kinematics, joint_rate_jacobians, leg_jacobian
from stewartid.platform import load_platform


@njit(cache=True)
def _repeat_forward_dynamics(params, upper, base, q, qd, forces, n):
    acc = 0.0
    for _ in range(n):
        acc += compiled.forward_dynamics_sample(params, upper, base, q, qd, forces, 1e-4, True)[0]
    return acc


def best_of(function, repeats=5):
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return min(times)


def main() -> None:
    paper = load_platform("paper").replace(friction__coulomb=5.0)
    args = (paper.parameters(), paper.upper_joints, paper.base_joints)
    rng = np.random.default_rng(0)
    q = paper.neutral_pose + rng.uniform(-0.05, 0.05, 6)
    qd = rng.normal(size=6) * 0.05
    forces = inverse_dynamics(paper, q, qd, np.zeros(6))
    compiled.forward_dynamics_sample(*args, q, qd, forces, 1e-4, True)
    _repeat_forward_dynamics(*args, q, qd, forces, 10)

    n = 20_000
    python_call = best_of(lambda: [compiled.forward_dynamics_sample(*args, q, qd, forces, 1e-4, True)
                                   for _ in range(n)]) / n
    compiled_loop = best_of(lambda: _repeat_forward_dynamics(*args, q, qd, forces, n)) / n

    poses = paper.neutral_pose + rng.uniform(-0.1, 0.1, (100_000, 6))
    leg_jacobian(paper, poses[:10])
    ik = best_of(lambda: inverse_kinematics(paper, poses), 3)
    jac = best_of(lambda: leg_jacobian(paper, poses), 3)
    joints = best_of(lambda: joint_rate_jacobians(paper, poses), 3)

    print(f"machine: {host.machine()}, {host.processor() or 'cpu'}, Python {host.python_version()}")
    print("| benchmark | result | target |")
    print("|---|---|---|")
    target = "≤ 20 µs"  # noqa: RUF001
    print(f"| forward dynamics, one evaluation called from Python | {python_call * 1e6:.1f} µs | {target} |")
    print(f"| forward dynamics, compiled loop, per evaluation | {compiled_loop * 1e6:.1f} µs | {target} |")
    print(f"| inverse kinematics, 100 000 poses (numpy) | {ik * 1e3:.0f} ms | — |")
    print(f"| leg Jacobian J_lq, 100 000 poses | {jac * 1e3:.0f} ms | — |")
    print(f"| all model terms incl. 30 joint Jacobians, 100 000 poses | {joints * 1e3:.0f} ms | — |")


if __name__ == "__main__":
    main()
