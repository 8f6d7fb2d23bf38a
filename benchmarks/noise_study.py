"""Sensor-noise study: each method's errors against the standard errors it predicts.

Two data sources. By default the independent simulator's example data set (below). With
``--kind paper|three|alldof|tenx`` (several separated by commas), noise-free logs of our own
plant (``--platform paper|FILE``, Coulomb 30 N m, 6 x 20 s; :func:`kind_logs`): the paper's
0.5 Hz sine per DOF, three sines per DOF (0.3, 0.7, 1.5 Hz), all six DOFs at once (one
frequency each) and the paper's sine at ten times its amplitude, with the reference sensor
noise (:func:`stewartid.simulation.sensors.reference_noise`) added per seed; the truth is the
nominal (Mt, Bt). Every registered method and the oracle run on each kind (:func:`kind_study`).
The sibling ``imperfection_study.py`` runs the three-sine logs with a late force channel and
with coloured noise, hum, drift and quantisation.

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
    python benchmarks/noise_study.py --kind three,alldof,tenx [--platform paper|FILE]
        [--clean DIR] [--tag NAME] [--seeds 4] [--methods ...]
"""

from __future__ import annotations

import argparse
import functools
import json
import time
from pathlib import Path

import numpy as np

from stewartid.datasets.dataset import Dataset, read_datasets, write_dataset
from stewartid.identification.registry import create_identifier, registered_methods
from stewartid.model.linearization import nominal_matrices
from stewartid.platform import load_platform
from stewartid.reference.published import PAPER_ENTRIES, relative_error_percent
from stewartid.signals.differentiation import savgol_gain, window_samples
from stewartid.simulation import (
    DEFAULT_AMPLITUDES,
    SensorNoise,
    Sine,
    degrade,
    multisine_excitation,
    simulate_experiment,
)
from stewartid.simulation.sensors import reference_noise

EXAMPLE = Path(__file__).resolve().parents[1] / "tests" / "data" / "example_c10"
#: Method B (default; on one sine per experiment the free interval constants or the Coulomb
#: law, whichever the data choose), with the free constants, with the shared-friction
#: interval constants, with the free constants and a 0.1 s margin, and with the paper's
#: equations; Method A; least squares; and the oracle (least squares given the true Coulomb
#: force, which no user has).
METHODS = {"fourier": functools.partial(create_identifier, "fourier"),
           "ls": functools.partial(create_identifier, "ls"),
           "wavelet": functools.partial(create_identifier, "wavelet"),
           "wavelet_free": functools.partial(create_identifier, "wavelet", friction="free"),
           "wavelet_shared": functools.partial(create_identifier, "wavelet", friction="shared"),
           "wavelet_m01": functools.partial(create_identifier, "wavelet", friction="free",
                                            margin=0.1),
           "wavelet-paper": functools.partial(create_identifier, "wavelet-paper")}


class OracleIdentifier:
    """Least squares given the Coulomb force of the noise-free motion (the efficiency bound a
    friction-immune method is measured against): y - F_coulomb = Mt q_ddot + Bt q_dot + offset
    per experiment (y less the model's nonlinear remainder, as every method's),
    Savitzky-Golay derivatives of the measured pose, standard errors for autocorrelated
    residuals. The window is the longest that passes every excitation line of
    the clean pose with a gain within 1e-3 of 1 (:func:`oracle_window`)."""

    def __init__(self, clean):
        self.clean = clean

    def fit(self, datasets, platform):
        from stewartid.identification.preparation import prepare
        from stewartid.identification.solvers import solve_least_squares
        from stewartid.model.dynamics import friction_forces
        from stewartid.signals.differentiation import differentiate, trim

        viscous_only = platform.replace(friction__coulomb=0.0)
        phis, ys = [], []
        for k, (experiment, clean) in enumerate(zip(prepare(datasets, platform, remainder=True),
                                                    self.clean, strict=True)):
            rate = experiment.sample_rate
            window = oracle_window(clean.lengths, rate)
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


#: Lines of the clean pose's spectrum counted as excitation: local maxima of amplitude above
#: this share of the channel's largest line.
LINE_FLOOR = 1e-2


