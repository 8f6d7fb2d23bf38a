"""A heavy payload on the platform file as built: payload mode and full mode against the truth.

The platform file (``--platform paper|FILE``) has no ``[payload]``; the records are simulated
with a payload of ``--ratios`` times the platform's moving mass (0.2, 1 and 2 by default) at
an offset centre (``R`` x (-0.10, 0.14, -0.24) m, ``R`` the upper radius) with inertia about
its centre ``m k^2`` x (0.8, 1.0, 1.2, -0.05, 0.03, 0.07) (``k = 0.3 R``), on our plant or on
MuJoCo (``--engine mujoco``). Motion: 6 records of every DOF at once (experiment k moves DOF d
at ``physical_study.HZ[(d + k) % 6]`` Hz at the paper's amplitudes times ``--scale``),
``--duration`` s at 1 kHz; the platform's Coulomb level, or 30 N m where it has none. Each
seed adds the reference sensor noise. Both fits are given the bare file, as
``identify --model physical --payload`` and ``identify --model physical`` would be:

- payload mode: the payload's mass (%), centre (largest coordinate error, mm) and inertia
  diagonal about its centre (%);
- full mode: the moving body's base parameters; the payload is their difference from the bare
  file's, scored the same way;
- the share of (parameter, seed) within 3 standard errors and the largest |z| per mode.

Usage::

    python benchmarks/payload_default.py [--platform paper|FILE] [--engine ours|mujoco]
        [--ratios 0.2,1,2] [--seeds 4] [--duration 20] [--scale 1] [--clean DIR]
"""

from __future__ import annotations

import argparse
import pickle
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import physical_study  # noqa: E402  (a sibling script)

from stewartid.model import regressor as reg  # noqa: E402
from stewartid.physical.estimator import PhysicalIdentifier  # noqa: E402
from stewartid.platform import load_platform  # noqa: E402
from stewartid.simulation import (  # noqa: E402
    DEFAULT_AMPLITUDES,
    SensorNoise,
    Sine,
    degrade,
    multisine_excitation,
    simulate_experiment,
)
from stewartid.simulation.sensors import reference_noise  # noqa: E402

#: Acceptance: payload mass (%), centre (mm), inertia diagonal (%).
TARGET = (0.5, 5.0, 5.0)


def bare_platform(name: str):
    """The platform file as built, with its Coulomb level or 30 N m where it has none."""
    platform = load_platform(name)
    if platform.friction.coulomb == 0:
        platform = platform.replace(friction__coulomb=30.0)
    return platform.replace(payload=None)


def study_payload(bare, ratio: float) -> dict:
    """The payload of ``ratio`` times the moving mass at the offset centre."""
    mass = ratio * bare.moving_body.mass
    radius = bare.geometry.upper_radius
    k2 = (0.3 * radius) ** 2
    return {"mass": mass, "com": (radius * np.array([-0.10, 0.14, -0.24])).tolist(),
            "inertia": (mass * k2 * np.array([0.8, 1.0, 1.2, -0.05, 0.03, 0.07])).tolist()}


def clean_records(loaded, engine: str, duration: float, scale: float, path: Path):
    """The six noise-free records, simulated once and kept in ``path``."""
    if path.exists():
        return pickle.loads(path.read_bytes())
    out = []
    for k in range(6):
        sines = [Sine(d, DEFAULT_AMPLITUDES[d] * scale, physical_study.HZ[(d + k) % 6],
                      0.5 * d + k) for d in range(6)]
        excitation = multisine_excitation(loaded, sines, name=f"exp{k + 1}")
        if engine == "mujoco":
            from stewartid.mujoco.closed_loop import simulate_mujoco

            out.append(simulate_mujoco(loaded, excitation, duration))
        else:
            out.append(simulate_experiment(loaded, excitation, duration, noise=SensorNoise(),
                                           rng=np.random.default_rng(k))[0])
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_bytes(pickle.dumps(out))
    return out


def scores(section: dict, payload: dict) -> tuple[float, float, float]:
    """Mass (%), centre (mm, largest coordinate) and inertia diagonal (%) errors."""
    mass = 100 * abs(section["mass"] - payload["mass"]) / payload["mass"]
    com = 1e3 * float(np.max(np.abs(np.subtract(section["com"], payload["com"]))))
    truth = np.array(payload["inertia"][:3])
    inertia = float(np.max(100 * np.abs(np.subtract(section["inertia"][:3], truth)) / truth))
    return mass, com, inertia


