"""Acceptance study of electric hexapods: every method and the physical model on the example
electric platform's logs, over seeds.

Data: ``src/stewartid/data/electric.toml`` (400 kg moving, 30 kg reflected mass, 200 N s/m and
80 N along each leg, 565 N/A, 20 A peak, 2 kHz logs) played by the electric plant (current loops,
current limit, 1 um encoders; ``--engine mujoco``: the same motors on the MuJoCo model). Two log
kinds of six experiments: "sines", the paper's experiments at :data:`SINE_HZ` (experiment k a sine
on DOF k, 20 mm or 10 mrad; what ``stewartid simulate --frequency 1`` plays) and "alldof", every
DOF at once (DOF d of experiment k at ``ALLDOF_HZ[(d + k) % 6]``, 0.7 of those amplitudes). Each
experiment is simulated once, noise-free; each seed then measures it as ``simulate --noise --seed``
does (whole encoder counts, 0.5 % of each motor current's RMS as white noise; the plant does not
see the sensors, so the measurement is all a seed changes).

For each seed: :func:`stewartid.compare_methods` (``identify --method all``) gives Method B
(``wavelet``), least squares (``ls``), Method A (``fourier``), the consensus of close methods when
the verdict builds one, and the trusted method; per method the largest relative error of Mt's
diagonal, Bt's diagonal and the paper's couplings against ``nominal_matrices``, and the share of
the paper's 20 entries within 3 standard errors (or the method's refusal). The physical model in
full mode gives the reflected mass and the friction along the legs against the file's values; in
payload mode, on logs of the platform carrying :data:`PAYLOAD` identified on the file without it,
the payload's mass and centre of mass.

Usage::

    python benchmarks/electric_study.py [--engine ours|mujoco] [--seeds 8] [--duration 20]
        [--kinds sines,alldof] [--no-payload] [--cache DIR] [--out rows.jsonl]
    python benchmarks/electric_study.py --summary rows.jsonl [rows2.jsonl ...]
"""

from __future__ import annotations

import argparse
import json
import time
from importlib import resources
from pathlib import Path

import numpy as np

import stewartid as sid
from stewartid.datasets.dataset import Dataset, read_datasets, write_dataset
from stewartid.model.linearization import nominal_matrices
from stewartid.physical.estimator import PhysicalIdentifier
from stewartid.reference.published import PAPER_ENTRIES, relative_error_percent
from stewartid.simulation import DEFAULT_AMPLITUDES, SensorNoise, Sine, multisine_excitation
from stewartid.simulation.electric import encoder_resolution
from stewartid.simulation.experiments import noise_generator, simulate_experiment
from stewartid.simulation.sensors import (
    REFERENCE_CURRENT_NOISE,
    measure_electric_legs,
    measured_pose,
)

#: Frequency of the single-DOF sines (Hz).
SINE_HZ = 1.0
#: Frequencies of the all-DOFs kind (Hz): DOF d of experiment k at ALLDOF_HZ[(d + k) % 6].
ALLDOF_HZ = (0.7, 0.9, 1.1, 1.3, 1.5, 1.7)
KINDS = ("sines", "alldof")
#: A payload on the platform (kg, m in the platform frame, kg m^2 about its centre of mass).
PAYLOAD = {"mass": 80.0, "com": [0.06, -0.04, -0.12],
           "inertia": [3.0, 3.5, 4.0, 0.1, -0.05, 0.08]}
#: Methods whose rows are reported, the trusted one added.
METHODS = ("wavelet", "ls", "fourier", "consensus")
#: Targets of the acceptance (%, mm, share of entries).
TARGETS = {"Mt diagonal": 1.0, "Bt diagonal": 8.0, "couplings": 10.0, "within 3 SE": 95.0,
           "reflected_mass": 3.0, "viscous[actuator]": 10.0, "coulomb[actuator]": 10.0,
           "payload mass": 0.5, "payload centre (mm)": 5.0}


