"""Sensor-noise study: each method's errors against the standard errors it predicts.

Data: the independent simulator's example data set (``tests/data/example_c10``, truth in
``truth.json``) with sensor noise added as on a real hexapod: white noise on the measured
leg lengths (the pose is then the forward kinematics of the noisy lengths) and on the leg
forces (a fraction of each leg's mean force). For every method and seed the script prints
the largest error over the paper's 20 entries (%), and the median and RMS over those entries
of |error| / predicted standard error (a ratio of order one means the standard errors are
honest).

Usage::

    python benchmarks/noise_study.py [--seeds 4] [--scales 0.5,1,2] [--length-noise 20e-6]
        [--force-noise 0.005] [--methods wavelet,fourier,...]
"""

from __future__ import annotations

import argparse
import functools
import json
import time
from pathlib import Path

import numpy as np

from stewartid.datasets.dataset import Dataset, read_datasets
from stewartid.identification.registry import create_identifier
from stewartid.platform import load_platform
from stewartid.reference.published import PAPER_ENTRIES, relative_error_percent
from stewartid.simulation import SensorNoise, degrade

EXAMPLE = Path(__file__).resolve().parents[1] / "tests" / "data" / "example_c10"
#: Method B (default: every interval constant free), with the shared-friction interval
#: constants, with a 0.1 s margin, and with the paper's equations; Method A; least squares;
#: and the oracle (least squares given the true Coulomb force, which no user has).
METHODS = {"fourier": functools.partial(create_identifier, "fourier"),
           "ls": functools.partial(create_identifier, "ls"),
           "wavelet": functools.partial(create_identifier, "wavelet"),
           "wavelet_shared": functools.partial(create_identifier, "wavelet", friction="shared"),
           "wavelet_m01": functools.partial(create_identifier, "wavelet", margin=0.1),
           "wavelet-paper": functools.partial(create_identifier, "wavelet-paper")}


class OracleIdentifier:
    """Least squares given the Coulomb force of the noise-free motion (the efficiency bound a
    friction-immune method is measured against): y - F_coulomb = Mt q_ddot + Bt q_dot + offset
    per experiment, Savitzky-Golay derivatives of the measured pose, standard errors for
    autocorrelated residuals."""

    def __init__(self, clean):
        self.clean = clean

    def fit(self, datasets, platform):
        from stewartid.identification.preparation import prepare
        from stewartid.identification.solvers import solve_least_squares
        from stewartid.model.dynamics import friction_forces
        from stewartid.signals.differentiation import (
            default_window,
            differentiate,
            estimate_frequency,
            trim,
        )

        viscous_only = platform.replace(friction__coulomb=0.0)
        phis, ys = [], []
        for k, (experiment, clean) in enumerate(zip(prepare(datasets, platform), self.clean,
                                                    strict=True)):
            rate = experiment.sample_rate
            window = default_window(estimate_frequency(clean.pose, rate))
            _, qd_true, _ = differentiate(clean.pose, rate, window)
            coulomb = (friction_forces(platform, clean.pose, qd_true)
                       - friction_forces(viscous_only, clean.pose, qd_true))
            _, qd, qdd = differentiate(experiment.q, rate, window)
            cut = trim(window, rate)
            offsets = np.zeros((len(qd), len(datasets)))
            offsets[:, k] = 1.0
            sl = slice(cut, len(qd) - cut)
            phis.append(np.hstack([qdd, qd, offsets])[sl])
            ys.append((experiment.generalized_force - coulomb)[sl])
        solution = solve_least_squares(np.vstack(phis), np.vstack(ys), autocorrelated=True)
        self.M_, self.B_ = solution.theta[:, :6], solution.theta[:, 6:12]
        self.std_errors_ = {"M": solution.theta_std[:, :6], "B": solution.theta_std[:, 6:12]}
        return self


def load_example(folder: Path = EXAMPLE):
    """Platform, datasets and true (Mt, Bt) of the example data set."""
    platform = load_platform(folder / "platform.toml")
    truth = json.loads((folder / "truth.json").read_text())
    datasets = read_datasets(sorted(folder.glob("exp*.csv")), platform)
    return platform, datasets, np.array(truth["Mt"]), np.array(truth["Bt"])


def add_noise(platform, datasets, length_noise: float, force_noise: float, seed: int):
    """Copies of ``datasets`` measured by noisy sensors (:func:`stewartid.simulation.degrade`):
    white noise of ``length_noise`` (m) on the leg lengths, the pose their forward kinematics,
    and of ``force_noise`` times each leg's mean |force| (N) on the forces."""
    rng = np.random.default_rng(seed)
    return [degrade(d, platform, SensorNoise(
        length_noise=length_noise, force_noise=tuple(force_noise * np.abs(d.forces).mean(axis=0))),
        rng) for d in datasets]