def full_payload(fitted, bare) -> dict:
    """The payload full mode implies: its moving body's parameters minus the bare file's."""
    base = reg.base_parameters(bare)
    own = dict(zip(base.names, base.combination @ reg.standard_parameters(bare), strict=True))
    body = np.array([fitted.parameters_[n] - own[n] for n in reg.BODY_PARAMETERS])
    m, c, inertia = reg.about_centre_of_mass(body)
    return {"mass": m, "com": c.tolist(), "inertia": inertia.tolist()}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--platform", default="paper", help="paper or a platform TOML file")
    parser.add_argument("--engine", default="ours", choices=("ours", "mujoco"))
    parser.add_argument("--ratios", default="0.2,1,2")
    parser.add_argument("--seeds", type=int, default=4)
    parser.add_argument("--duration", type=float, default=20.0)
    parser.add_argument("--scale", type=float, default=1.0)
    parser.add_argument("--clean", type=Path, default=Path("results/payload_default"),
                        help="folder of the clean records (simulated there when missing)")
    args = parser.parse_args()
    bare = bare_platform(args.platform)
    tag = "paper" if args.platform == "paper" else Path(args.platform).stem
    print("| platform | engine | payload / moving mass | mode | mass (%) | centre (mm) | "
          "inertia diag. (%) | within 3 SE (largest) | meets 0.5 % / 5 mm / 5 % | seeds |")
    print("|---" * 10 + "|")
    for ratio in (float(r) for r in args.ratios.split(",")):
        payload = study_payload(bare, ratio)
        loaded = bare.replace(**{f"payload__{key}": value for key, value in payload.items()})
        path = args.clean / (f"{args.engine}_{tag}_r{ratio:g}_d{args.duration:g}"
                             f"_s{args.scale:g}.pkl")
        start = time.perf_counter()
        clean = clean_records(loaded, args.engine, args.duration, args.scale, path)
        print(f"{tag} {args.engine} ratio {ratio:g}: records {time.perf_counter() - start:.0f} s,"
              f" limits {physical_study.limit_peaks(loaded, clean)}", file=sys.stderr,
              flush=True)
        body = reg.parameter_index(reg.BODY_PARAMETERS)
        own = (reg.standard_parameters(loaded) - reg.standard_parameters(bare))[body]
        truth_p = {f"payload.{n}": v for n, v in zip(reg.BODY_PARAMETERS, own, strict=True)}
        base = reg.base_parameters(loaded)
        truth_f = dict(zip(base.names, base.combination @ reg.standard_parameters(loaded),
                           strict=True))
        rows = {"payload": [], "full": []}
        z = {"payload": [], "full": []}
        for seed in range(args.seeds):
            data = [degrade(d, loaded, reference_noise(loaded), rng=1000 * seed + k)
                    for k, d in enumerate(clean)]
            for mode in ("payload", "full"):
                try:
                    fitted = PhysicalIdentifier(payload=mode == "payload").fit(data, bare)
                except Exception as error:  # noqa: BLE001 - a refusal is a result
                    rows[mode].append(str(error).splitlines()[0])
                    continue
                section = (fitted.result_.diagnostics["payload"] if mode == "payload"
                           else full_payload(fitted, bare))
                rows[mode].append(scores(section, payload))
                z[mode] += physical_study.z_scores(fitted,
                                                   truth_p if mode == "payload" else truth_f)
            print(f"  seed {seed}: " + "; ".join(
                f"{m} {rows[m][-1] if isinstance(rows[m][-1], str) else np.round(rows[m][-1], 3)}"
                for m in rows), file=sys.stderr, flush=True)
        for mode, found in rows.items():
            fitted = [r for r in found if not isinstance(r, str)]
            if not fitted:
                print(f"| {tag} | {args.engine} | {ratio:g} | {mode} | refused: {found[0]} "
                      f"| | | | no | {args.seeds} |")
                continue
            worst = np.max(fitted, axis=0)
            zs = np.abs(z[mode])
            ok = "yes" if len(fitted) == len(found) and np.all(worst <= TARGET) else "**no**"
            print(f"| {tag} | {args.engine} | {ratio:g} | {mode} | {worst[0]:.3f} | "
                  f"{worst[1]:.2f} | {worst[2]:.2f} | {100 * np.mean(zs <= 3):.0f} % "
                  f"({zs.max():.1f}) | {ok} | {len(fitted)}/{len(found)} |", flush=True)


if __name__ == "__main__":
    main()
