"""The physical model over seeds: payload and full mode against the truth of our plant.

Data: our plant (``--platform paper`` or the example platform
``tests/data/example_c10/platform.toml``) carrying a payload (:data:`PAYLOADS`), Coulomb
30 N m, 6 x 20 s at 1 kHz of all-DOFs-at-once motion (experiment k moves DOF d at
``HZ[(d + k) % 6] / --slower`` Hz, amplitude ``--scale`` times the paper's; the peak use of
the stroke and leg-speed limits is printed). The noise-free records are
simulated once and cached in the temporary folder; each seed adds the reference sensor noise
(:func:`stewartid.simulation.sensors.degrade`). For each seed:

- payload mode on the platform file without its payload: mass (%), centre of mass (mm),
  inertia diagonal about the centre of mass (%);
- full mode on the loaded file: the moving body's base parameters (mass %, first moments
  kg m, inertia diagonal about the reference point %), friction coefficients (%), Mt(q) at
  50 random poses inside the motion's range (diagonal %, couplings % of the diagonal's scale);
- the share of (parameter, seed) pairs within 3 standard errors, and the largest |z|;
- with ``--consistent``, how far the consistent fit moved the parameters (SE).

With ``--engine mujoco`` the records come from the MuJoCo model of the same loaded platform
(:func:`stewartid.mujoco.closed_loop.simulate_mujoco`: another engine's rigid-body algorithms,
Cardan chains and friction constraints, ideal actuators under the PD servo) instead of our
plant.

Usage::

    python benchmarks/physical_study.py [--platform paper|example] [--scale 1] [--slower 1]
        [--seeds 8] [--engine ours|mujoco]
        [--consistent] [--out rows.jsonl]
"""

from __future__ import annotations

import argparse
import hashlib
import json
import pickle
import tempfile
import time
from pathlib import Path

import numpy as np

from stewartid.model import matrix_regressors
from stewartid.model import regressor as reg
from stewartid.model.linearization import nominal_matrices
from stewartid.mujoco.model import DEFAULT_TIMESTEP
from stewartid.physical.estimator import PhysicalIdentifier
from stewartid.platform import load_platform
from stewartid.simulation import (
    DEFAULT_AMPLITUDES,
    SensorNoise,
    Sine,
    degrade,
    multisine_excitation,
    simulate_experiment,
)
from stewartid.simulation.sensors import reference_noise

HZ = (0.3, 0.45, 0.6, 0.75, 0.9, 1.05)
#: The payload of each platform: the physical-model acceptance payload on the paper
#: platform, a quarter-scale one on the example platform.
PAYLOADS = {
    "paper": {"mass": 2000.0, "com": [-0.20, 0.30, -0.50],
              "inertia": [1800.0, 2200.0, 2600.0, -120.0, 80.0, 160.0]},
    "example": {"mass": 1200.0, "com": [0.15, -0.10, -0.40],
                "inertia": [900.0, 1100.0, 1400.0, 60.0, -40.0, 90.0]},
}
DURATION = 20.0
#: MuJoCo's RK4 step (s) for ``--engine mujoco`` (simulate_mujoco's default).
MUJOCO_STEP = DEFAULT_TIMESTEP
EXAMPLE = Path(__file__).resolve().parents[1] / "tests" / "data" / "example_c10" / "platform.toml"


def loaded_platform(name: str):
    """The platform with Coulomb 30 N m and its study payload."""
    base = load_platform("paper" if name == "paper" else EXAMPLE)
    payload = PAYLOADS["paper" if name == "paper" else "example"]
    return base.replace(friction__coulomb=30.0,
                        **{f"payload__{key}": value for key, value in payload.items()})