def electric_platform():
    """The example electric platform, data/electric.toml."""
    with resources.as_file(resources.files("stewartid") / "data/electric.toml") as path:
        return sid.load_platform(path)


def kind_sines(kind: str, k: int) -> list[Sine]:
    """The sines of experiment ``k`` (0..5) of a log kind (:data:`KINDS`)."""
    if kind == "sines":
        return [Sine(k, DEFAULT_AMPLITUDES[k], SINE_HZ)]
    if kind == "alldof":
        return [Sine(d, 0.7 * DEFAULT_AMPLITUDES[d], ALLDOF_HZ[(d + k) % 6], 0.5 * d + k)
                for d in range(6)]
    raise ValueError(f"log kind must be one of {', '.join(KINDS)}; got {kind!r}.")


def clean_logs(platform, kind: str, engine: str, duration: float, folder: Path) -> list[Dataset]:
    """True pose, leg lengths and motor forces of the six experiments, simulated once and kept in
    ``folder`` (Parquet)."""
    folder.mkdir(parents=True, exist_ok=True)
    paths = [folder / f"exp{k + 1}.parquet" for k in range(6)]
    if not all(p.exists() for p in paths):
        for k, path in enumerate(paths):
            excitation = multisine_excitation(platform, kind_sines(kind, k), name=f"exp{k + 1}")
            if engine == "mujoco":
                from stewartid.mujoco.closed_loop import simulate_mujoco

                clean = simulate_mujoco(platform, excitation, duration)
            else:
                _, record = simulate_experiment(platform, excitation, duration,
                                                noise=SensorNoise())
                clean = Dataset(t=record.t, pose=record.q, lengths=record.lengths,
                                forces=record.forces, name=f"exp{k + 1}")
            write_dataset(clean, path)
            print(f"  simulated {engine} {kind} exp{k + 1}", flush=True)
    return read_datasets(paths, platform)


def measured(platform, clean: list[Dataset], seed: int) -> list[Dataset]:
    """The logs ``simulate --noise --seed SEED`` writes of these true signals."""
    out = []
    for k, data in enumerate(clean):
        lengths, forces = measure_electric_legs(
            data.lengths, data.forces, SensorNoise(), noise_generator(seed, k, len(clean)),
            data.t, encoder_resolution(platform.actuator), REFERENCE_CURRENT_NOISE)
        out.append(Dataset(t=data.t, pose=measured_pose(platform, lengths, data.pose),
                           lengths=lengths, forces=forces, name=data.name))
    return out


def matrix_row(result, M0: np.ndarray, B0: np.ndarray) -> dict:
    """Largest relative errors (%) by group and the share of the paper's entries within 3 SE."""
    groups = {"Mt diagonal": [], "Bt diagonal": [], "couplings": []}
    within = []
    for matrix, i, j in PAPER_ENTRIES:
        estimate = (result.M if matrix == "M" else result.B)[i, j]
        truth = (M0 if matrix == "M" else B0)[i, j]
        se = (result.std_errors_M if matrix == "M" else result.std_errors_B)[i, j]
        group = "couplings" if i != j else ("Mt diagonal" if matrix == "M" else "Bt diagonal")
        groups[group].append(abs(relative_error_percent(estimate, truth)))
        within.append(bool(np.isfinite(se) and se > 0 and abs(estimate - truth) <= 3 * se))
    return {**{k: float(max(v)) for k, v in groups.items()}, "within": within}


