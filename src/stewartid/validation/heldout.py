"""Validation of an identified model on data it was not fitted on: y = J^T f_a - G(q) against
Mt q_ddot + Bt q_dot + Fc(q_dot) + c, both filtered with one zero-phase kernel; per DOF
VAF = 100 (1 - sum e^2 / sum y^2) % and NRMSE = rms(e) / (max y - min y).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import cached_property
from typing import Any

import numpy as np

from stewartid.arrays import median
from stewartid.datasets.dataset import Dataset
from stewartid.errors import DataError, StewartidError
from stewartid.identification.result import IdentificationResult
from stewartid.model.joints import FRICTION_TYPES
from stewartid.platform import Platform
from stewartid.signals.differentiation import share_frequency

#: Default number of time-segment folds.
DEFAULT_FOLDS = 3


@dataclass(frozen=True)
class Segment:
    """One held-out piece of one experiment, filtered for prediction.

    Attributes
    ----------
    name : str
        ``"exp1[0-4 s]"``.
    experiment, fold : int
        Source experiment; fold holding it out.
    t : ndarray, shape (n,)
    force, q_dot, q_ddot : ndarray, shape (n, 6)
        y * h (N, N m), q * h', q * h''.
    coulomb : ndarray, shape (n, 3, 6)
        Filtered generalized Coulomb force per unit level of each joint type.
    window : float
        Support of the filter kernel h, s (NaN when not known).
    """

    name: str
    experiment: int
    fold: int
    t: np.ndarray
    force: np.ndarray
    q_dot: np.ndarray
    q_ddot: np.ndarray
    coulomb: np.ndarray
    window: float = float("nan")

    @cached_property
    def centred_force(self) -> np.ndarray:
        """``force`` less its mean, (n, 6), read-only: what every model's prediction is scored
        against, one array for all of them."""
        centred = self.force - self.force.mean(axis=0)
        centred.flags.writeable = False
        return centred


@dataclass(frozen=True)
class ResidualDelay:
    """Delay of the measured force behind a model's prediction, left in its held-out residuals.

    Attributes
    ----------
    seconds, std_error : float
        The delay (positive: the measured force lags the prediction) and its standard error,
        s; NaN when the regression is singular.
    identifiable : bool
        Whether the motion tells a delay from damping (two or more frequencies in every DOF,
        as :func:`~stewartid.identification.delay.estimate_delay` requires). Where it does
        not, a fit absorbs any delay into Bt and its residuals show none: the numbers say
        nothing about the delay.
    frequencies_hz : tuple of float
        Per DOF, the frequency at which a delay reads as damping in a fit of these segments,
        sqrt(sum q_ddot^2 / sum q_dot^2) / 2 pi: a fit absorbs a delay tau as
        tau (2 pi f)^2 Mt(i, i) on Bt(i, i).
    """

    seconds: float
    std_error: float
    identifiable: bool
    frequencies_hz: tuple[float, ...] = ()

    def significant(self, sigmas: float, floor_s: float) -> bool:
        """Identifiable, more than ``sigmas`` standard errors and ``floor_s`` seconds from 0."""
        return bool(self.identifiable and np.isfinite(self.seconds)
                    and abs(self.seconds) > max(sigmas * self.std_error, floor_s))

    def to_dict(self) -> dict[str, Any]:
        """``validation["residual_delay"]`` of ``result.json``: ``ms``, ``std_ms``
        (None when not computed), ``identifiable``."""
        def ms(value: float) -> float | None:
            return float(value * 1e3) if np.isfinite(value) else None

        return {"ms": ms(self.seconds), "std_ms": ms(self.std_error),
                "identifiable": bool(self.identifiable)}


@dataclass(frozen=True)
class ValidationResult:
    """Held-out prediction scores of one model.

    Attributes
    ----------
    vaf_percent, nrmse : ndarray, shape (6,)
        Per DOF.
    folds : int
    measured, predicted : list of ndarray, each (n_k, 6)
        Centred generalized force of every segment (N, N m).
    segments : list of Segment
    """

    vaf_percent: np.ndarray
    nrmse: np.ndarray
    folds: int
    measured: list[np.ndarray]
    predicted: list[np.ndarray]
    segments: list[Segment]
    residual_delay: ResidualDelay | None = None

    def to_dict(self) -> dict[str, Any]:
        """``validation`` object of ``result.json``: ``vaf_percent``, ``nrmse``, ``folds``, and
        ``residual_delay`` (:meth:`ResidualDelay.to_dict`) where measured."""
        entry = {"vaf_percent": self.vaf_percent.tolist(), "nrmse": self.nrmse.tolist(),
                 "folds": int(self.folds)}
        if self.residual_delay is not None:
            entry["residual_delay"] = self.residual_delay.to_dict()
        return entry


@dataclass(frozen=True)
class CrossValidation:
    """Refits of a k-fold validation and the held-out segments they predict.

    Attributes
    ----------
    folds : int
    fold_results : list of IdentificationResult
        The method refitted without fold k.
    segments : list of Segment
        Every segment of every experiment.
    delay_identifiable : bool or None
        Whether the experiments tell a force delay from damping; None: the scores measure no
        :class:`ResidualDelay`.
    """

    folds: int
    fold_results: list[IdentificationResult]
    segments: list[Segment]
    delay_identifiable: bool | None = None

    def scores(self, adjust: Callable[[IdentificationResult], IdentificationResult]
               | None = None) -> ValidationResult:
        """VAF and NRMSE of the fold models on their held-out segments; ``adjust`` (e.g. the
        physically consistent projection) is applied to every fold's result first.
        """
        results = [r if adjust is None else adjust(r) for r in self.fold_results]
        predicted = [predict(s, results[s.fold]) for s in self.segments]
        return score(self.segments, predicted, self.folds, self.delay_identifiable)


def coulomb_levels(result: IdentificationResult) -> np.ndarray | None:
    """Coulomb level per joint type (N m), shape (3,) in :data:`FRICTION_TYPES` order; None if none."""
    found = result.coulomb
    return None if found is None else found[0]


def prediction_levels(result: IdentificationResult) -> np.ndarray | None:
    """Coulomb levels a result predicts with: its own, else its companion fit's
    (:attr:`~stewartid.identification.result.IdentificationResult.validation_coulomb`), else
    None.
    """
    levels = coulomb_levels(result)
    return levels if levels is not None else result.validation_coulomb


def with_companion_friction(result: IdentificationResult, companion: Callable[[], Any] | None,
                            datasets: Sequence[Dataset], platform: Platform
                            ) -> IdentificationResult:
    """``result`` with the Coulomb levels of a friction-estimating fit of the same data.

    A method leaving friction free would otherwise be scored on friction it never modelled. The
    levels go to ``diagnostics["validation_coulomb"]``; Mt and Bt stay the method's own.
    """
    if companion is None or prediction_levels(result) is not None:
        return result
    try:
        levels = companion().fit(list(datasets), platform).result_.diagnostics.get("coulomb")
    except StewartidError:  # too little data for the companion: predict without friction
        return result
    if not isinstance(levels, dict):
        return result
    return dataclasses.replace(result, diagnostics={**result.diagnostics,
                                                    "validation_coulomb": dict(levels)})


def coulomb_estimate(result: IdentificationResult) -> tuple[np.ndarray, np.ndarray]:
    """Coulomb levels and standard errors per joint type (N m), shape (3,) each; NaN where not estimated."""
    found = result.coulomb
    if found is None:
        nan = np.full(len(FRICTION_TYPES), np.nan)
        return nan, nan
    return found


def prepare_segment(dataset: Dataset, platform: Platform, window: float, *, gravity: bool,
                    experiment: int = 0, fold: int = 0,
                    coulomb_smoothing: float = 1e-4, remainder: bool = False) -> Segment:
    """Filtered force, motion and Coulomb regressors of one record, kernel support ``window`` (s).

    ``gravity`` subtracts G(q); ``remainder`` subtracts
    :func:`~stewartid.identification.preparation.model_remainder`; ``experiment``, ``fold`` label
    the segment; below ``coulomb_smoothing`` (rad/s) a Coulomb sign is attenuated. The motion
    and the Coulomb regressors, which the force's settings leave alone, are computed once per
    record and window (:meth:`~stewartid.datasets.dataset.Dataset.derived`).
    """
    from stewartid.identification.preparation import prepare
    from stewartid.signals.differentiation import kernel_filter

    record = prepare([dataset], platform, gravity=gravity, remainder=remainder)[0]
    t, q_dot, q_ddot, coulomb = dataset.derived(
        ("segment motion", platform, float(window), float(coulomb_smoothing)),
        lambda _: _segment_motion(record, window, coulomb_smoothing))
    force = kernel_filter(record.generalized_force, record.sample_rate, window)[0]
    return Segment(name=dataset.name, experiment=experiment, fold=fold, t=t, force=force,
                   q_dot=q_dot, q_ddot=q_ddot, coulomb=coulomb, window=float(window))


def _segment_motion(record: Any, window: float, coulomb_smoothing: float
                    ) -> tuple[np.ndarray, ...]:
    """``t``, ``q_dot``, ``q_ddot`` and ``coulomb`` of :func:`prepare_segment` for a prepared
    experiment ``record``."""
    from stewartid.identification.least_squares import coulomb_regressors
    from stewartid.identification.wavelet.noise import measured_sign_rates
    from stewartid.signals.differentiation import kernel_filter

    # the signs need rates at every sample, from the window the noise allows
    q_dot_sign = measured_sign_rates(record.q, record.sample_rate, window)
    unit = coulomb_regressors(record.joint_jacobians, q_dot_sign, coulomb_smoothing)
    filtered = kernel_filter(unit.reshape(len(unit), -1), record.sample_rate, window)[0]
    _, q_dot, q_ddot = kernel_filter(record.q, record.sample_rate, window, derivatives=2)
    cut = (len(record.t) - len(q_dot)) // 2
    return (record.t[cut:cut + len(q_dot)], q_dot, q_ddot,
            filtered.reshape(len(q_dot), 3, 6))


def predict(segment: Segment, result: IdentificationResult) -> np.ndarray:
    """Generalized force (n, 6) predicted by ``result`` on ``segment`` (N, N m), not centred."""
    out = segment.q_ddot @ np.asarray(result.M).T + segment.q_dot @ np.asarray(result.B).T
    levels = prediction_levels(result)
    if levels is not None:
        out = out + np.einsum("k,nkc->nc", levels, segment.coulomb)
    return out


def residual_delay(segments: Sequence[Segment], predicted: Sequence[np.ndarray],
                   identifiable: bool) -> ResidualDelay:
    """The delay of the measured force behind the prediction, from the held-out residuals.

    A force logged tau late leaves r = y - y_pred ~ -tau y_pred' (first order). A fit on
    such data absorbs part of it into Mt and Bt, so r is first cleared, channel by channel,
    of what any other Mt, Bt (one pair per fold), Coulomb levels and offsets would explain
    (the regressors q_ddot, q_dot, the Coulomb terms, one constant per segment); tau is the shared
    coefficient of -y_pred' in what is left. Channels are weighted by their residual variance;
    the standard error is a sandwich with a Newey-West long-run covariance over two kernel
    supports, segments independent
    (:func:`~stewartid.identification.delay.shared_least_squares`).

    Parameters
    ----------
    segments : sequence of Segment
    predicted : sequence of ndarray, each (n_k, 6)
        Prediction on each segment (N, N m).
    identifiable : bool
        Whether the motion tells a delay from damping; recorded with the estimate.

    Returns
    -------
    ResidualDelay
        NaN where the delay term is not independent of the model's regressors (one frequency
        per DOF).
    """
    from stewartid.identification.delay import shared_least_squares

    windows = [s.window for s in segments if np.isfinite(s.window)]
    rate = min(1.0 / median(np.diff(s.t)) for s in segments)
    window = min(windows) if windows else 20.0 / rate
    # as the delay estimator: 20 rows per kernel support carry what the filter leaves
    step = max(1, int(window * rate / 20))
    folds = sorted({s.fold for s in segments})
    phis, ys, shared, groups = [], [], [], []
    for k, (segment, p) in enumerate(zip(segments, predicted, strict=True)):
        slope = np.gradient(p, segment.t, axis=0)
        # each fold's own Mt, Bt: their fold-to-fold scatter is no delay
        motion = np.zeros((len(p), len(folds), 12))
        motion[:, folds.index(segment.fold)] = np.concatenate([segment.q_ddot, segment.q_dot],
                                                              axis=1)
        offsets = np.zeros((len(p), len(segments)))
        offsets[:, k] = 1.0
        phis.append(np.concatenate([motion.reshape(len(p), -1), offsets], axis=1)[::step])
        ys.append((segment.force - p)[::step])
        shared.append(np.concatenate([segment.coulomb, -slope[:, None, :]], axis=1)[::step])
        groups.append(np.full(len(ys[-1]), k))
    lags = int(np.ceil(2 * window * rate / step))
    # the least-squares projection of q_dddot on q_dot, per DOF: sum q_ddot^2 / sum q_dot^2
    power = [sum(float(np.sum(getattr(s, name)[:, k] ** 2)) for s in segments)
             for name in ("q_ddot", "q_dot") for k in range(6)]
    frequencies = tuple(float(np.sqrt(power[k] / power[6 + k]) / (2 * np.pi))
                        if power[6 + k] > 0 else float("nan") for k in range(6))
    try:
        c, std = shared_least_squares(np.concatenate(phis), np.concatenate(ys),
                                      np.concatenate(shared), np.concatenate(groups), lags)
    except (StewartidError, np.linalg.LinAlgError):
        return ResidualDelay(float("nan"), float("nan"), bool(identifiable), frequencies)
    return ResidualDelay(float(c[-1]), float(std[-1]), bool(identifiable), frequencies)


def score(segments: Sequence[Segment], predicted: Sequence[np.ndarray], folds: int,
          delay_identifiable: bool | None = None) -> ValidationResult:
    """VAF and NRMSE per DOF of predictions against the segments' measured force; with
    ``delay_identifiable`` set, the :func:`residual_delay` too."""
    measured = [s.centred_force for s in segments]
    centred = [p - p.mean(axis=0) for p in predicted]
    y = np.concatenate(measured)
    error = y - np.concatenate(centred)
    energy = np.sum(y ** 2, axis=0)
    vaf = 100.0 * (1.0 - np.sum(error ** 2, axis=0) / np.where(energy > 0, energy, np.nan))
    spread = y.max(axis=0) - y.min(axis=0)
    nrmse = np.sqrt(np.mean(error ** 2, axis=0)) / np.where(spread > 0, spread, np.nan)
    delay = (None if delay_identifiable is None
             else residual_delay(segments, predicted, delay_identifiable))
    return ValidationResult(vaf_percent=vaf, nrmse=nrmse, folds=int(folds), measured=measured,
                            predicted=centred, segments=list(segments), residual_delay=delay)


def fold_bounds(n: int, folds: int) -> np.ndarray:
    """Sample boundaries of ``folds`` equal segments of ``n`` samples, shape (folds + 1,)."""
    return np.round(np.linspace(0, n, folds + 1)).astype(int)


def time_piece(dataset: Dataset, start: int, stop: int) -> Dataset:
    """Samples ``start:stop`` of a record, named after their time span; one copy per record and
    span, which every method's folds share. Its excitation frequency is the record's: a fold's
    piece may hold a single period of the slowest line, too few to find it."""
    def piece(record: Dataset) -> Dataset:
        t = record.t[start:stop]
        part = record.part(slice(start, stop), f"{record.name}[{t[0]:.4g}-{t[-1]:.4g} s]")
        share_frequency(part.pose, record.pose)
        return part

    return dataset.derived(("piece", int(start), int(stop)), piece)


def excitation_window(dataset: Dataset) -> float:
    """Kernel support (s): 0.2 periods of the record's dominant excitation frequency."""
    from stewartid.signals.differentiation import default_window, estimate_frequency

    return default_window(estimate_frequency(dataset.pose, dataset.sample_rate))


