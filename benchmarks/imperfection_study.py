"""Rig-imperfection study: every method on three-sine logs with a late force channel or
coloured sensor noise, beside the oracle.

The clean logs are :mod:`noise_study`'s ``three`` kind (each DOF driven by 0.3, 0.7 and
1.5 Hz; Coulomb 30 N m, 6 x 20 s at 1 kHz, cached in ``DIR/TAG_three_clean``; ``--base
paper``: the paper's 0.5 Hz sines instead); per seed they are degraded
(:func:`stewartid.simulation.degrade`) into one log per kind:

- ``white``: the reference sensor noise (20 µm on the leg lengths, 0.5 % of the static leg
  force on the forces), the figures the others are compared with;
- ``delayMS``: the same with the forces logged MS milliseconds after the motion (``--delays``);
  the delay is estimated (``identify --delay auto``,
  :func:`stewartid.identification.delay.apply_delay`) and every method, the oracle
  included, fits the aligned logs;
- ``coloured``: the reference force noise low-pass filtered at 20 Hz (fourth-order
  Butterworth, same standard deviation), a 30 N mains hum at 50 Hz, a 50 N random-walk
  drift of every force channel and the leg lengths quantised to 1 µm (:data:`COLOURED`);
  ``lowpass`` and ``humdrift`` its parts (:data:`PARTS`);
- ``filtered``: the same rig, but the force sensor's white noise itself goes through the
  20 Hz filter (an anti-aliasing filter on the channel: the noise density below 20 Hz is the
  white noise's, its standard deviation :func:`filtered_share` of it), where ``coloured``
  squeezes the whole standard deviation into the filter's band.

For each kind and method: the median over seeds of the largest error over the paper's 20
entries, the share of (entry, seed) pairs within 3 reported standard errors, the largest
|error| / SE, the median largest error of the Mt diagonal, and on delayed logs the estimated
delay's mean and its RMS error against the mean reported standard error.

Usage::

    python benchmarks/imperfection_study.py --kind white,coloured [--seeds 4]
        [--platform paper|FILE] [--clean DIR] [--tag NAME] [--methods wavelet,ls,oracle]
    python benchmarks/imperfection_study.py --kind delay --delays 0.5,1,2,3 [...]
    python benchmarks/imperfection_study.py --base paper --kind white,coloured [...]
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import noise_study  # noqa: E402  (a sibling script)

from stewartid.datasets.dataset import Dataset  # noqa: E402
from stewartid.identification.delay import apply_delay  # noqa: E402
from stewartid.identification.registry import registered_methods  # noqa: E402
from stewartid.model.linearization import nominal_matrices  # noqa: E402
from stewartid.simulation import degrade  # noqa: E402
from stewartid.simulation.sensors import reference_noise  # noqa: E402

#: The coloured-noise rig, on top of the reference noise (the worked example of docs/logs.md).
COLOURED = {"force_lowpass": 20.0, "hum_amplitude": 30.0, "hum_frequency": 50.0,
            "force_drift": 50.0, "length_resolution": 1e-6}
#: Sample rate (Hz) of the kinds' logs (simulated at the plant's default).
LOG_RATE = 1000.0
#: Its parts, to tell what each costs: the filtered force noise alone, and the hum, drift and
#: quantisation on white noise.
PARTS = {"lowpass": {"force_lowpass": 20.0},
         "humdrift": {k: v for k, v in COLOURED.items() if k != "force_lowpass"}}


def filtered_share(cutoff: float, order: int, sample_rate: float) -> float:
    """Standard deviation of white noise after a Butterworth low-pass (``cutoff`` Hz,
    ``order``) as a share of its own: sqrt(noise bandwidth / Nyquist frequency), the noise
    bandwidth of the Butterworth filter being cutoff * (pi / 2n) / sin(pi / 2n)."""
    bandwidth = cutoff * (np.pi / (2 * order)) / np.sin(np.pi / (2 * order))
    return float(np.sqrt(bandwidth / (0.5 * sample_rate)))


def rig_noise(platform, kind: str):
    """The sensor errors of a kind ("white", "coloured" or "delayMS") and the delay (s) the
    fit estimates first (None: the logs are used as logged)."""
    noise = reference_noise(platform)
    if kind == "white":
        return noise, None
    if kind == "coloured":
        return dataclasses.replace(noise, **COLOURED), None
    if kind in PARTS:
        return dataclasses.replace(noise, **PARTS[kind]), None
    if kind == "filtered":
        share = filtered_share(COLOURED["force_lowpass"], noise.force_lowpass_order,
                               LOG_RATE)
        return dataclasses.replace(noise, **COLOURED, force_noise=tuple(
            share * np.broadcast_to(noise.force_noise, 6))), None
    if kind.startswith("delay"):
        return dataclasses.replace(noise, force_delay=float(kind[5:]) * 1e-3), "auto"
    raise ValueError(f"kind must be white, coloured, filtered, lowpass, humdrift or delayMS; got "
                     f"{kind!r}.")


def matching_clean(clean: list[Dataset], data: list[Dataset]) -> list[Dataset]:
    """The clean logs at the samples ``data`` kept (alignment drops the samples whose shifted
    time leaves the record), for the oracle's true Coulomb force."""
    out = []
    for c, d in zip(clean, data, strict=True):
        keep = np.searchsorted(c.t, d.t[0]) + np.arange(len(d.t))
        out.append(Dataset(t=c.t[keep], pose=c.pose[keep], lengths=c.lengths[keep],
                           forces=c.forces[keep], name=c.name))
    return out


