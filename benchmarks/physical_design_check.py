"""The physical design checked on our plant: design, play, identify over seeds, compare.

Our plant (the paper platform with the physical model's 2 t payload, Coulomb 30 N m), the
reference sensor noise. ``stewartid design --model physical`` is run (timed) on the platform
file; its records are played once on the plant without noise and each seed adds the
reference noise as ``simulate --noise`` draws it (the pose by the first Newton step of the
forward kinematics, :func:`stewartid.design.prediction.measured_plant_datasets`); the
physical model is fitted as the printed ``identify`` command does (payload mode on the same
file with ``--payload``). Printed: the payload's errors (mass %, com mm, inertia diagonal
about the com %) or full mode's (Mt(q) at 50 random poses inside the motion's range: diagonal
%), the predicted SE (``design.json``'s) against the spread over seeds (with more than 8
seeds, also over each block of 8) and the fits' own standard errors against it, the limit
use on the plant's states; in payload mode the payload's mass, centre of mass and inertia
about it, predicted against their spread, and each parameter's mean error over seeds in its
fits' standard errors where beyond 3/sqrt(seeds) (a bias).

With ``--engine mujoco`` the design's exported pose command files (``commands/exp*.csv``) are
played on MuJoCo's model of the same platform instead
(:func:`stewartid.mujoco.closed_loop.simulate_mujoco`), as another simulator would play
them; each seed then adds the reference noise with :func:`stewartid.simulation.degrade`, and
the limit use is the stroke and leg speed of the recorded motion.

Usage::

    python benchmarks/physical_design_check.py [--payload] [--seeds 8] [--budget 120]
        [--engine ours|mujoco] [--save FILE.npz]
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import physical_study  # noqa: E402

from stewartid.design.candidates import Design  # noqa: E402
from stewartid.design.limits import record_limit_use  # noqa: E402
from stewartid.design.multisine import MultisineRecord  # noqa: E402
from stewartid.design.prediction import (  # noqa: E402
    inverse_leg_jacobians,
    measured_plant_datasets,
    plant_records,
)
from stewartid.physical.estimator import PhysicalIdentifier  # noqa: E402
from stewartid.simulation import degrade  # noqa: E402
from stewartid.simulation.sensors import reference_noise  # noqa: E402


def mujoco_datasets(platform, paths: list[Path]) -> list:
    """The design's exported pose command files played on the MuJoCo model of ``platform``,
    as another simulator would play them (no noise)."""
    from stewartid.design.export import read_excitation
    from stewartid.mujoco.closed_loop import simulate_mujoco

    out = []
    for path in paths:
        excitation = read_excitation(path, platform)
        out.append(simulate_mujoco(platform, excitation, excitation.duration))
        print(f"played {path.name} on MuJoCo ({excitation.duration:.0f} s)", flush=True)
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--payload", action="store_true")
    parser.add_argument("--seeds", type=int, default=8)
    parser.add_argument("--budget", type=float, default=120.0)
    parser.add_argument("--engine", default="ours", choices=["ours", "mujoco"],
                        help="play the design's command files on our plant or on the MuJoCo "
                             "model (ideal actuators, the mujoco extra)")
    parser.add_argument("--save", type=Path, default=None,
                        help="write the estimates, the fits' standard errors and the truth "
                             "(.npz)")
    args = parser.parse_args()
    loaded = physical_study.loaded_platform("paper")
    folder = Path(tempfile.mkdtemp(prefix="stewartid-physical-design-"))
    (folder / "plant.toml").write_text(loaded.to_toml())
    start = time.perf_counter()
    subprocess.run([sys.executable, "-m", "stewartid", "design", "--model", "physical",
                    *(["--payload"] if args.payload else []), "--platform",
                    str(folder / "plant.toml"), "--budget", str(args.budget), "--out",
                    str(folder / "design")], check=True)
    print(f"design: {time.perf_counter() - start:.1f} s wall")
    import json

    document = json.loads((folder / "design" / "design.json").read_text())
    design = Design(tuple(MultisineRecord(r["amplitudes"], r["frequencies_hz"], r["phases"],
                                          r["duration_s"], r["fade_s"], r["name"])
                          for r in document["design"]["records"]))
    noise = reference_noise(loaded)
    # the design's own prediction, as design.json reports it (along its motion on the plant)
    reported = document["prediction"]["parameters"]
    names = tuple(reported)
    expected = np.array([np.nan if reported[n]["expected_std_error"] is None
                         else reported[n]["expected_std_error"] for n in names])
    if args.engine == "mujoco":
        clean = mujoco_datasets(loaded, sorted((folder / "design" / "commands").glob("*.csv")))
        use = max(physical_study.limit_peaks(loaded, clean).values())
    else:
        records = plant_records(loaded, design)
        use = max(max(record_limit_use(loaded, r).peak.values()) for r in records)
        inverse = inverse_leg_jacobians(loaded, [r.q for r in records])
    rows, estimates, fitted_errors, sections = [], [], [], []
    for seed in range(args.seeds):
        if args.engine == "mujoco":
            data = [degrade(d, loaded, noise, rng=np.random.default_rng([1000 + seed, k]))
                    for k, d in enumerate(clean)]
        else:
            generators = [np.random.default_rng([1000 + seed, k]) for k in range(len(records))]
            data = measured_plant_datasets(loaded, records, noise, generators, inverse)
        fitted = PhysicalIdentifier(payload=args.payload).fit(data, loaded)
        estimates.append([fitted.parameters_[n] for n in names])
        fitted_errors.append([fitted.parameter_std_errors_.get(n, np.nan) for n in names])
        if args.payload:
            section = fitted.result_.diagnostics["payload"]
            sections.append([section["mass"], *section["com"], *section["inertia"]])
        rows.append(physical_study.payload_row(fitted, loaded, physical_study.PAYLOADS["paper"])
                    if args.payload else physical_study.full_row(
                        fitted, loaded, data, np.random.default_rng(seed)))
        print(seed, {k: round(v, 3) for k, v in rows[-1].items()
                     if isinstance(v, float)}, flush=True)
    estimates = np.array(estimates)
    # the truth: the platform file's values, which the plant (or MuJoCo) simulates
    truth = np.array([reported[n]["nominal"] for n in names])
    if args.save:
        np.savez(args.save, names=np.array(names), estimates=estimates,
                 fitted_errors=np.array(fitted_errors), truth=truth)
    spread = np.std(estimates, axis=0, ddof=1)
    ratio = expected / spread
    finite = np.isfinite(ratio)
    keys = [k for k, v in rows[0].items() if isinstance(v, float)]
    print("worst over seeds:", {k: round(max(r[k] for r in rows), 3) for k in keys})
    print(f"predicted SE within 30 % of the spread over {args.seeds} seeds: "
          f"{np.mean(np.abs(ratio[finite] - 1) <= 0.3):.0%} of {finite.sum()} parameters "
          f"(median ratio {np.median(ratio[finite]):.2f}); predicted worst relative SE "
          f"{document['prediction']['worst_relative_std_percent']:.3g} % vs multisine "
          f"{document['baseline']['worst_relative_std_percent']:.3g} %")
    with warnings.catch_warnings():  # a parameter fixed in every fit has no error at all
        warnings.simplefilter("ignore", RuntimeWarning)
        own = np.nanmean(fitted_errors, axis=0) / spread
    print(f"  the fits' own standard errors: {np.nanmedian(own):.2f} times the spread in the "
          f"median ({np.nanmin(own):.2f}-{np.nanmax(own):.2f})")
    z = np.abs(estimates - truth) / np.array(fitted_errors)
    kept = np.isfinite(z)
    beyond = {n: round(float(np.nanmax(z[:, k])), 2) for k, n in enumerate(names)
              if np.nanmax(z[:, k], initial=0.0) > 3}
    print(f"  within 3 of the fits' own standard errors: {np.mean(z[kept] <= 3):.1%} of "
          f"{kept.sum()} (parameter, seed) pairs; beyond: {beyond}")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        bias = np.nanmean((estimates - truth) / np.array(fitted_errors), axis=0)
    # a mean over seeds of errors in units of their SE: beyond 3 / sqrt(seeds), a bias
    print("  mean error over seeds in SE (bias test, 3/sqrt(seeds) = "
          f"{3 / np.sqrt(args.seeds):.2f}): " + ", ".join(
              f"{n} {b:+.2f}" for n, b in zip(names, bias, strict=True)
              if np.isfinite(b) and abs(b) > 3 / np.sqrt(args.seeds)))
    commanded = document["prediction_commanded"]["parameters"]
    along = np.array([np.nan if commanded[n]["expected_std_error"] is None
                      else commanded[n]["expected_std_error"] for n in names]) / spread
    print(f"  along the commanded motion: {np.mean(np.abs(along[finite] - 1) <= 0.3):.0%} "
          f"within 30 % (median ratio {np.median(along[finite]):.2f})")
    for start in range(0, args.seeds - 7 if args.seeds > 8 else 0, 8):
        block = expected / np.std(estimates[start:start + 8], axis=0, ddof=1)
        print(f"  seeds {1000 + start}-{1007 + start}: "
              f"{np.mean(np.abs(block[finite] - 1) <= 0.3):.0%} within 30 %")
    outside = {n: round(float(r), 2) for n, r, f in zip(names, ratio, finite,
                                                        strict=True) if f and abs(r - 1) > 0.3}
    print(f"predicted / spread beyond 30 %: {outside}")
    print(f"largest limit use on the plant's states: {use:.3f}")
    if args.payload:
        payload_spread(document, np.array(sections))


def payload_spread(document: dict, sections: np.ndarray) -> None:
    """The payload's mass (relative), centre of mass (m, along its least certain direction)
    and inertia about it (largest entry relative to the mean diagonal): predicted standard
    errors (design.json's) beside their spread over seeds, and the criterion against the
    multisine's."""
    mass = sections[:, 0]
    inertia = sections[:, 4:]
    spread = {"mass": np.std(mass, ddof=1) / np.mean(mass),
              "com": np.sqrt(np.linalg.eigvalsh(np.cov(sections[:, 1:4].T))[-1]),
              "inertia": np.std(inertia, axis=0, ddof=1).max() / np.mean(inertia[:, :3])}
    for key in ("prediction", "prediction_commanded", "baseline"):
        predicted = document[key]["payload_std_errors"]
        print(f"  {key}: criterion {document[key]['criterion']:.3g}; "
              + ", ".join(f"{k} {predicted[k]:.3g}" for k in spread))
    print("  spread over seeds: " + ", ".join(f"{k} {v:.3g}" for k, v in spread.items()))
    print(f"  criterion against the multisine's: "
          f"{document['prediction']['criterion'] / document['baseline']['criterion']:.2f}")


if __name__ == "__main__":
    main()