def held_out_segments(datasets: Sequence[Dataset], platform: Platform,
                      folds: int = DEFAULT_FOLDS, gravity: bool = True,
                      remainder: bool = False) -> list[Segment]:
    """Every fold segment of every experiment, filtered (:func:`prepare_segment`)."""
    segments = []
    for e, dataset in enumerate(datasets):
        edges, window = fold_bounds(len(dataset), folds), excitation_window(dataset)
        for k in range(folds):
            segments.append(prepare_segment(time_piece(dataset, edges[k], edges[k + 1]), platform,
                                            window, gravity=gravity, experiment=e, fold=k,
                                            remainder=remainder))
    return segments


def cross_validate(create: Callable[[], Any], datasets: Sequence[Dataset], platform: Platform,
                   folds: int = DEFAULT_FOLDS, gravity: bool = True,
                   segments: list[Segment] | None = None,
                   companion: Callable[[], Any] | None = None,
                   delay_identifiable: bool | None = None) -> CrossValidation:
    """Refit a method without each time segment and prepare the held-out segments.

    Parameters
    ----------
    create : callable
        Returns a new unfitted identifier.
    datasets : sequence of Dataset
    platform : Platform
    folds : int
        Segments per experiment, >= 2.
    gravity : bool
        Whether the method subtracts G(q).
    segments : list of Segment, optional
        From :func:`held_out_segments` with the same ``folds`` and ``gravity``.
    companion : callable, optional
        Friction-estimating identifier lending Coulomb levels (:func:`with_companion_friction`).
    delay_identifiable : bool, optional
        Whether the experiments tell a force delay from damping; when given, the scores
        measure the :func:`residual_delay`.

    Raises
    ------
    DataError
        ``folds`` < 2, or a refit fails on too short remaining data.
    """
    if not (isinstance(folds, int | np.integer) and folds >= 2):
        raise DataError(f"validation needs at least 2 folds; got {folds!r}.")
    bounds = [fold_bounds(len(d), folds) for d in datasets]
    fold_results = []
    for k in range(folds):
        training = []
        for dataset, edges in zip(datasets, bounds, strict=True):
            for start, stop in ((0, edges[k]), (edges[k + 1], len(dataset))):
                if stop - start > 1:
                    training.append(time_piece(dataset, start, stop))
        try:
            fold_results.append(with_companion_friction(
                create().fit(training, platform).result_, companion, training, platform))
        except StewartidError as exc:
            raise DataError(f"validation fold {k + 1} of {folds} (segment {k + 1} of every "
                            f"experiment held out) cannot be fitted: {exc} Record longer "
                            "experiments or use fewer folds.") from exc
    if segments is None:
        segments = held_out_segments(datasets, platform, folds, gravity)
    return CrossValidation(folds=int(folds), fold_results=fold_results, segments=segments,
                           delay_identifiable=delay_identifiable)