def seed_rows(platform, kind: str, engine: str, seed: int, data, loaded_data,
              delays=(None,)) -> list:
    """Rows of one seed: every compared method and the trusted one for each force delay in
    ``delays`` (None: ``identify``'s default; "auto": estimated; or seconds), the physical
    model."""
    M0, B0 = nominal_matrices(platform)
    rows = []
    base = {"engine": engine, "kind": kind, "seed": seed}
    for delay in delays:
        start = time.perf_counter()
        comparison = sid.compare_methods(data, platform, "all", delay=delay)
        seconds = time.perf_counter() - start
        applied = (comparison.delay or {}).get("seconds") if (
            comparison.delay or {}).get("applied") else 0.0
        mine = []
        for run in comparison.runs:
            row = {**base, "delay": "default" if delay is None else delay,
                   "applied_delay_s": applied, "method": run.name, "seconds": seconds}
            if run.result is None:
                row["refused"] = (run.error or "refused").splitlines()[0]
            else:
                row.update(matrix_row(run.result, M0, B0))
            mine.append(row)
        trusted = next(r for r in mine if r["method"] == comparison.trusted)
        rows += [*mine, {**trusted, "method": "trusted", "trusted": comparison.trusted}]
    start = time.perf_counter()
    full = PhysicalIdentifier().fit(data, platform)
    a = platform.actuator
    truth = {"reflected_mass": a.reflected_mass, "viscous[actuator]": a.viscous,
             "coulomb[actuator]": a.coulomb}
    physical = {**base, "method": "physical", "seconds": time.perf_counter() - start}
    for name, value in truth.items():
        estimate, se = full.parameters_[name], full.parameter_std_errors_[name]
        physical[name] = 100 * (estimate - value) / value
        physical[f"{name} z"] = (estimate - value) / se
    if loaded_data is not None:
        fitted = PhysicalIdentifier(payload=True).fit(loaded_data, platform)
        section = fitted.result_.diagnostics["payload"]
        physical["payload mass"] = 100 * (section["mass"] - PAYLOAD["mass"]) / PAYLOAD["mass"]
        physical["payload centre (mm)"] = 1e3 * float(np.linalg.norm(
            np.subtract(section["com"], PAYLOAD["com"])))
    rows.append(physical)
    return rows


