"""Cramér-Rao bounds for the paper's excitation: what accuracy any unbiased estimator can reach.

For each case the bound on the paper's 20 entries (% of nominal) with the Coulomb force known
(the oracle's bound) and with a free constant per constant-direction interval (the bound of a
friction-immune estimator such as Method B with free interval constants), and, drawn from
the bound's Gaussian, the chance that one noise seed meets the accuracy targets of the noisy
acceptance (Mt diagonal 0.5 %, Bt diagonal 3 %, couplings 10 %) and that at least 7 of 8
seeds do. Only the leg-force noise is counted (the motion is known exactly), so every figure
is optimistic for a real log, whose pose noise costs more.

Cases: ``own`` the plant's 6 x 20 s paper excitation at Coulomb ``--coulomb`` (true states
from the simulator), ``example`` the independent simulator's data set (motion from its
noise-free pose by Savitzky-Golay differentiation, force noise 0.5 % of each leg's mean
force, as ``noise_study.py`` adds it), ``--design DIR/design.json`` a designed excitation
played on the plant, and ``--logs DIR`` noise-free logs exp1..exp6 of ``--platform`` (e.g.
``noise_study.py``'s kinds; motion from the noise-free pose, the platform's reference force
noise as the studies add it per seed). For each, the median and 90th percentile of the
largest error of each group over ``--seeds`` seeds, drawn from the bound's Gaussian.

Usage::

    python benchmarks/information_bound.py [--cases own,example] [--design results/design/design.json]
        [--logs DIR --platform paper|FILE] [--seeds 8] [--coulomb 30] [--draws 200000]
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
from scipy.stats import binom

from stewartid.identification.bounds import information_bound
from stewartid.model.linearization import nominal_matrices
from stewartid.platform import load_platform
from stewartid.reference.published import PAPER_ENTRIES, entry_label
from stewartid.signals.differentiation import default_window, differentiate, estimate_frequency
from stewartid.simulation import SensorNoise, simulate_experiments
from stewartid.simulation.sensors import reference_noise

#: Targets (%) of the noisy acceptance: Mt diagonal, Bt diagonal, couplings.
TARGETS = {"Mt diagonal": 0.5, "Bt diagonal": 3.0, "couplings": 10.0}
GROUPS = {"Mt diagonal": slice(0, 6), "Bt diagonal": slice(10, 16)}


def own_case(coulomb: float):
    """Platform, motions and leg-force noise (N) of the plant's paper excitation."""
    platform = load_platform("paper").replace(friction__coulomb=coulomb)
    run = simulate_experiments(platform, coulomb=coulomb, duration_s=20.0, noise=SensorNoise())
    motions = [(r.t, r.q, r.q_dot, r.q_ddot) for r in run.states]
    return platform, motions, reference_noise(platform).force_noise, None


def example_case():
    """Platform, motions, leg-force noise and truth of the example data set."""
    from noise_study import load_example

    platform, datasets, M, B = load_example()
    motions, levels = [], []
    for d in datasets:
        rate = 1.0 / float(d.t[1] - d.t[0])
        q, q_dot, q_ddot = differentiate(d.pose, rate,
                                         default_window(estimate_frequency(d.pose, rate)))
        motions.append((d.t, q, q_dot, q_ddot))
        levels.append(0.005 * np.abs(d.forces).mean(axis=0))
    # one noise level per leg for the whole set (the records' levels differ by a few %)
    return platform, motions, np.mean(levels, axis=0), (M, B)


def design_case(path: Path, coulomb: float):
    """Platform, motions and leg-force noise of a design played on the plant."""
    from stewartid.design.candidates import design_from_dict
    from stewartid.design.prediction import plant_records

    platform = load_platform("paper").replace(friction__coulomb=coulomb)
    design = design_from_dict(json.loads(path.read_text())["design"])
    motions = [(r.t, r.q, r.q_dot, r.q_ddot) for r in plant_records(platform, design)]
    return platform, motions, reference_noise(platform).force_noise, None


def logs_case(folder: Path, platform_name: str):
    """Platform, motions and leg-force noise (N) of noise-free logs exp1..exp6 in ``folder``."""
    from stewartid.datasets.dataset import read_datasets

    platform = load_platform(platform_name)
    datasets = read_datasets(sorted(folder.glob("exp*.csv")), platform)
    motions = []
    for d in datasets:
        # noise-free: a short window differentiates them to round-off
        q, q_dot, q_ddot = differentiate(d.pose, d.sample_rate, 0.02, 5)
        motions.append((d.t, q, q_dot, q_ddot))
    return platform, motions, reference_noise(platform).force_noise, None