def record_segments(datasets: Sequence[Dataset], platform: Platform, gravity: bool = True,
                    remainder: bool = False) -> list[Segment]:
    """Validation records, each whole, filtered as held-out segments (fold 0)."""
    return [prepare_segment(dataset, platform, excitation_window(dataset), gravity=gravity,
                            experiment=k, remainder=remainder)
            for k, dataset in enumerate(datasets)]


def validate_on_records(result: IdentificationResult, segments: Sequence[Segment]
                        ) -> ValidationResult:
    """Scores (``folds`` = 0) of a model fitted on all experiments, on records of another
    excitation: other motion shows a wrong parameter friction compensated.
    """
    return score(segments, [predict(s, result) for s in segments], folds=0)


def validation_entry(held_out: ValidationResult, records: ValidationResult | None = None
                     ) -> dict[str, Any]:
    """``validation`` object of ``result.json``, with ``"records"`` scores when given."""
    entry = held_out.to_dict()
    if records is not None:
        entry["records"] = {"vaf_percent": records.vaf_percent.tolist(),
                            "nrmse": records.nrmse.tolist(),
                            "names": [s.name for s in records.segments]}
    return entry


#: Eigenvalues of the Coulomb regressors' normal matrix below this fraction of the largest are
#: taken as zero by :func:`friction_signature` (a joint type that never moves).
SIGNATURE_RANK_CUT = 1e-12


