"""Cramér-Rao bounds of the physical model on the physical study's motion: what accuracy any
unbiased estimator can reach on the first moments and the friction coefficients.

The information matrix of every base parameter in full mode
(:func:`stewartid.design.physical.information.predict_parameters`): the leg forces' white noise of the
reference sensors, each leg weighted alike (generalized least squares is then the maximum
likelihood estimator), the motion known exactly. Pose noise only adds to it, so every figure
is optimistic for a log. Beside it, the same with the estimator's differentiating kernel
applied to the regressor (what the filtering costs), the worst friction coefficient with the
pose noise's first-order share added too (:mod:`stewartid.design.pose_noise`: what the
design's final prediction gives), and, drawn from the bound's Gaussian
(the parameters independent), the chance that the worst of 8 seeds meets the physical-model
acceptance: first moments within 2 kg m, friction coefficients within 5 %.

Motions: the physical study's 6 x 20 s all-DOF multisine (``physical_study.py``) at S times
the paper's amplitudes and frequencies divided by K (``--motions S:K,...``), on the paper
platform and the example platform with their payloads (``physical_study.PAYLOADS``).

Usage::

    python benchmarks/physical_bound.py [--platforms paper,example] [--motions 1:1,3:3,0.5:0.5,0.333:0.333]
        [--draws 100000]
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import physical_study  # noqa: E402  (a sibling script)

from stewartid.design.multisine import all_dofs_multisine  # noqa: E402
from stewartid.design.physical.information import predict_parameters  # noqa: E402
from stewartid.simulation.sensors import reference_noise  # noqa: E402

#: The acceptance: first moments (kg m) and friction coefficients (%), worst of 8 seeds.
FIRST_MOMENT_TARGET = 2.0
FRICTION_TARGET = 5.0
SEEDS = 8
#: Rate the information is summed at (Hz); the kernel needs 100 Hz or more.
RATE = 200.0


def chance(std: np.ndarray, target: float, draws: int, rng: np.random.Generator) -> float:
    """P(max over SEEDS seeds and the parameters of |N(0, std)| <= target)."""
    worst = np.abs(rng.normal(size=(draws, SEEDS, std.size)) * std).max(axis=(1, 2))
    return float(np.mean(worst <= target))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--platforms", default="paper,example")
    parser.add_argument("--motions", default="1:1,3:3,0.5:0.5,0.333:0.333")
    parser.add_argument("--draws", type=int, default=100_000)
    args = parser.parse_args()
    rng = np.random.default_rng(0)
    print("| platform | S / K | bound: mc_x / mc_y / mc_z (kg m) | with the kernel: mc_z | "
          "bound: worst friction coefficient | with the kernel | with the pose noise too | "
          f"P(8 seeds: first moments <= {FIRST_MOMENT_TARGET:g} kg m) | P(8 seeds: friction "
          f"<= {FRICTION_TARGET:g} %) |")
    print("|---|---|---|---|---|---|---|---|---|")
    for name in args.platforms.split(","):
        platform = physical_study.loaded_platform(name)
        noise = reference_noise(platform)
        for motion in args.motions.split(","):
            scale, slower = (float(x) for x in motion.split(":"))
            design = all_dofs_multisine(120.0, scale, slower)
            found = {}
            # the bound and the kernel's cost with the force noise alone, then the pose's too
            quiet = dataclasses.replace(noise, length_noise=0.0)
            for key, filtered, sensors in ((False, False, quiet), (True, True, quiet),
                                           ("pose", True, noise)):
                prediction = predict_parameters(platform, design, sensors, False, RATE,
                                                filtered=filtered)
                std = dict(zip(prediction.names, prediction.expected_std_errors, strict=True))
                nominal = dict(zip(prediction.names, prediction.nominal, strict=True))
                friction = [n for n in prediction.names
                            if n.startswith(("coulomb[", "viscous[")) and nominal[n] > 0]
                found[key] = (np.array([std["mc_x"], std["mc_y"], std["mc_z"]]),
                                   np.array([100 * std[n] / nominal[n] for n in friction]))
            moments, friction = found[False]
            print(f"| {name} | {scale:g} / {slower:g} | "
                  f"{moments[0]:.2f} / {moments[1]:.2f} / {moments[2]:.2f} | "
                  f"{found[True][0][2]:.2f} | {friction.max():.2f} % | "
                  f"{found[True][1].max():.2f} % | {found['pose'][1].max():.2f} % | "
                  f"{chance(moments, FIRST_MOMENT_TARGET, args.draws, rng):.3g} | "
                  f"{chance(friction, FRICTION_TARGET, args.draws, rng):.3g} |", flush=True)


if __name__ == "__main__":
    main()