def clean_records(platform, name: str, scale: float, slower: float = 1.0,
                  engine: str = "ours"):
    """The six noise-free records, simulated once and cached (frequencies ``HZ / slower``):
    on our hydraulic plant, or on the MuJoCo model with ideal actuators (``engine``)."""
    tag = f"{name}-{scale}-{DURATION}-v1" + (f"-{slower}" if slower != 1.0 else "")
    if engine == "mujoco":
        tag += f"-mujoco-{MUJOCO_STEP}-v3"
    key = hashlib.sha1(tag.encode()).hexdigest()[:10]
    cache = Path(tempfile.gettempdir()) / f"stewartid-physical-study-{key}.pkl"
    if cache.exists():
        return pickle.loads(cache.read_bytes())
    out = []
    for k in range(6):
        sines = [Sine(d, DEFAULT_AMPLITUDES[d] * scale, HZ[(d + k) % 6] / slower, 0.5 * d + k)
                 for d in range(6)]
        excitation = multisine_excitation(platform, sines, name=f"exp{k + 1}")
        if engine == "mujoco":
            from stewartid.mujoco.closed_loop import simulate_mujoco

            out.append(simulate_mujoco(platform, excitation, DURATION, step=MUJOCO_STEP))
        else:
            out.append(simulate_experiment(platform, excitation, DURATION, noise=SensorNoise(),
                                           rng=np.random.default_rng(k))[0])
    cache.write_bytes(pickle.dumps(out))
    return out


def limit_peaks(platform, data) -> dict[str, float]:
    """Peak use (1 = the limit) of the stroke and leg speed on the recorded motion."""
    from stewartid.design.limits import resolve_limits
    from stewartid.model.kinematics import leg_lengths

    limits = resolve_limits(platform)
    lengths = np.concatenate([leg_lengths(platform, d.pose) for d in data])
    rates = np.concatenate([np.gradient(leg_lengths(platform, d.pose), d.t, axis=0)
                            for d in data])
    half = (limits.stroke_max - limits.stroke_min) / 2
    return {"stroke": round(float(np.abs(lengths - limits.neutral_length).max() / half), 2),
            "leg_velocity": round(float(np.abs(rates).max() / limits.leg_velocity), 2)}


def z_scores(fitted, truth: dict[str, float]) -> list[float]:
    """(estimate - truth) / SE of every parameter fitted (not fixed) with a known truth."""
    out = []
    for name, value in fitted.parameters_.items():
        se = fitted.parameter_std_errors_[name]
        if name in truth and np.isfinite(se) and se > 0:
            out.append((value - truth[name]) / se)
    return out


def payload_row(fitted, loaded, payload: dict) -> dict:
    """Payload mode's errors against the true payload."""
    section = fitted.result_.diagnostics["payload"]
    m = payload["mass"]
    body = reg.parameter_index(reg.BODY_PARAMETERS)
    own = (reg.standard_parameters(loaded)
           - reg.standard_parameters(loaded.replace(payload=None)))[body]
    truth = {f"payload.{n}": v for n, v in zip(reg.BODY_PARAMETERS, own, strict=True)}
    return {"mass_pct": 100 * abs(section["mass"] - m) / m,
            "com_mm": 1e3 * float(np.max(np.abs(np.subtract(section["com"], payload["com"])))),
            "inertia_pct": float(np.max(100 * np.abs(np.subtract(section["inertia"][:3],
                                                                 payload["inertia"][:3]))
                                        / np.array(payload["inertia"][:3]))),
            "z": z_scores(fitted, truth)}


def mt_errors(fitted, platform, data, rng) -> tuple[float, float]:
    """Largest Mt(q) errors at 50 random poses inside the motion's range: diagonal (%) and
    couplings (% of sqrt(M_ii M_jj))."""
    q = np.concatenate([d.pose for d in data])
    lo, hi = q.min(axis=0), q.max(axis=0)
    names = list(fitted.parameters_)
    base = reg.base_parameters(platform)
    columns = base.columns[[base.names.index(n) for n in names]]
    values = np.array([fitted.parameters_[n] for n in names])
    diag, coupling = 0.0, 0.0
    for pose in rng.uniform(lo, hi, size=(50, 6)):
        A = matrix_regressors.inertia_regressor(platform, pose)
        estimate = A[:, :, columns] @ values
        truth, _ = nominal_matrices(platform, pose)
        scale = np.sqrt(np.outer(np.diag(truth), np.diag(truth)))
        rel = 100 * np.abs(estimate - truth) / scale
        diag = max(diag, float(np.max(np.diag(rel))))
        coupling = max(coupling, float(np.max(rel[~np.eye(6, dtype=bool)])))
    return diag, coupling