def report(name: str, platform, motions, force_noise, truth, draws: int,
           seeds: int = 8) -> dict:
    """Print and return the bounds and the chances of meeting the targets."""
    M, B = truth if truth is not None else nominal_matrices(platform)
    nominal = np.abs([(M if m == "M" else B)[i, j] for m, i, j in PAPER_ENTRIES])
    rng = np.random.default_rng(0)
    out = {}
    for friction in ("known", "immune"):
        bound = information_bound(platform, motions, force_noise, friction)
        covariance = bound.paper_covariance()
        relative = 100 * np.sqrt(np.diag(covariance)) / nominal
        errors = np.abs(rng.multivariate_normal(np.zeros(20), covariance, size=draws)
                        ) / nominal * 100
        coupling = np.r_[6:10, 16:20]
        ok = {g: np.max(errors[:, s], axis=1) <= TARGETS[g] for g, s in GROUPS.items()}
        ok["couplings"] = np.max(errors[:, coupling], axis=1) <= TARGETS["couplings"]
        largest = {g: np.max(errors[:, s], axis=1) for g, s in GROUPS.items()}
        largest["couplings"] = np.max(errors[:, coupling], axis=1)
        usable = draws // seeds * seeds
        worst = {g: np.quantile(v[:usable].reshape(-1, seeds).max(axis=1), [0.5, 0.9])
                 for g, v in largest.items()}
        every = np.logical_and.reduce(list(ok.values()))
        chance = {g: float(v.mean()) for g, v in ok.items()} | {"all": float(every.mean())}
        seven = {g: float(binom.sf(6, 8, p)) for g, p in chance.items()}
        print(f"\n{name}, Coulomb force {friction} ({bound.n_constants} constants per channel)")
        print("  bound (% of nominal): " + ", ".join(
            f"{entry_label(k)} {r:.2f}" for k, r in zip(PAPER_ENTRIES, relative, strict=True)))
        for g in chance:
            print(f"  {g:12s} one seed within target {100 * chance[g]:5.1f} %, "
                  f">= 7 of 8 seeds {100 * seven[g]:5.1f} %" + (
                      f"; largest error, worst of {seeds} seeds: median {worst[g][0]:.3g} %, "
                      f"90 % {worst[g][1]:.3g} %" if g in worst else ""))
        out[friction] = {"bound_percent": dict(zip(map(entry_label, PAPER_ENTRIES),
                                                   relative.tolist(), strict=True)),
                         "one_seed": chance, "seven_of_eight": seven,
                         "constants": bound.n_constants,
                         "worst_of_seeds": {g: v.tolist() for g, v in worst.items()},
                         "seeds": seeds}
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", default="own,example")
    parser.add_argument("--design", type=Path, default=None)
    parser.add_argument("--coulomb", type=float, default=30.0)
    parser.add_argument("--draws", type=int, default=200_000)
    parser.add_argument("--logs", type=Path, default=None,
                        help="folder of noise-free logs exp1..exp6 (CSV) of --platform")
    parser.add_argument("--platform", default="paper", help="paper or a platform TOML file")
    parser.add_argument("--seeds", type=int, default=8,
                        help="seeds the worst error is predicted over")
    parser.add_argument("--json", type=Path, default=None, help="also write the figures here")
    args = parser.parse_args()
    results = {}
    for case in filter(None, args.cases.split(",")):
        if case == "own":
            results["own"] = report(f"own plant, paper excitation 6 x 20 s, Coulomb "
                                    f"{args.coulomb:g} N m", *own_case(args.coulomb), args.draws,
                                    args.seeds)
        elif case == "example":
            results["example"] = report("example_c10 (independent simulator)", *example_case(),
                                        args.draws, args.seeds)
        else:
            parser.error(f"unknown case {case!r}: choose from own, example")
    if args.design is not None:
        results["design"] = report(f"design {args.design}", *design_case(args.design,
                                                                         args.coulomb), args.draws,
                                   args.seeds)
    if args.logs is not None:
        results["logs"] = report(f"logs {args.logs}, {args.platform}",
                                 *logs_case(args.logs, args.platform), args.draws, args.seeds)
    if args.json is not None:
        args.json.write_text(json.dumps(results, indent=1))


if __name__ == "__main__":
    main()
