"""Screw friction on MuJoCo beside our electric plant: where MuJoCo's electric logs depart from
the rigid-body model, and whether that departure is the whole gap between the engines'
identification results.

Data: ``src/stewartid/data/electric.toml`` (80 N of Coulomb friction along each leg). Two parts:

1. One experiment, noise off, on both engines (``--dof``, a 1 Hz sine of the study's amplitude,
   ``--duration`` s): per leg, the friction transitions at the rate reversals (|friction| < 0.99
   Fc after the first second), their length and the leg's travel during them; MuJoCo's own
   friction force (the slide's friction row, ``efc_force``) against the model's law
   Fc l' / sqrt(l'^2 + s^2) (s = ``COULOMB_SMOOTHING``) on MuJoCo's exact rate; and the logged
   force against the model's inverse dynamics on the exact states (accelerations by finite
   differences of the rates).
2. ``--study-cache DIR``: the logs of ``electric_study.py`` (its cache layout,
   ``mujoco-<kind>-<duration>s``) played on MuJoCo with each slide's ``frictionloss`` replaced by
   that law, applied as ``qfrc_applied`` at every integrator stage; ``electric_study.py --engine
   mujoco --cache DIR`` then identifies them. Everything else (armature, damping, current loops,
   servo, welds) is MuJoCo's as ``simulate --engine mujoco`` builds it.

Usage::

    python benchmarks/mujoco_screw_friction.py [--dof 3] [--duration 3]
        [--study-cache DIR --kinds sines,alldof --study-duration 5]
"""

from __future__ import annotations

import argparse
from importlib import resources
from pathlib import Path

import numpy as np

import stewartid as sid
from stewartid.datasets.dataset import write_dataset
from stewartid.model.dynamics import COULOMB_SMOOTHING, inverse_dynamics
from stewartid.mujoco import closed_loop
from stewartid.mujoco import model as mjcf
from stewartid.mujoco import state as mujoco_state
from stewartid.simulation import DEFAULT_AMPLITUDES, SensorNoise, Sine, multisine_excitation
from stewartid.simulation.experiments import simulate_experiment

#: Frequency of the probe's sine (Hz), the study's.
SINE_HZ = 1.0
#: Samples before this time (s) are left out: the command's fade-in and the first reversal.
SETTLE = 1.0


def electric_platform():
    """The example electric platform, data/electric.toml."""
    with resources.as_file(resources.files("stewartid") / "data/electric.toml") as path:
        return sid.load_platform(path)


def sign_law(rates: np.ndarray, coulomb: float) -> np.ndarray:
    """The model's Coulomb force along a leg (N) at leg ``rates`` (m/s), opposing them with a minus."""
    return coulomb * rates / np.sqrt(rates ** 2 + COULOMB_SMOOTHING ** 2)


def play_mujoco(platform, excitation, duration: float, *, sign_friction: bool = False,
                probe: dict | None = None):
    """``simulate_mujoco`` of ``excitation``; with ``sign_friction`` the slides' frictionloss is
    replaced by :func:`sign_law` (applied forces); ``probe``, if given, gets per sample the slides'
    rates (m/s) and the forces of their friction rows (N, generalized, opposing the rate).

    Wraps the module's recorder: a diagnostic, not an engine option.
    """
    mj = mjcf.require_mujoco()
    coulomb = platform.actuator.coulomb
    record, load = closed_loop._record, mjcf.load_model

    def recorder(platform, model, data, control, force, n, per, name):
        dofs = mujoco_state.Indices(model).slide_dof

        def applied(m, d):
            control(m, d)
            v = d.qvel[dofs]
            d.qfrc_applied[dofs] = -sign_law(v, coulomb)

        def logged(d):
            if probe is not None:
                rows = d.efc_type[:d.nefc] == mj.mjtConstraint.mjCNSTR_FRICTION_DOF
                friction = np.zeros(model.nv)
                friction[d.efc_id[:d.nefc][rows]] = d.efc_force[:d.nefc][rows]
                probe.setdefault("rates", []).append(d.qvel[dofs].copy())
                probe.setdefault("friction", []).append(friction[dofs])
            return force(d)

        return record(platform, model, data, applied if sign_friction else control, logged, n,
                      per, name)

    closed_loop._record = recorder
    if sign_friction:
        mjcf.load_model = lambda platform, **options: load(platform, **{**options,
                                                                        "coulomb": False})
    try:
        return closed_loop.simulate_mujoco(platform, excitation, duration)
    finally:
        closed_loop._record, mjcf.load_model = record, load