def full_row(fitted, platform, data, rng) -> dict:
    """Full mode's errors against the loaded platform's base parameters."""
    base = reg.base_parameters(platform)
    truth = dict(zip(base.names, base.combination @ reg.standard_parameters(platform),
                     strict=True))
    p = fitted.parameters_
    rel = {n: 100 * abs(p[n] - truth[n]) / abs(truth[n]) for n in p if abs(truth[n]) > 1e-9}
    friction = [rel[n] for n in reg.FRICTION_PARAMETERS + reg.ACTUATOR_PARAMETERS
                if n in rel and n not in fitted.fixed_]
    diag, coupling = mt_errors(fitted, platform, data, rng)
    return {"mass_pct": rel["m"],
            "first_moment_kgm": max(abs(p[f"mc_{a}"] - truth[f"mc_{a}"]) for a in "xyz"),
            "inertia_pct": max(rel[f"I_{a}{a}"] for a in "xyz"),
            "friction_pct": max(friction, default=float("nan")),
            "Mt_diag_pct": diag, "Mt_coupling_pct": coupling,
            "fixed": sorted(fitted.fixed_), "z": z_scores(fitted, truth)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--platform", default="paper", choices=["paper", "example"])
    parser.add_argument("--scale", type=float, default=1.0)
    parser.add_argument("--slower", type=float, default=1.0,
                        help="divide the frequencies by this (larger amplitudes within the "
                             "leg-speed limit)")
    parser.add_argument("--seeds", type=int, default=8)
    parser.add_argument("--engine", default="ours", choices=["ours", "mujoco"],
                        help="simulate the records on our hydraulic plant or on the MuJoCo "
                             "model (ideal actuators, the mujoco extra)")
    parser.add_argument("--consistent", action="store_true")
    parser.add_argument("--out", type=Path)
    args = parser.parse_args()
    loaded = loaded_platform(args.platform)
    bare = loaded.replace(payload=None)
    payload = PAYLOADS["paper" if args.platform == "paper" else "example"]
    clean = clean_records(loaded, args.platform, args.scale, args.slower, args.engine)
    print(f"peak use of the limits on the plant's states: {limit_peaks(loaded, clean)}")
    rows = []
    for seed in range(args.seeds):
        data = [degrade(d, loaded, reference_noise(loaded), rng=1000 * seed + k)
                for k, d in enumerate(clean)]
        start = time.perf_counter()
        fit_p = PhysicalIdentifier(payload=True, consistent=args.consistent).fit(data, bare)
        fit_f = PhysicalIdentifier(consistent=args.consistent).fit(data, loaded)
        row = {"seed": seed, "seconds": time.perf_counter() - start,
               "payload": payload_row(fit_p, loaded, payload),
               "full": full_row(fit_f, loaded, data, np.random.default_rng(seed))}
        if args.consistent:
            row["moved_se"] = [f.result_.diagnostics["consistent"]["max_change_std_errors"]
                               for f in (fit_p, fit_f)]
        rows.append(row)
        short = {m: {k: (round(v, 3) if isinstance(v, float) else v) for k, v in row[m].items()
                     if k != "z"} for m in ("payload", "full")}
        print(seed, f"{row['seconds']:.1f}s", json.dumps(short), flush=True)
    for mode in ("payload", "full"):
        z = np.abs(np.concatenate([r[mode]["z"] for r in rows]))
        keys = [k for k in rows[0][mode] if k not in ("z", "fixed")]
        worst = {k: round(max(r[mode][k] for r in rows), 3) for k in keys}
        print(f"{mode}: worst over seeds {worst}; within 3 SE {np.mean(z <= 3):.1%} "
              f"of {len(z)}; largest |z| {z.max():.1f}")
    if args.out:
        args.out.write_text("".join(json.dumps(r) + "\n" for r in rows))


if __name__ == "__main__":
    main()