def leg_length_lines(lengths: np.ndarray, sample_rate: float, floor: float = LINE_FLOOR
                     ) -> tuple[np.ndarray, np.ndarray]:
    """The spectral lines of a clean record with real power, found in the leg lengths (one
    unit for every channel; a pose line is a line of the legs that move).

    Parameters
    ----------
    lengths : ndarray, shape (N, 6)
        Noise-free leg lengths (m).
    sample_rate : float
        Hz.
    floor : float
        A bin counts when its Hann-windowed amplitude on some leg is a local maximum above
        ``floor`` times the largest of any leg.

    Returns
    -------
    frequencies : ndarray, shape (n_lines,)
        Sorted (Hz), zero excluded.
    shares : ndarray, shape (n_lines,)
        Each line's largest amplitude over the largest of any leg.
    """
    centered = lengths - lengths.mean(axis=0)
    amplitude = np.abs(np.fft.rfft(centered * np.hanning(len(lengths))[:, None], axis=0))
    amplitude[0] = 0.0
    # one unit for every channel: shares of the largest line of any leg
    share = amplitude / amplitude.max()
    # local maxima only: the fade-in's leakage around a line is not a line of its own
    local = np.zeros_like(share, dtype=bool)
    local[1:-1] = (share[1:-1] >= share[:-2]) & (share[1:-1] >= share[2:])
    share = np.where(local & (share > floor), share, 0.0).max(axis=1)
    strong = share > 0
    return np.fft.rfftfreq(len(lengths), 1.0 / sample_rate)[strong], share[strong]


def oracle_window(lengths: np.ndarray, sample_rate: float, tolerance: float = 1e-3) -> float:
    """The longest Savitzky-Golay window (s) whose error on the position, velocity and
    acceleration of every excitation line (:func:`leg_length_lines`), |gain - 1| times the
    line's share of that derivative's largest line, stays within ``tolerance`` (longer
    windows average more noise; shorter ones bias less)."""
    frequencies, shares = leg_length_lines(lengths, sample_rate)
    # each derivative's amplitude relative to its largest line
    weights = [shares * frequencies ** d / np.max(shares * frequencies ** d) for d in (0, 1, 2)]

    def worst(window: float) -> float:
        return max(abs(savgol_gain(f, sample_rate, window, deriv=d) - 1.0) * weights[d][i]
                   for i, f in enumerate(frequencies) for d in (0, 1, 2))

    low = window_samples(0.0, sample_rate) / sample_rate
    high = 1.0 / float(frequencies.min())
    if worst(low) > tolerance:
        return low
    while high - low > 1.0 / sample_rate:
        middle = 0.5 * (low + high)
        low, high = (middle, high) if worst(middle) <= tolerance else (low, middle)
    return low

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


def noise_std(estimator, matrix: str) -> np.ndarray:
    """The part of an estimator's standard errors that noise explains (6, 6): Method A's
    without its friction-bias bound, the others' as reported."""
    result = getattr(estimator, "result_", None)
    bias = {} if result is None else result.diagnostics.get("friction_bias") or {}
    noise = bias.get(f"noise_std_{matrix}")
    return estimator.std_errors_[matrix] if noise is None else np.asarray(noise)


def entry_ratios(estimator, M, B, reference=None) -> tuple[np.ndarray, np.ndarray]:
    """Relative errors (%) against (M, B) and |estimate - reference| / standard error over
    the 20 paper entries; ``reference`` (an estimator fitted to noise-free data) isolates the
    noise-induced error from the method's own bias (Method A's Coulomb bias), and is then
    compared with the noise part of the standard errors (:func:`noise_std`); None: truth."""
    errors, ratios = [], []
    for matrix, i, j in PAPER_ENTRIES:
        est = (estimator.M_ if matrix == "M" else estimator.B_)[i, j]
        true = (M if matrix == "M" else B)[i, j]
        ref = true if reference is None else (reference.M_ if matrix == "M"
                                              else reference.B_)[i, j]
        std = estimator.std_errors_[matrix][i, j]
        if reference is not None:
            std = noise_std(estimator, matrix)[i, j]
        errors.append(relative_error_percent(est, true))
        ratios.append(abs(est - ref) / std if std > 0 else np.inf)
    return np.array(errors), np.array(ratios)