def kind_rows(kind: str, platform, clean, methods, seeds) -> list[dict]:
    """Rows (kind, method, seed, errors, ratios, Mt diagonal error, delay) of one kind."""
    M, B = nominal_matrices(platform)
    noise, delay = rig_noise(platform, kind)
    rows = []
    for seed in seeds:
        data = [degrade(d, platform, noise, np.random.default_rng(seed + 101 * k))
                for k, d in enumerate(clean)]
        entry = None
        if delay is not None:
            data, entry = apply_delay(data, platform, delay)
        truth = matching_clean(clean, data)
        for method in methods:
            start = time.perf_counter()
            estimator = noise_study.fit_method(method, data, truth, platform)
            row = {"kind": kind, "method": method, "seed": seed, "refused": None,
                   "seconds": time.perf_counter() - start,
                   "delay": None if entry is None else (entry["seconds"], entry["std_error"])}
            if isinstance(estimator, str):
                row["refused"] = estimator
            else:
                errors, ratios = noise_study.entry_ratios(estimator, M, B)
                mt_diag = 100 * np.abs(np.diag(estimator.M_) / np.diag(M) - 1)
                row.update(errors=errors, ratios=ratios, mt_diag=float(mt_diag.max()))
            rows.append(row)
            delay_text = "" if entry is None else (
                f", delay {entry['seconds'] * 1e3:.4f} +- {entry['std_error'] * 1e3:.4f} ms")
            print(kind, method, seed, "refused" if row["refused"] else
                  f"{row['errors'].max():.3g} % ({row['ratios'].max():.2g} SE), Mt diag "
                  f"{row['mt_diag']:.3g} %{delay_text}", flush=True)
    return rows


def summary(rows) -> list[str]:
    """Markdown table per kind and method (module docstring)."""
    lines = ["| log | method | median largest error (%) | within 3 SE (%) | largest error/SE "
             "| median Mt diagonal error (%) | delay: mean estimate, RMS error / mean SE (ms) "
             "| time (s) |", "|---|---|---|---|---|---|---|---|"]
    for kind in dict.fromkeys(r["kind"] for r in rows):
        for method in dict.fromkeys(r["method"] for r in rows if r["kind"] == kind):
            group = [r for r in rows if r["kind"] == kind and r["method"] == method]
            fitted = [r for r in group if r["refused"] is None]
            delay = "-"
            if group[0]["delay"] is not None:
                estimates = np.array([r["delay"] for r in group]) * 1e3
                true = float(kind[5:])
                rms = np.sqrt(np.mean((estimates[:, 0] - true) ** 2))
                delay = (f"{estimates[:, 0].mean():.3f}, {rms:.3f} / "
                         f"{estimates[:, 1].mean():.3f}")
            if fitted:
                ratios = np.concatenate([r["ratios"] for r in fitted])
                cells = (f"{np.median([r['errors'].max() for r in fitted]):.3g} | "
                         f"{100 * np.mean(ratios <= 3):.0f} | {ratios.max():.3g} | "
                         f"{np.median([r['mt_diag'] for r in fitted]):.3g}")
            else:
                cells = f"refused: {group[0]['refused'][:60]} | - | - | -"
            lines.append(f"| {kind} | {method} | {cells} | {delay} | "
                         f"{np.mean([r['seconds'] for r in group]):.1f} |")
    return lines


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--kind", default="white,coloured,delay",
                        help="comma-separated: white, coloured, filtered, lowpass, humdrift, delay (one "
                             "log per --delays)")
    parser.add_argument("--base", default="three", choices=("three", "paper"),
                        help="clean logs: noise_study's three-sine or paper kind")
    parser.add_argument("--delays", default="0.5,1,2,3", help="ms, comma-separated")
    parser.add_argument("--seeds", type=int, default=4)
    parser.add_argument("--methods", default=None,
                        help="comma-separated; default: every registered method and the oracle")
    parser.add_argument("--platform", default="paper", help="paper or a TOML file")
    parser.add_argument("--clean", type=Path, default=Path("noise_study_logs"),
                        help="folder of the clean logs, TAG_BASE_clean/exp1..6.csv "
                             "(simulated and written there when missing)")
    parser.add_argument("--tag", default=None,
                        help="TAG of the clean-log folder (default: paper, or the platform "
                             "file's stem)")
    args = parser.parse_args()
    platform = noise_study.kind_platform(args.platform)
    tag = args.tag or ("paper" if args.platform == "paper" else Path(args.platform).stem)
    clean = noise_study.kind_logs(args.base, platform, args.clean / f"{tag}_{args.base}_clean")
    methods = (args.methods.split(",") if args.methods
               else [*(spec.name for spec in registered_methods()), "oracle"])
    kinds = []
    for kind in args.kind.split(","):
        kinds += [f"delay{d}" for d in args.delays.split(",")] if kind == "delay" else [kind]
    rows = []
    for kind in kinds:
        rows += kind_rows(kind, platform, clean, methods, range(args.seeds))
    print(f"platform {args.platform}, {args.base} logs, Coulomb {noise_study.KIND_COULOMB:g} "
          f"N m, {args.seeds} seeds")
    print("\n".join(summary(rows)))


if __name__ == "__main__":
    main()
