"""Where the pose noise biases the rotational inertia: least squares and Method B fitted to noisy
copies of one set of noise-free logs, with the Coulomb signs' rates taken three ways.

"log": as the methods take them (the shortest Savitzky-Golay window whose noise is within the
limit of the rates' RMS, from the noisy pose); "true, noisy window": from the noise-free pose,
differentiated with the window the noisy pose selected; "true": from the noise-free pose with
its own window (the shortest) and, for Method B's soft signs, no noise. Every other term
(regressors, Jacobians, gravity, remainder, sampling check) stays the noisy log's. If "true,
noisy window" carries the bias and "true" does not, the bias is the window's rounding of the
reversals, not the noise in the signs.

The noise: the reference sensor noise of the platform per seed, as ``coverage_study.py`` adds
it, or with ``--pose-only`` its pose part alone (the force noise set to zero: the bias with less
spread). Printed per method and variant: the mean error (%) of Mt(1,1)..(6,6) over the seeds,
its standard error of the mean, and the largest |error| / standard error of the fits; with
``--per-seed`` also each seed's largest |error| of the Mt diagonal (%) and the standard error of
Mt(4,4) (% of nominal), the figures of the acceptance's worst seed.

Usage::

    python benchmarks/pose_noise_bias.py --logs DIR --platform paper|FILE [--seeds 6]
        [--pose-only] [--methods ls,wavelet] [--per-seed]
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import time
from pathlib import Path
from unittest import mock

import numpy as np

from stewartid.datasets.dataset import read_datasets
from stewartid.identification import least_squares
from stewartid.identification.registry import create_identifier
from stewartid.identification.wavelet import detection
from stewartid.model.linearization import nominal_matrices
from stewartid.platform import load_platform
from stewartid.signals.differentiation import differentiate
from stewartid.signals.sign_rates import SIGN_ORDER, coulomb_sign_rates
from stewartid.simulation import degrade
from stewartid.simulation.sensors import reference_noise

VARIANTS = ("log", "true, noisy window", "true")


def noise_free(poses: list[np.ndarray], q: np.ndarray) -> np.ndarray:
    """The noise-free pose of the record ``q`` is (the sampling check refits thinned copies)."""
    steps = [max(1, round(len(p) / len(q))) for p in poses]
    return min((p[::k][:len(q)] for p, k in zip(poses, steps, strict=True)),
               key=lambda p: np.inf if len(p) != len(q) else float(np.abs(p - q).mean()))


@contextlib.contextmanager
def sign_rates_from(variant: str, poses: list[np.ndarray]):
    """Both methods' Coulomb sign rates as ``variant`` says; ``poses`` the noise-free ones."""
    if variant == "log":
        yield
        return

    def rates(q, sample_rate, window, pose_noise, limit=None, shorter=0):
        limit = {"shorter": shorter} | ({} if limit is None else {"noise_limit": limit})
        true = noise_free(poses, q)
        if variant == "true":
            return coulomb_sign_rates(true, sample_rate, window, np.zeros((6, 6)), **limit)
        chosen = coulomb_sign_rates(q, sample_rate, window, pose_noise, **limit)[1]
        return differentiate(true, sample_rate, chosen, SIGN_ORDER, (1,))[0], chosen

    # noise-free rates carry no noise for Method B's soft signs either
    level = (lambda *args, **kwargs: np.zeros(36)) if variant == "true" else detection.joint_rate_noise
    with (mock.patch.object(detection, "coulomb_sign_rates", rates),
          mock.patch.object(detection, "joint_rate_noise", level),
          mock.patch.object(least_squares, "coulomb_sign_rates", rates)):
        yield


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--logs", type=Path, required=True, help="noise-free exp*.csv")
    parser.add_argument("--platform", required=True, help="paper or a platform TOML")
    parser.add_argument("--seeds", type=int, default=6)
    parser.add_argument("--pose-only", action="store_true", help="no force noise")
    parser.add_argument("--methods", default="ls,wavelet")
    parser.add_argument("--per-seed", action="store_true",
                        help="also each seed's largest Mt diagonal error and Mt(4,4)'s SE")
    args = parser.parse_args()
    platform = load_platform(args.platform)
    clean = read_datasets(sorted(args.logs.glob("exp*.csv")), platform)
    poses = [d.pose for d in clean]
    truth = np.diag(nominal_matrices(platform)[0])
    sensors = reference_noise(platform)
    if args.pose_only:
        sensors = dataclasses.replace(sensors, force_noise=0.0)
    methods = args.methods.split(",")
    errors = {(m, v): [] for m in methods for v in VARIANTS}
    scores = {(m, v): [] for m in methods for v in VARIANTS}
    spreads = {(m, v): [] for m in methods for v in VARIANTS}
    start, cpu = time.perf_counter(), time.process_time()
    for seed in range(args.seeds):
        data = [degrade(d, platform, sensors, np.random.default_rng(seed + 101 * k))
                for k, d in enumerate(clean)]
        for method in methods:
            for variant in VARIANTS:
                with sign_rates_from(variant, poses):
                    result = create_identifier(method).fit(data, platform).result_
                fitted = np.diag(result.M)
                errors[method, variant].append(100 * (fitted - truth) / truth)
                scores[method, variant].append((fitted - truth) / np.diag(result.std_errors_M))
                spreads[method, variant].append(100 * result.std_errors_M[3, 3] / truth[3])
    for (method, variant), values in errors.items():
        values = np.array(values)
        sem = values.std(axis=0, ddof=1) / np.sqrt(len(values)) if len(values) > 1 else 0 * truth
        worst = float(np.max(np.abs(scores[method, variant])))
        print(f"{method:8s} {variant:20s} Mt diagonal mean % "
              + " ".join(f"{m:+.2f}±{s:.2f}" for m, s in zip(values.mean(axis=0), sem, strict=True))
              + f" | worst {worst:.1f} SE")
        if args.per_seed:
            print(" " * 29 + "per seed: largest |Mt diagonal error| % (SE of Mt(4,4) %) "
                  + " ".join(f"{np.max(np.abs(e)):.2f} ({s:.2f})"
                             for e, s in zip(values, spreads[method, variant], strict=True)))
    print(f"{time.perf_counter() - start:.0f} s wall, {time.process_time() - cpu:.0f} s CPU")


if __name__ == "__main__":
    main()