def summary(rows: list[dict]) -> list[str]:
    """Markdown tables: per engine, kind and method the worst over seeds, and the physical
    model's parameters."""
    lines = ["| engine | logs | force delay | method | seeds | Mt diagonal (%) | "
             "Bt diagonal (%) | couplings (%) | within 3 SE (%) | compare time (s) |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    keys = list(dict.fromkeys((r["engine"], r["kind"]) for r in rows))
    cases = list(dict.fromkeys((r["engine"], r["kind"], r["delay"]) for r in rows
                               if "delay" in r))
    for engine, kind, delay in cases:
        group = [r for r in rows if (r["engine"], r["kind"], r.get("delay")) == (engine, kind,
                                                                                  delay)]
        applied = [r["applied_delay_s"] for r in group if r["method"] == "trusted"]
        span = (f"applied {1e3 * min(applied):.1f} to {1e3 * max(applied):.1f} ms" if any(applied)
                else "none applied")
        delay_text = (f"as identify takes it, {span}" if delay == "default"
                      else f"estimated (--delay auto), {span}" if delay == "auto"
                      else f"{delay:g} s (given)")
        for method in [*METHODS, "trusted"]:
            mine = [r for r in group if r["method"] == method]
            if not mine:
                continue
            fitted = [r for r in mine if "refused" not in r]
            refused = [r for r in mine if "refused" in r]
            name = method
            if method == "trusted":
                chosen = sorted(dict.fromkeys(r["trusted"] for r in mine))
                name = f"trusted ({', '.join(chosen)})"
            if fitted:
                worst = {k: max(r[k] for r in fitted) for k in ("Mt diagonal", "Bt diagonal",
                                                               "couplings")}
                share = 100 * np.mean(np.concatenate([r["within"] for r in fitted]))
                cells = (f"{worst['Mt diagonal']:.2f} | {worst['Bt diagonal']:.2f} | "
                         f"{worst['couplings']:.2f} | {share:.0f}")
            else:
                cells = "– | – | – | –"
            if refused:
                cells += f" (refused on {len(refused)}: {refused[0]['refused'][:80]})"
            seconds = np.mean([r["seconds"] for r in mine])
            lines.append(f"| {engine} | {kind} | {delay_text} | {name} | {len(mine)} | "
                         f"{cells} | {seconds:.0f} |")
    lines += ["", "| engine | logs | seeds | reflected mass (%) | leg viscous (%) | "
              "leg Coulomb (%) | largest \\|z\\| | payload mass (%) | payload centre (mm) | "
              "physical time (s) |", "|---|---|---|---|---|---|---|---|---|---|"]
    for engine, kind in keys:
        mine = [r for r in rows if (r["engine"], r["kind"], r["method"])
                == (engine, kind, "physical")]
        if not mine:
            continue

        def span(key: str, mine=mine) -> str:
            values = [r[key] for r in mine if key in r]
            if not values:
                return "–"
            return f"{min(values):+.2f} to {max(values):+.2f}"

        z = max(abs(r[f"{n} z"]) for r in mine for n in
                ("reflected_mass", "viscous[actuator]", "coulomb[actuator]"))
        centre = [r["payload centre (mm)"] for r in mine if "payload centre (mm)" in r]
        lines.append(f"| {engine} | {kind} | {len(mine)} | {span('reflected_mass')} | "
                     f"{span('viscous[actuator]')} | {span('coulomb[actuator]')} | {z:.1f} | "
                     f"{span('payload mass')} | "
                     f"{(f'{max(centre):.1f}' if centre else '–')} | "
                     f"{np.mean([r['seconds'] for r in mine]):.1f} |")
    return lines


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--engine", default="ours", choices=["ours", "mujoco"])
    parser.add_argument("--seeds", type=int, default=8)
    parser.add_argument("--duration", type=float, default=20.0, help="s per experiment")
    parser.add_argument("--kinds", default=",".join(KINDS))
    parser.add_argument("--delays", default="default,0",
                        help="force delays given to compare_methods: 'default' (as identify "
                             "takes them), 'auto' (estimated) and/or seconds")
    parser.add_argument("--no-payload", action="store_true",
                        help="skip the loaded platform's logs and payload mode")
    parser.add_argument("--cache", type=Path, default=Path("electric_study_logs"),
                        help="folder of the noise-free logs (simulated when missing)")
    parser.add_argument("--out", type=Path, help="JSON lines of every row")
    parser.add_argument("--summary", type=Path, nargs="*",
                        help="print the tables of earlier --out files and stop")
    args = parser.parse_args()
    if args.summary:
        rows = [json.loads(line) for path in args.summary
                for line in path.read_text().splitlines()]
        print("\n".join(summary(rows)))
        return
    platform = electric_platform()
    loaded = platform.replace(**{f"payload__{k}": v for k, v in PAYLOAD.items()})
    delays = [None if v == "default" else v if v == "auto" else float(v)
              for v in args.delays.split(",")]
    rows = []
    for kind in args.kinds.split(","):
        tag = f"{args.engine}-{kind}-{args.duration:g}s"
        clean = clean_logs(platform, kind, args.engine, args.duration, args.cache / tag)
        clean_loaded = (None if args.no_payload else clean_logs(
            loaded, kind, args.engine, args.duration, args.cache / f"{tag}-payload"))
        for seed in range(args.seeds):
            data = measured(platform, clean, seed)
            loaded_data = None if clean_loaded is None else measured(loaded, clean_loaded, seed)
            new = seed_rows(platform, kind, args.engine, seed, data, loaded_data, delays)
            rows += new
            if args.out:
                with args.out.open("a") as handle:
                    handle.writelines(json.dumps(r) + "\n" for r in new)
            print(f"{args.engine} {kind} seed {seed}: " + "; ".join(
                f"{r['method']} {r.get('delay', '')} " + ("refused" if "refused" in r else
                                     f"{r.get('Mt diagonal', float('nan')):.2f}/"
                                     f"{r.get('Bt diagonal', float('nan')):.2f}")
                for r in new), flush=True)
    print(f"electric.toml, {args.engine}, {args.seeds} seeds, 6 x {args.duration:g} s at "
          f"{platform.sensors.sample_rate:g} Hz, --noise")
    print("\n".join(summary(rows)))


if __name__ == "__main__":
    main()