def study(methods=tuple(METHODS), seeds=(0, 1, 2, 3), length_noise=20e-6, force_noise=0.005,
          stride=1, datasets=None, scales=(1.0,), sampling_check=True):
    """Rows (method, noise scale, seed, largest error %, err/SE ratios, seconds).

    Every method runs on the noise-free records once and on ``seeds`` noisy copies at every
    nonzero multiple in ``scales`` of (``length_noise``, ``force_noise``). Two ratios per row:
    against the truth (``ratios``) and against the same method's noise-free estimate
    (``noise_ratios``, the noise-induced error the standard errors are meant to predict).

    ``stride`` keeps every stride-th sample of the records (shorter runs for tests);
    ``sampling_check`` False skips the methods' refit at half the rate
    (:mod:`stewartid.identification.sampling`), which changes nothing where the records
    carry noise.
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
                estimator = factory()
                if "sampling_check" in getattr(estimator, "get_params", dict)():
                    estimator.set_params(sampling_check=sampling_check)
                estimator = estimator.fit(data, platform)
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


#: Log kinds of our own plant (:func:`kind_sines`).
KINDS = ("paper", "three", "alldof", "tenx")
#: Coulomb level (N m), record length (s) and sample count of the kinds' logs.
KIND_COULOMB = 30.0
KIND_DURATION = 20.0
#: Frequencies (Hz) of the all-DOFs kind: DOF d of experiment k at ALLDOF_HZ[(d + k) % 6].
ALLDOF_HZ = (0.3, 0.45, 0.6, 0.75, 0.9, 1.05)


def kind_sines(kind: str, k: int) -> list[Sine]:
    """The sines of experiment ``k`` (0..5) of a log kind.

    "paper": DOF k at 0.5 Hz, the paper's amplitude; "three": DOF k at 0.3, 0.7 and 1.5 Hz
    (0.6, 0.3, 0.15 of that amplitude); "alldof": every DOF at 0.7 of its amplitude, each at
    its own frequency (:data:`ALLDOF_HZ`); "tenx": the paper's sine at ten times its amplitude.
    """
    a = DEFAULT_AMPLITUDES[k]
    if kind == "paper":
        return [Sine(k, a, 0.5)]
    if kind == "three":
        return [Sine(k, a * w, f, ph) for w, f, ph in ((0.6, 0.3, 0.0), (0.3, 0.7, 1.0),
                                                        (0.15, 1.5, 2.0))]
    if kind == "alldof":
        return [Sine(d, DEFAULT_AMPLITUDES[d] * 0.7, ALLDOF_HZ[(d + k) % 6], 0.5 * d + k)
                for d in range(6)]
    if kind == "tenx":
        return [Sine(k, 10 * a, 0.5)]
    raise ValueError(f"log kind must be one of {', '.join(KINDS)}; got {kind!r}.")


def kind_platform(name: str):
    """The platform ``name`` ("paper" or a TOML file) with the kinds' Coulomb level."""
    return load_platform(name).replace(friction__coulomb=KIND_COULOMB)


def kind_logs(kind: str, platform, folder: Path, engine: str = "ours") -> list[Dataset]:
    """Noise-free logs exp1..exp6 of a kind, read from ``folder`` when there, else simulated
    (ideal sensors, 1 kHz) and written there first: on our plant, or with ``engine="mujoco"``
    on the MuJoCo model of the same platform (ideal actuators under the PD servo)."""
    paths = [folder / f"exp{k + 1}.csv" for k in range(6)]
    if not all(path.exists() for path in paths):
        folder.mkdir(parents=True, exist_ok=True)
        for k, path in enumerate(paths):
            excitation = multisine_excitation(platform, kind_sines(kind, k), name=f"exp{k + 1}")
            if engine == "mujoco":
                from stewartid.mujoco.closed_loop import simulate_mujoco

                dataset = simulate_mujoco(platform, excitation, KIND_DURATION)
            else:
                dataset, _ = simulate_experiment(platform, excitation, KIND_DURATION,
                                                 noise=SensorNoise(), rng=np.random.default_rng(0))
            write_dataset(dataset, path)
    return read_datasets(paths, platform)


def fit_method(method: str, data, clean, platform):
    """Fit one method (a registered name, a :data:`METHODS` variant or "oracle"); the
    estimator, or the first line of the error that refused the data."""
    if method == "oracle":
        factory = functools.partial(OracleIdentifier, clean)
    else:
        factory = METHODS.get(method, functools.partial(create_identifier, method))
    try:
        return factory().fit(data, platform)
    except Exception as error:  # noqa: BLE001 - a refusal is a result of the study
        return str(error).splitlines()[0]