def transitions(friction: np.ndarray, lengths: np.ndarray, coulomb: float, start: int):
    """Length (samples) and leg travel (m) of each interval from ``start`` where |friction| < 0.99
    Fc; ``friction`` and ``lengths`` (N,) of one leg."""
    inside = np.abs(friction) < 0.99 * coulomb
    inside[:start] = False
    edges = np.flatnonzero(np.diff(inside.astype(int))) + 1
    if inside[-1]:
        edges = np.append(edges, inside.size)
    spans = list(zip(edges[::2], edges[1::2], strict=True))
    return [(b - a, float(np.ptp(lengths[a:b]))) for a, b in spans], inside


def probe(platform, dof: int, duration: float) -> None:
    """Part 1: print the transitions and the force errors per leg."""
    a = platform.actuator
    fs = platform.sensors.sample_rate
    start = int(SETTLE * fs)
    excitation = multisine_excitation(platform, [Sine(dof, DEFAULT_AMPLITUDES[dof], SINE_HZ)],
                                      name=f"dof{dof + 1}")
    _, ours = simulate_experiment(platform, excitation, duration, noise=SensorNoise())
    seen: dict = {}
    theirs = play_mujoco(platform, excitation, duration, probe=seen)
    rates, friction = np.array(seen["rates"]), -np.array(seen["friction"])
    q, q_dot = theirs.pose, np.gradient(theirs.pose, 1 / fs, axis=0)
    model_force = inverse_dynamics(platform, q, q_dot, np.gradient(q_dot, 1 / fs, axis=0))
    ours_friction = sign_law(ours.length_rates, a.coulomb)
    print(f"{excitation.name}, 1 Hz sine, {duration:g} s at {fs:g} Hz, noise off; from t = "
          f"{SETTLE:g} s. Transitions: |friction| < 0.99 Fc, length in ms, travel in um.")
    print("| leg | MuJoCo transitions (ms) | travel (um) | plant transitions (ms) | travel (um) | "
          "MuJoCo friction - law: RMS, in transitions (N) | time in transitions (%) | "
          "MuJoCo force - inverse dynamics: RMS (N) | largest |rate| in transitions (m/s) |")
    print("|---|---|---|---|---|---|---|---|---|")
    for k in range(6):
        mine, inside = transitions(friction[:, k], theirs.lengths[:, k], a.coulomb, start)
        plant, _ = transitions(ours_friction[:, k], ours.lengths[:, k], a.coulomb, start)
        error = friction[start:, k] - sign_law(rates[start:, k], a.coulomb)
        within = friction[:, k][inside] - sign_law(rates[:, k][inside], a.coulomb)
        residual = (theirs.forces - model_force)[start:-1, k]
        print(f"| {k + 1} | {', '.join(f'{1e3 * n / fs:.1f}' for n, _ in mine)} | "
              f"{', '.join(f'{1e6 * t:.2f}' for _, t in mine)} | "
              f"{', '.join(f'{1e3 * n / fs:.1f}' for n, _ in plant)} | "
              f"{', '.join(f'{1e6 * t:.1f}' for _, t in plant)} | "
              f"{np.sqrt(np.mean(error ** 2)):.1f}, {np.sqrt(np.mean(within ** 2)):.1f} | "
              f"{100 * inside[start:].mean():.1f} | {np.sqrt(np.mean(residual ** 2)):.1f} | "
              f"{np.abs(rates[:, k][inside]).max():.1e} |")


def study_cache(platform, folder: Path, kinds: list[str], duration: float) -> None:
    """Part 2: the study's logs on MuJoCo with the sign law, in its cache layout."""
    from electric_study import kind_sines  # benchmarks/ is the script's directory

    for kind in kinds:
        target = folder / f"mujoco-{kind}-{duration:g}s"
        target.mkdir(parents=True, exist_ok=True)
        for k in range(6):
            excitation = multisine_excitation(platform, kind_sines(kind, k), name=f"exp{k + 1}")
            write_dataset(play_mujoco(platform, excitation, duration, sign_friction=True),
                          target / f"exp{k + 1}.parquet")
            print(f"  simulated mujoco (sign-law friction) {kind} exp{k + 1}", flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--dof", type=int, default=3, help="0..5 for x, y, z, rx, ry, rz")
    parser.add_argument("--duration", type=float, default=3.0, help="s of the probe")
    parser.add_argument("--study-cache", type=Path, help="write the study's logs here")
    parser.add_argument("--kinds", default="sines,alldof")
    parser.add_argument("--study-duration", type=float, default=5.0)
    args = parser.parse_args()
    platform = electric_platform()
    if args.study_cache is not None:
        study_cache(platform, args.study_cache, args.kinds.split(","), args.study_duration)
    else:
        probe(platform, args.dof, args.duration)


if __name__ == "__main__":
    main()