def friction_signature(validation: ValidationResult) -> float:
    """Share of the held-out residual shaped like Coulomb joint friction: 0 none, near 1
    mostly friction the model lacks (RMS-scaled residuals fitted with the three Coulomb regressors).
    """
    measured = np.concatenate(validation.measured)
    scale = np.sqrt(np.mean(measured ** 2, axis=0))
    scale = np.where(scale > 0, scale, 1.0)
    residual = (measured - np.concatenate(validation.predicted)) / scale
    energy = float(np.sum(residual ** 2))
    if energy == 0:
        return 0.0
    # the fitted share from the regressors' normal equations (a few columns over many rows),
    # summed segment by segment and channel by channel: R_c^T R_c and R_c^T r_c
    types = validation.segments[0].coulomb.shape[1]
    gram, rhs, start = np.zeros((types, types)), np.zeros(types), 0
    for segment in validation.segments:
        rows = segment.coulomb - segment.coulomb.mean(axis=0)             # (n, types, 6)
        columns = np.ascontiguousarray((rows / scale).transpose(2, 1, 0))  # (6, types, n)
        gram += (columns @ columns.transpose(0, 2, 1)).sum(axis=0)
        rhs += np.einsum("ctn,nc->t", columns, residual[start:start + len(rows)])
        start += len(rows)
    values, vectors = np.linalg.eigh(gram)
    kept = values > SIGNATURE_RANK_CUT * max(values[-1], 0.0)
    projected = vectors[:, kept].T @ rhs
    return float(np.sum(projected ** 2 / values[kept]) / energy)


def in_sample(segments: Sequence[Segment], result: IdentificationResult) -> ValidationResult:
    """Scores of the model fitted on all data, on the same segments."""
    return score(segments, [predict(s, result) for s in segments], folds=1)


__all__ = ["DEFAULT_FOLDS", "CrossValidation", "ResidualDelay", "Segment", "ValidationResult",
           "coulomb_estimate", "coulomb_levels", "cross_validate", "excitation_window", "fold_bounds",
           "friction_signature", "held_out_segments", "in_sample", "predict", "prediction_levels",
           "prepare_segment", "record_segments", "residual_delay", "score", "validate_on_records",
           "validation_entry", "with_companion_friction"]