def kind_study(kind: str, platform_name: str = "paper", folder: Path | None = None,
               methods=None, seeds=(0, 1, 2, 3), tag: str | None = None):
    """Rows (kind, method, seed, largest error %, err/SE ratios) on one log kind: every
    method on the clean logs (seed None) and on ``seeds`` copies with the reference sensor
    noise; the truth is the platform's nominal (Mt, Bt). A method that refuses the data
    gives a row with ``refused`` set to its message. The clean logs live in
    ``folder/TAG_KIND_clean`` (``tag``: default "paper", or the platform file's stem)."""
    platform = kind_platform(platform_name)
    M, B = nominal_matrices(platform)
    tag = tag or ("paper" if platform_name == "paper" else Path(platform_name).stem)
    folder = Path(folder) if folder is not None else Path("noise_study_logs")
    clean = kind_logs(kind, platform, folder / f"{tag}_{kind}_clean")
    methods = methods or [*(spec.name for spec in registered_methods()), "oracle"]
    rows = []
    for seed in [None, *seeds]:
        data = clean if seed is None else [
            degrade(d, platform, reference_noise(platform), np.random.default_rng(seed + 101 * k))
            for k, d in enumerate(clean)]
        for method in methods:
            start = time.perf_counter()
            estimator = fit_method(method, data, clean, platform)
            row = {"kind": kind, "method": method, "seed": seed,
                   "seconds": time.perf_counter() - start, "refused": None}
            if isinstance(estimator, str):
                row["refused"] = estimator
            else:
                errors, ratios = entry_ratios(estimator, M, B)
                row.update(max_error_percent=float(errors.max()), errors=errors, ratios=ratios)
            rows.append(row)
    return rows


def kind_summary(rows) -> list[str]:
    """Markdown table per kind and method: the largest error over the 20 entries on the clean
    logs, its median over the noisy seeds, the share of (entry, seed) pairs within 3
    standard errors and the largest |error| / SE over them."""
    lines = ["| log | method | clean: largest error (%) | noisy: median largest error (%) | "
             "within 3 SE (%) | largest error/SE | time (s) |", "|---|---|---|---|---|---|---|"]
    for kind in dict.fromkeys(r["kind"] for r in rows):
        for method in dict.fromkeys(r["method"] for r in rows if r["kind"] == kind):
            group = [r for r in rows if r["kind"] == kind and r["method"] == method]
            clean = [r for r in group if r["seed"] is None]
            noisy = [r for r in group if r["seed"] is not None and r["refused"] is None]
            refused = [r for r in group if r["refused"] is not None]
            clean_text = (f"{clean[0]['max_error_percent']:.3g}" if clean and not
                          clean[0]["refused"] else "refused")
            if noisy:
                ratios = np.concatenate([r["ratios"] for r in noisy])
                largest = np.median([r["max_error_percent"] for r in noisy])
                cells = f"{largest:.3g} | {100 * np.mean(ratios <= 3):.0f} | {ratios.max():.3g}"
            else:
                cells = "refused | - | -"
            note = f" (refused: {refused[0]['refused'][:90]})" if refused else ""
            lines.append(f"| {kind} | {method}{note} | {clean_text} | {cells} | "
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
    parser.add_argument("--methods", default=None,
                        help="comma-separated; default: the variants of METHODS and the oracle "
                             "on the example data, every registered method and the oracle "
                             "with --kind")
    parser.add_argument("--kind", default=None,
                        help=f"comma-separated log kinds of our plant ({', '.join(KINDS)}) "
                             "instead of the example data set")
    parser.add_argument("--platform", default="paper", help="with --kind: paper or a TOML file")
    parser.add_argument("--clean", type=Path, default=Path("noise_study_logs"),
                        help="with --kind: folder of the clean logs, TAG_KIND_clean/exp1..6.csv "
                             "(simulated and written there when missing)")
    parser.add_argument("--tag", default=None,
                        help="with --kind: TAG of the clean-log folders (default: paper, or the "
                             "platform file's stem)")
    args = parser.parse_args()
    if args.kind:
        methods = args.methods.split(",") if args.methods else None
        rows = []
        for kind in args.kind.split(","):
            rows += kind_study(kind, args.platform, args.clean, methods, tuple(range(args.seeds)),
                               args.tag)
        print(f"platform {args.platform}, Coulomb {KIND_COULOMB:g} N m, reference sensor noise, "
              f"{args.seeds} seeds")
        print("\n".join(kind_summary(rows)))
        return
    args.methods = args.methods or ",".join([*METHODS, "oracle"])
    scales = tuple(float(v) for v in args.scales.split(","))
    rows = study(tuple(args.methods.split(",")), tuple(range(args.seeds)), args.length_noise,
                 args.force_noise, scales=scales)
    print(f"reference: length noise {args.length_noise * 1e6:g} um, force noise "
          f"{100 * args.force_noise:g} % of the mean leg force; {args.seeds} seeds")
    print("\n".join(summary(rows)))


if __name__ == "__main__":
    main()
