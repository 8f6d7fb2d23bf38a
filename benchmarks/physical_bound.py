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

With ``--payload-default PLATFORM`` (paper or a platform TOML file) the bound is taken on the
very records of ``payload_default.py`` at ``--ratio`` (their noise-free motion, differentiated;
the loaded platform's reference noise): full mode's payload, the moving body's ten parameters
minus the file's own, as mass (%), centre (largest coordinate error, mm) and inertia diagonal
about the centre (%), their standard errors by the delta method; then ``--seeds`` fits in full
mode on the same records with that script's noise, scored the same way, beside the bound's
prediction for the worst of them (median and 90th percentile of the Gaussian's worst over the
seeds). ``--electric sines|alldof`` does the same on ``electric_study.py``'s cached logs: full
mode's leg parameters (reflected mass, viscous and Coulomb friction along the legs, %) and
payload mode's payload (mass %, centre distance mm), each record's current noise as a seed
measures it; the fits once as they are and once with the Coulomb signs' rates taken from the
noise-free pose (``--true-signs``), which tells a bias of the signs from the encoder counts.

Usage::

    python benchmarks/physical_bound.py [--platforms paper,example] [--motions 1:1,3:3,0.5:0.5,0.333:0.333]
        [--draws 100000]
    python benchmarks/physical_bound.py --payload-default paper|FILE [--ratio 0.2] [--engine ours|mujoco]
        [--duration 20] [--seeds 8] [--clean DIR]
    python benchmarks/physical_bound.py --electric sines|alldof [--engine ours|mujoco] [--duration 20]
        [--seeds 4] [--true-signs] --cache DIR
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import sys
from pathlib import Path
from unittest import mock

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import physical_study  # noqa: E402  (a sibling script)

from stewartid.design.multisine import all_dofs_multisine  # noqa: E402
from stewartid.design.physical.information import predict_parameters  # noqa: E402
from stewartid.model import regressor as reg  # noqa: E402
from stewartid.physical import regression as physical_regression  # noqa: E402
from stewartid.physical.estimator import PhysicalIdentifier, parameter_model  # noqa: E402
from stewartid.physical.regression import leg_force_transforms  # noqa: E402
from stewartid.signals.differentiation import differentiate  # noqa: E402
from stewartid.signals.sign_rates import coulomb_sign_rates  # noqa: E402
from stewartid.simulation import degrade  # noqa: E402
from stewartid.simulation.sensors import REFERENCE_CURRENT_NOISE, reference_noise  # noqa: E402

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


def logged_states(records: list, rate_hz: float = RATE) -> list[tuple[np.ndarray, ...]]:
    """Each noise-free log's q, q_dot, q_ddot at ``rate_hz``, each (K, 6): Savitzky-Golay of
    order 5 over 20 ms at the log's rate (exact to round-off on these smooth records)."""
    out = []
    for data in records:
        step = round(data.sample_rate / rate_hz)
        out.append(tuple(x[::step] for x in differentiate(data.pose, data.sample_rate, 0.02, 5)))
    return out


def fisher_covariance(platform, states: list, sigmas: list, payload: bool,
                      fixed: tuple[str, ...] = (), per_row: float = 1.0
                      ) -> tuple[tuple[str, ...], np.ndarray]:
    """Cramér-Rao covariance of the physical model's parameters (NaN for ``fixed``).

    ``states``: per record (q, q_dot, q_ddot); ``sigmas``: per record the leg forces' white
    noise (6,) N; each row stands for ``per_row`` logged samples. The information is
    sum_k X_k^T S^-1 X_k of the rows in leg forces, the motion known exactly.
    """
    names, _, selection, _, _ = parameter_model(platform, payload)
    free = ~np.isin(names, fixed)
    information = 0.0
    for (q, q_dot, q_ddot), sigma in zip(states, sigmas, strict=True):
        X = np.einsum("kij,kjp->kip", leg_force_transforms(platform, q),
                      reg.regressor(platform, q, q_dot, q_ddot) @ selection.T, optimize=True)
        X = X[:, :, free]
        information = information + np.einsum("kcp,c,kcq->pq", X, np.asarray(sigma) ** -2.0, X,
                                              optimize=True)
    scale = np.sqrt(np.diag(information))
    inverse = np.linalg.inv(information / np.outer(scale, scale)) / np.outer(scale, scale)
    covariance = np.full((len(names),) * 2, np.nan)
    covariance[np.ix_(free, free)] = inverse / per_row
    return tuple(names), covariance


def payload_quantities(body: np.ndarray) -> np.ndarray:
    """Mass (kg), centre (3,) m and inertia diagonal about it (3,) kg m^2 of ten body parameters."""
    m, c, inertia = reg.about_centre_of_mass(body)
    return np.r_[m, c, inertia[:3]]


def payload_covariance(body: np.ndarray, covariance: np.ndarray) -> np.ndarray:
    """Delta-method covariance (7, 7) of :func:`payload_quantities` from the body's (10, 10)."""
    steps = 1e-6 * np.maximum(np.abs(body), 1e-3 * abs(body[0]))
    G = np.stack([(payload_quantities(body + np.eye(10)[k] * steps[k])
                   - payload_quantities(body - np.eye(10)[k] * steps[k])) / (2 * steps[k])
                  for k in range(10)], axis=1)
    return G @ covariance @ G.T


def payload_scores(error: np.ndarray, truth: np.ndarray, centre: str) -> np.ndarray:
    """Mass (%), centre (mm: ``centre`` "max" the largest coordinate, "norm" the distance) and
    inertia diagonal (%, largest) errors; ``error`` (..., 7) of :func:`payload_quantities`."""
    error = np.asarray(error)
    mass = 100 * np.abs(error[..., 0]) / truth[0]
    c = error[..., 1:4]
    distance = 1e3 * (np.abs(c).max(axis=-1) if centre == "max" else np.linalg.norm(c, axis=-1))
    inertia = 100 * np.max(np.abs(error[..., 4:7]) / truth[4:7], axis=-1)
    return np.stack([mass, distance, inertia], axis=-1)


def worst_of_seeds(scores_of_draws: np.ndarray) -> np.ndarray:
    """Median and 90th percentile (2, q) of the worst over seeds; draws (draws, seeds, q)."""
    return np.quantile(scores_of_draws.max(axis=1), [0.5, 0.9], axis=0)


def body_block(names: tuple[str, ...], covariance: np.ndarray, prefix: str = "") -> np.ndarray:
    """The body's ten parameters' (10, 10) block of a covariance over ``names``."""
    index = [names.index(prefix + n) for n in reg.BODY_PARAMETERS]
    return covariance[np.ix_(index, index)]


@contextlib.contextmanager
def signs_from(poses: list[np.ndarray] | None):
    """The physical model's Coulomb signs' rates from ``poses`` (one per record, in fit order),
    the noise-free ones, instead of the log's; None: unchanged."""
    if poses is None:
        yield
        return
    def rates(q, sample_rate, window, pose_noise):
        # the record this is (the sampling check refits thinned copies): the nearest pose
        steps = [max(1, round(len(p) / len(q))) for p in poses]
        true = min((p[::k][:len(q)] for p, k in zip(poses, steps, strict=True)),
                   key=lambda p: np.inf if len(p) != len(q) else float(np.abs(p - q).mean()))
        return coulomb_sign_rates(true, sample_rate, window, np.zeros_like(pose_noise))

    with mock.patch.object(physical_regression, "coulomb_sign_rates", rates):
        yield


def draws_of(covariance: np.ndarray, seeds: int, draws: int, rng: np.random.Generator
             ) -> np.ndarray:
    """Gaussian draws (draws, seeds, q) of zero mean and ``covariance`` (q, q)."""
    return rng.multivariate_normal(np.zeros(len(covariance)), covariance, size=(draws, seeds))


def payload_default_bound(args, rng: np.random.Generator) -> None:
    """Full mode's payload on payload_default.py's records: the bound beside the fits."""
    import payload_default

    bare = payload_default.bare_platform(args.payload_default)
    truth_payload = payload_default.study_payload(bare, args.ratio)
    loaded = bare.replace(**{f"payload__{k}": v for k, v in truth_payload.items()})
    tag = "paper" if args.payload_default == "paper" else Path(args.payload_default).stem
    path = args.clean / (f"{args.engine}_{tag}_r{args.ratio:g}_d{args.duration:g}_s1.pkl")
    clean = payload_default.clean_records(loaded, args.engine, args.duration, 1.0, path)
    body = reg.parameter_index(reg.BODY_PARAMETERS)
    truth_body = (reg.standard_parameters(loaded) - reg.standard_parameters(bare))[body]
    truth = payload_quantities(truth_body)
    noise = reference_noise(loaded)
    fits = []
    for seed in range(args.seeds):
        data = [degrade(d, loaded, noise, rng=1000 * seed + k) for k, d in enumerate(clean)]
        fitted = PhysicalIdentifier().fit(data, bare)
        names = tuple(fitted.parameters_)
        estimate = np.array([fitted.parameters_[n] for n in reg.BODY_PARAMETERS])
        base = reg.base_parameters(bare)
        own = dict(zip(base.names, base.combination @ reg.standard_parameters(bare),
                       strict=True))
        payload = estimate - np.array([own[n] for n in reg.BODY_PARAMETERS])
        cov = payload_covariance(payload, body_block(names, fitted.covariance_))
        fits.append((payload_quantities(payload) - truth, np.sqrt(np.diag(cov)),
                     tuple(fitted.fixed_)))
        print(f"  seed {seed}: {np.round(payload_scores(fits[-1][0], truth, 'max'), 3)}, "
              f"fixed {fits[-1][2]}", file=sys.stderr, flush=True)
    fixed = tuple(sorted(set().union(*(f[2] for f in fits)))) if fits else ()
    states = logged_states(clean)
    per_row = clean[0].sample_rate / RATE
    sigma = np.broadcast_to(np.asarray(noise.force_noise, dtype=float), 6)
    names, covariance = fisher_covariance(bare, states, [sigma] * len(states), False, fixed,
                                          per_row)
    bound = payload_covariance(truth_body, body_block(names, covariance))
    # the estimator's own prediction: its kernel and the pose noise's first-order share too
    design = all_dofs_multisine(len(clean) * 20.0, 1.0)  # records as the logs' (ends)
    design = dataclasses.replace(design, records=tuple(
        dataclasses.replace(r, duration=args.duration) for r in design.records))
    prediction = predict_parameters(bare, design, noise, False, RATE, states=tuple(
        np.concatenate(x) for x in zip(*states, strict=True)), filtered=True)
    kernel = payload_covariance(truth_body, body_block(prediction.names,
                                                       prediction.expected_covariance))
    report_payload(tag, args, truth, bound, kernel, fits, fixed, rng)


def report_payload(tag: str, args, truth: np.ndarray, bound: np.ndarray, kernel: np.ndarray,
                   fits: list, fixed: tuple[str, ...], rng: np.random.Generator) -> None:
    """One table row per quantity: bound, the worst the bound predicts, the fits' worst."""
    labels = ("mass (%)", "centre (mm)", "inertia diagonal (%)")
    se = [100 * np.sqrt(bound[0, 0]) / truth[0], 1e3 * np.sqrt(np.diag(bound)[1:4]).max(),
          100 * np.max(np.sqrt(np.diag(bound)[4:7]) / truth[4:7])]
    predicted = worst_of_seeds(payload_scores(draws_of(bound, args.seeds, args.draws, rng),
                                              truth, "max"))
    with_kernel = worst_of_seeds(payload_scores(draws_of(kernel, args.seeds, args.draws, rng),
                                                truth, "max"))
    observed = payload_scores(np.array([f[0] for f in fits]), truth, "max").max(axis=0)
    fit_se = np.array([f[1] for f in fits])
    z = np.abs(np.array([f[0] for f in fits])) / fit_se
    fit_se_scores = np.stack([100 * fit_se[:, 0] / truth[0], 1e3 * fit_se[:, 1:4].max(axis=1),
                              100 * np.max(fit_se[:, 4:7] / truth[4:7], axis=1)], axis=1)
    print(f"\n{tag}, {args.engine}, payload {args.ratio:g} x the moving mass, "
          f"{len(fits)} seeds, full mode (fixed in some fit, and in the bound: {fixed})")
    print("| quantity | bound SE | fits' SE (median) | bound's worst of the seeds: median "
          "(90 %) | with the kernel and pose noise | observed worst | observed / bound | "
          "within 3 fit SE (largest) |")
    print("|---|---|---|---|---|---|---|---|")
    groups = (slice(0, 1), slice(1, 4), slice(4, 7))
    for k, label in enumerate(labels):
        print(f"| {label} | {se[k]:.3g} | {np.median(fit_se_scores[:, k]):.3g} | "
              f"{predicted[0, k]:.3g} ({predicted[1, k]:.3g}) | {with_kernel[0, k]:.3g} "
              f"({with_kernel[1, k]:.3g}) | {observed[k]:.3g} | "
              f"{observed[k] / predicted[0, k]:.2f} | "
              f"{100 * np.mean(z[:, groups[k]] <= 3):.0f} % ({z[:, groups[k]].max():.1f}) |",
              flush=True)


def electric_bound(args, rng: np.random.Generator) -> None:
    """Full mode's leg parameters and payload mode's payload on electric_study.py's logs."""
    import electric_study

    platform = electric_study.electric_platform()
    loaded = platform.replace(**{f"payload__{k}": v
                                 for k, v in electric_study.PAYLOAD.items()})
    tag = f"{args.engine}-{args.electric}-{args.duration:g}s"
    clean = electric_study.clean_logs(platform, args.electric, args.engine, args.duration,
                                      args.cache / tag)
    clean_loaded = electric_study.clean_logs(loaded, args.electric, args.engine, args.duration,
                                             args.cache / f"{tag}-payload")
    legs = ("reflected_mass", "viscous[actuator]", "coulomb[actuator]")
    a = platform.actuator
    leg_truth = np.array([a.reflected_mass, a.viscous, a.coulomb])
    payload_body = (reg.standard_parameters(loaded) - reg.standard_parameters(platform))[
        reg.parameter_index(reg.BODY_PARAMETERS)]
    payload_truth = payload_quantities(payload_body)
    rows = {}
    for signs in ((False, True) if args.true_signs else (False,)):
        full, payload = [], []
        for seed in range(args.seeds):
            data = electric_study.measured(platform, clean, seed)
            loaded_data = electric_study.measured(loaded, clean_loaded, seed)
            with signs_from([d.pose for d in clean] if signs else None):
                fitted = PhysicalIdentifier().fit(data, platform)
            full.append((np.array([fitted.parameters_[n] for n in legs]) - leg_truth,
                         np.array([fitted.parameter_std_errors_[n] for n in legs]),
                         tuple(fitted.fixed_)))
            with signs_from([d.pose for d in clean_loaded] if signs else None):
                fitted = PhysicalIdentifier(payload=True).fit(loaded_data, platform)
            estimate = np.array([fitted.parameters_[f"payload.{n}"]
                                 for n in reg.BODY_PARAMETERS])
            cov = payload_covariance(estimate, body_block(tuple(fitted.parameters_),
                                                          fitted.covariance_, "payload."))
            payload.append((payload_quantities(estimate) - payload_truth,
                            np.sqrt(np.diag(cov)), tuple(fitted.fixed_)))
            print(f"  signs {'noise-free' if signs else 'logged'}, seed {seed}: legs "
                  f"{np.round(100 * full[-1][0] / leg_truth, 2)} %, payload "
                  f"{np.round(payload_scores(payload[-1][0], payload_truth, 'norm'), 3)}",
                  file=sys.stderr, flush=True)
        rows[signs] = (full, payload)
    per_row = clean[0].sample_rate / RATE
    sigmas = [REFERENCE_CURRENT_NOISE * np.sqrt(np.mean(d.forces ** 2, axis=0)) for d in clean]
    names, covariance = fisher_covariance(platform, logged_states(clean), sigmas, False,
                                          (), per_row)
    index = [names.index(n) for n in legs]
    leg_bound = np.sqrt(np.diag(covariance)[index])
    sigmas = [REFERENCE_CURRENT_NOISE * np.sqrt(np.mean(d.forces ** 2, axis=0))
              for d in clean_loaded]
    names, covariance = fisher_covariance(platform, logged_states(clean_loaded), sigmas, True,
                                          (), per_row)
    payload_bound = payload_covariance(payload_body, body_block(names, covariance, "payload."))
    leg_draws = np.abs(rng.normal(size=(args.draws, args.seeds, 3)) * leg_bound)
    leg_worst = worst_of_seeds(100 * leg_draws / leg_truth)
    payload_worst = worst_of_seeds(payload_scores(
        draws_of(payload_bound, args.seeds, args.draws, rng), payload_truth, "norm"))
    print(f"\nelectric.toml, {args.engine}, {args.electric}, 6 x {args.duration:g} s, {args.seeds} seeds")
    print("| quantity | bound SE | bound's worst of the seeds: median (90 %) | signs | "
          "observed: range (signed) | fits' SE (median) | observed worst / bound | "
          "largest z (fits' SE) |")
    print("|---|---|---|---|---|---|---|---|")
    for signs, (full, payload) in rows.items():
        which = "noise-free pose" if signs else "logged"
        errors = 100 * np.array([f[0] for f in full]) / leg_truth
        ses = 100 * np.array([f[1] for f in full]) / leg_truth
        for k, name in enumerate(legs):
            worst = np.abs(errors[:, k]).max()
            print(f"| full: {name} (%) | {100 * leg_bound[k] / leg_truth[k]:.3g} | "
                  f"{leg_worst[0, k]:.3g} ({leg_worst[1, k]:.3g}) | {which} | "
                  f"{errors[:, k].min():+.3g} to {errors[:, k].max():+.3g} | "
                  f"{np.median(ses[:, k]):.3g} | {worst / leg_worst[0, k]:.2f} | "
                  f"{np.max(np.abs(errors[:, k] / ses[:, k])):.1f} |")
        scores = payload_scores(np.array([f[0] for f in payload]), payload_truth, "norm")
        z = np.abs(np.array([f[0] for f in payload]) / np.array([f[1] for f in payload]))
        signed = 100 * np.array([f[0][0] for f in payload]) / payload_truth[0]
        se_mass = 100 * np.array([f[1][0] for f in payload]) / payload_truth[0]
        se_centre = 1e3 * np.array([np.linalg.norm(f[1][1:4]) for f in payload])
        bound_se = (100 * np.sqrt(payload_bound[0, 0]) / payload_truth[0],
                    1e3 * np.sqrt(np.trace(payload_bound[1:4, 1:4])))
        for k, (label, observed, se) in enumerate((
                ("payload: mass (%)", f"{signed.min():+.3g} to {signed.max():+.3g}", se_mass),
                ("payload: centre (mm, distance)",
                 f"{scores[:, 1].min():.3g} to {scores[:, 1].max():.3g}", se_centre))):
            zk = z[:, 0] if k == 0 else z[:, 1:4]
            print(f"| {label} | {bound_se[k]:.3g} | {payload_worst[0, k]:.3g} "
                  f"({payload_worst[1, k]:.3g}) | {which} | {observed} | "
                  f"{np.median(se):.3g} | {scores[:, k].max() / payload_worst[0, k]:.2f} | "
                  f"{zk.max():.1f} |", flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--platforms", default="paper,example")
    parser.add_argument("--motions", default="1:1,3:3,0.5:0.5,0.333:0.333")
    parser.add_argument("--draws", type=int, default=100_000)
    parser.add_argument("--payload-default", metavar="PLATFORM",
                        help="bound full mode's payload on payload_default.py's records")
    parser.add_argument("--ratio", type=float, default=0.2)
    parser.add_argument("--engine", default="ours", choices=("ours", "mujoco"))
    parser.add_argument("--duration", type=float, default=20.0)
    parser.add_argument("--seeds", type=int, default=8)
    parser.add_argument("--clean", type=Path, default=Path("results/payload_default"),
                        help="payload_default.py's folder of clean records")
    parser.add_argument("--electric", choices=("sines", "alldof"),
                        help="bound the physical model on electric_study.py's logs")
    parser.add_argument("--true-signs", action="store_true",
                        help="also fit with the Coulomb signs' rates of the noise-free pose")
    parser.add_argument("--cache", type=Path, default=Path("electric_study_logs"),
                        help="electric_study.py's folder of noise-free logs")
    args = parser.parse_args()
    rng = np.random.default_rng(0)
    if args.payload_default:
        payload_default_bound(args, rng)
        return
    if args.electric:
        electric_bound(args, rng)
        return
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