def entry_ratios(estimator, M, B, reference=None) -> tuple[np.ndarray, np.ndarray]:
    """Relative errors (%) against (M, B) and |estimate - reference| / standard error over
    the 20 paper entries; ``reference`` (an estimator fitted to noise-free data) isolates the
    noise-induced error from the method's own bias (Method A's Coulomb bias); None: truth."""
    errors, ratios = [], []
    for matrix, i, j in PAPER_ENTRIES:
        est = (estimator.M_ if matrix == "M" else estimator.B_)[i, j]
        true = (M if matrix == "M" else B)[i, j]
        ref = true if reference is None else (reference.M_ if matrix == "M"
                                              else reference.B_)[i, j]
        std = estimator.std_errors_[matrix][i, j]
        errors.append(relative_error_percent(est, true))
        ratios.append(abs(est - ref) / std if std > 0 else np.inf)
    return np.array(errors), np.array(ratios)


def study(methods=tuple(METHODS), seeds=(0, 1, 2, 3), length_noise=20e-6, force_noise=0.005,
          stride=1, datasets=None, scales=(1.0,)):
    """Rows (method, noise scale, seed, largest error %, err/SE ratios, seconds).

    Every method runs on the noise-free records once and on ``seeds`` noisy copies at every
    nonzero multiple in ``scales`` of (``length_noise``, ``force_noise``). Two ratios per row:
    against the truth (``ratios``) and against the same method's noise-free estimate
    (``noise_ratios``, the noise-induced error the standard errors are meant to predict).

    ``stride`` keeps every stride-th sample of the records (shorter runs for tests).
    """
    platform, clean, M, B = load_example()
    if stride > 1:
        clean = [Dataset(t=d.t[::stride], pose=d.pose[::stride], lengths=d.lengths[::stride],
                         forces=d.forces[::stride], name=d.name) for d in clean]
    rows = []
    references = {}
    cases = [(0.0, [None])] + [(float(scale), list(seeds)) for scale in scales
                               if scale > 0 and (length_noise or force_noise)]
    for scale, case_seeds in cases:
        for seed in case_seeds:
            data = clean if seed is None else add_noise(
                platform, clean, scale * length_noise, scale * force_noise, seed)
            for method in methods:
                start = time.perf_counter()
                factory = (functools.partial(OracleIdentifier, clean) if method == "oracle"
                           else METHODS[method])
                estimator = factory().fit(data, platform)
                seconds = time.perf_counter() - start
                if seed is None:
                    references[method] = estimator
                errors, ratios = entry_ratios(estimator, M, B)
                _, noise_ratios = entry_ratios(estimator, M, B, references.get(method))
                rows.append({"method": method, "scale": scale,
                             "noise": "none" if seed is None else "noisy", "seed": seed,
                             "max_error_percent": float(errors.max()),
                             "median_ratio": float(np.median(ratios)),
                             "rms_ratio": float(np.sqrt(np.mean(ratios ** 2))),
                             "rms_noise_ratio": float(np.sqrt(np.mean(noise_ratios ** 2))),
                             "ratios": ratios, "noise_ratios": noise_ratios,
                             "errors": errors, "seconds": seconds})
    return rows


def summary(rows) -> list[str]:
    """Markdown table: per method and noise scale, the median and worst largest error over
    seeds, the share of (entry, seed) pairs within 3 standard errors, the mean fit time."""
    lines = ["| method | noise (x reference) | median largest error (%) | worst largest "
             "error (%) | within 3 SE (%) | time (s) |", "|---|---|---|---|---|---|"]
    for method in dict.fromkeys(r["method"] for r in rows):
        for scale in dict.fromkeys(r["scale"] for r in rows):
            group = [r for r in rows if r["method"] == method and r["scale"] == scale]
            if not group:
                continue
            largest = np.array([r["max_error_percent"] for r in group])
            ratios = np.concatenate([r["ratios"] for r in group])
            lines.append(f"| {method} | {scale:g} | {np.median(largest):.3g} | "
                         f"{largest.max():.3g} | {100 * np.mean(ratios <= 3):.0f} | "
                         f"{np.mean([r['seconds'] for r in group]):.1f} |")
    return lines


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=4)
    parser.add_argument("--length-noise", type=float, default=20e-6, help="m")
    parser.add_argument("--force-noise", type=float, default=0.005,
                        help="fraction of each leg's mean force")
    parser.add_argument("--scales", default="0.5,1,2",
                        help="comma-separated multiples of the noise levels (0 is always run)")
    parser.add_argument("--methods", default=",".join([*METHODS, "oracle"]))
    args = parser.parse_args()
    scales = tuple(float(v) for v in args.scales.split(","))
    rows = study(tuple(args.methods.split(",")), tuple(range(args.seeds)), args.length_noise,
                 args.force_noise, scales=scales)
    print(f"reference: length noise {args.length_noise * 1e6:g} um, force noise "
          f"{100 * args.force_noise:g} % of the mean leg force; {args.seeds} seeds")
    print("\n".join(summary(rows)))


if __name__ == "__main__":
    main()
