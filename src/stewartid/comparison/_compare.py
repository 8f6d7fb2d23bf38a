"""Every method fitted to the same experiments, validated on held-out data and judged: the
:class:`Comparison` behind ``identify --method all``, computed without writing a file."""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from stewartid.comparison._delay import align_experiments, delay_note
from stewartid.comparison._physical import (
    PhysicalRequest,
    physical_fit,
    physical_folds,
    with_physical_folds,
)
from stewartid.comparison._records import MethodFit, PhysicalSection
from stewartid.comparison._runs import (
    FoldFits,
    fit_method,
    judge,
    method_folds,
    same_segments,
    with_folds,
)
from stewartid.datasets.alignment import align_forces
from stewartid.datasets.dataset import Dataset
from stewartid.datasets.plausibility import check_identified
from stewartid.datasets.set_checks import check_experiment_set
from stewartid.errors import ConfigError, StewartidError
from stewartid.identification import registry
from stewartid.identification.averaging import AveragingPolicy, average_experiments
from stewartid.identification.delay import delay_identifiable
from stewartid.identification.result import IdentificationResult
from stewartid.model.linearization import nominal_matrices
from stewartid.parallel import inheriting_workers, longest_first, one_blas_thread, run_in_order
from stewartid.platform import Platform, load_platform
from stewartid.signals.differentiation import acceleration_frequency
from stewartid.validation.heldout import DEFAULT_FOLDS, ResidualDelay, Segment, ValidationResult
from stewartid.verdict.policy import (
    DEFAULT_POLICY,
    VerdictPolicy,
    parse_entries,
    scored_entries,
)
from stewartid.verdict.rule import Verdict, friction_immune, models_friction

#: ``methods`` value that compares every registered method.
ALL_METHODS = "all"


def method_names(methods: str | Sequence[str]) -> tuple[str, ...]:
    """The registered methods ``methods`` names: every method the verdict compares for
    ``"all"`` (presets and the physical model aside), else the names themselves.

    Returns
    -------
    tuple of str
        Registry names.

    Raises
    ------
    ConfigError
        For an unknown name (the message lists the registered ones).
    """
    if isinstance(methods, str):
        if methods == ALL_METHODS:
            return tuple(spec.name for spec in registry.registered_methods()
                         if spec.preset_of is None and spec.compared)
        methods = (methods,)
    return tuple(registry.method_spec(name).name for name in methods)


def plausibility_check(platform: Platform) -> Callable[[IdentificationResult], None]:
    """The physical check of a method's result against the platform description
    (:func:`~stewartid.datasets.plausibility.check_identified`), naming the method: a
    result that fails it counts as the method not applying."""

    def check(result: IdentificationResult) -> None:
        check_identified(result.M, result.B, platform, result.method,
                         not (models_friction(result) or friction_immune(result)),
                         result.std_errors_B)

    return check


@dataclass(frozen=True, repr=False)
class Comparison:
    """Every method's fit, validation and the verdict on which to trust.

    Attributes
    ----------
    runs : tuple of MethodFit
        One per method, in the order asked, the consensus of close methods last when the
        verdict built it.
    verdict : Verdict
    platform : Platform
    experiments : tuple of Dataset
    records : tuple of Dataset
        Validation records of another excitation, predicted and not fitted.
    folds : int
        Time segments per experiment of the held-out validation.
    nominal_M, nominal_B : ndarray, shape (6, 6)
        The reference matrices the results are compared with.
    nominal_source : str
        Where they come from.
    physical : PhysicalSection or None
        The physical model beside the compared methods, when asked for.
    physical_primary : bool
        The physical model was asked for by itself: :attr:`result` is its result.
    seconds : float
        Wall time of the fits, validations and verdict.
    delay : dict or None
        The ``"delay"`` entry of ``result.json``: the force delay the experiments were aligned
        by, or estimated and found within noise of zero.
    delay_sensitivity : dict or None
        Where the motion cannot tell a force delay from damping, the Bt bias per ms of delay.
    averaging : dict or None
        The ``diagnostics["averaging"]`` entry of ``result.json``: the samples averaged into
        one before the fits (:func:`~stewartid.identification.averaging.average_experiments`);
        None when not asked.
    notes : tuple of str
        Sentences for the report's summary.
    """

    runs: tuple[MethodFit, ...]
    verdict: Verdict
    platform: Platform
    experiments: tuple[Dataset, ...]
    records: tuple[Dataset, ...]
    folds: int
    nominal_M: np.ndarray
    nominal_B: np.ndarray
    nominal_source: str
    physical: PhysicalSection | None = None
    physical_primary: bool = False
    seconds: float = 0.0
    delay: dict[str, Any] | None = None
    delay_sensitivity: dict[str, Any] | None = None
    averaging: dict[str, Any] | None = None
    notes: tuple[str, ...] = ()

    @property
    def trusted(self) -> str:
        """Registry name of the method to trust (the only one for a single method)."""
        return self.verdict.trusted

    @property
    def ranking(self) -> tuple[str, ...]:
        """The applicable methods, best first."""
        return self.verdict.ranking

    @property
    def reasons(self) -> list[str]:
        """Why the trusted method was chosen, one sentence each."""
        return list(self.verdict.reasons)

    @property
    def uncertain_entries(self) -> list[dict]:
        """The scored entries the trusted result is unsure of, and why."""
        return list(self.verdict.uncertain)

    @property
    def estimators(self) -> dict[str, Any]:
        """Fitted estimator by method name (methods that refused the data left out)."""
        return {run.name: run.estimator for run in self.runs if run.estimator is not None}

    @property
    def validation(self) -> dict[str, ValidationResult]:
        """Held-out validation (or the validation records' prediction) by method name."""
        return {run.name: run.evidence for run in self.runs if run.evidence is not None}

    @property
    def residual_delays(self) -> dict[str, ResidualDelay]:
        """Force delay left in each method's held-out residuals, by method name
        (:func:`~stewartid.validation.heldout.residual_delay`; ``result.json``:
        ``validation["residual_delay"]``)."""
        return {run.name: run.validation.residual_delay for run in self.runs
                if run.validation is not None and run.validation.residual_delay is not None}

    @property
    def trusted_result(self) -> IdentificationResult:
        """The trusted method's result, with its ``validation`` (and ``verdict`` when several
        methods were compared)."""
        return next(run.result for run in self.runs if run.name == self.trusted)

    @property
    def result(self) -> IdentificationResult:
        """What ``result.json`` holds: the physical model's result with the compared methods'
        verdict when it was asked for by itself, else :attr:`trusted_result`."""
        if self.physical_primary and self.physical is not None and self.physical.result:
            return dataclasses.replace(self.physical.result, verdict=self.verdict.to_dict())
        return self.trusted_result

    @property
    def M(self) -> np.ndarray:
        """The trusted inertia matrix Mt, shape (6, 6) (kg, kg m, kg m^2)."""
        return self.trusted_result.M

    @property
    def B(self) -> np.ndarray:
        """The trusted viscous matrix Bt, shape (6, 6) (N s/m, N m s/rad)."""
        return self.trusted_result.B

    @property
    def std_errors(self) -> dict[str, np.ndarray]:
        """The trusted matrices' standard errors, ``{"M": (6, 6), "B": (6, 6)}``."""
        result = self.trusted_result
        return {"M": result.std_errors_M, "B": result.std_errors_B}

    def __repr__(self) -> str:
        return (f"Comparison(trusted={self.trusted!r}, ranking={self.ranking!r}, "
                f"experiments={len(self.experiments)}, folds={self.folds}, "
                f"uncertain_entries={[u['entry'] for u in self.uncertain_entries]!r})")

    def with_result(self, **fields: Any) -> Comparison:
        """A copy whose :attr:`result` has ``fields`` replaced (e.g. the ``delay`` the data
        were aligned by)."""
        if self.physical_primary and self.physical is not None and self.physical.result:
            physical = dataclasses.replace(
                self.physical, result=dataclasses.replace(self.physical.result, **fields))
            return dataclasses.replace(self, physical=physical)
        runs = tuple(dataclasses.replace(run, result=dataclasses.replace(run.result, **fields))
                     if run.name == self.trusted else run for run in self.runs)
        return dataclasses.replace(self, runs=runs)


def _experiments(experiments: Sequence[Dataset | str | Path], platform: Platform
                 ) -> list[Dataset]:
    from stewartid.datasets.dataset import read_datasets

    return [item if isinstance(item, Dataset) else read_datasets([item], platform)[0]
            for item in experiments]


def check_jobs(jobs: int | None) -> None:
    """Refuse a worker count that is not a whole number of at least 1 (None: every core)."""
    if jobs is not None and not (isinstance(jobs, int | np.integer) and jobs >= 1):
        raise ConfigError(f"jobs (--jobs) must be a whole number of worker processes, 1 or "
                          f"more; got {jobs!r}.")


#: The physical model's tasks among the methods' in :func:`compare_methods`.
PHYSICAL_TASK = "physical model"
#: Each method's two tasks: its full fit, and its fits without each time segment.
FIT, FOLDS = "fit", "folds"
#: The order the workers take the tasks in, longest first on the paper's log (docs/benchmarks.md),
#: so that the short ones fill the workers' ends; other methods' tasks follow. Results do not
#: depend on it.
LONGEST_FIRST = ((PHYSICAL_TASK, FOLDS), ("wavelet", FOLDS), ("ls", FOLDS), ("wavelet", FIT),
                 ("ls", FIT), (PHYSICAL_TASK, FIT), ("fourier", FOLDS), ("fourier", FIT))


@dataclass
class _Work:
    """What every task of :func:`compare_methods` shares; the held-out segments are prepared once
    per worker process and shared by its tasks."""

    settings: dict[str, Any]
    datasets: list[Dataset]
    platform: Platform
    folds: int
    consistent: bool
    check: Callable[[IdentificationResult], None] | None
    records: list[Dataset]
    delay_identifiable: bool
    physical: PhysicalRequest | None
    segments: dict[tuple[bool, bool], list[Segment]] = dataclasses.field(default_factory=dict)
    record_cache: dict[tuple[bool, bool], list[Segment]] = dataclasses.field(
        default_factory=dict)


def _run_task(work: _Work, task: tuple[str, str]) -> Any:
    """One task of :func:`compare_methods`: a method's (or the physical model's) full fit or its
    fold fits; an error the physical model raises is returned, to be raised in task order."""
    name, part = task
    if name == PHYSICAL_TASK:
        if part == FOLDS:
            start = time.perf_counter()
            return (physical_folds(work.datasets, work.platform, work.physical, work.folds,
                                   work.segments), time.perf_counter() - start)
        try:
            return physical_fit(work.datasets, work.platform, work.physical, work.records,
                                work.record_cache)
        except StewartidError as exc:
            return exc
    if part == FOLDS:
        return method_folds(name, work.settings, work.datasets, work.platform, work.folds,
                            work.consistent, work.segments, work.delay_identifiable)
    run = fit_method(name, work.settings, work.datasets, work.platform, work.folds,
                     work.consistent, work.segments, work.check, work.records,
                     work.record_cache)
    if run.in_sample is None:
        return run
    # the folds' task returns the same held-out segments: one copy leaves the worker
    return dataclasses.replace(run, in_sample=dataclasses.replace(
        run.in_sample, segments=None, measured=None))


def _with_segments(run: MethodFit, folds: FoldFits) -> MethodFit:
    """A full fit's in-sample scores given back the held-out segments :func:`_run_task` left out,
    from its folds' task (the same segments)."""
    if run.in_sample is None or run.in_sample.segments is not None or \
            folds.cross_validation is None:
        return run
    segments = folds.cross_validation.segments
    return dataclasses.replace(run, in_sample=dataclasses.replace(
        run.in_sample, segments=segments, measured=[s.centred_force for s in segments]))


def _assembled(names: Sequence[str], physical: PhysicalRequest | None,
               done: Mapping[tuple[str, str], Any]) -> dict[str, Any]:
    """Each method's and the physical model's two tasks joined, by name; the physical model's
    error raised (its full fit's first)."""
    joined: dict[str, Any] = {
        name: with_folds(_with_segments(done[name, FIT], done[name, FOLDS]), done[name, FOLDS])
        for name in names}
    if physical is not None:
        section = done[PHYSICAL_TASK, FIT]
        if isinstance(section, StewartidError):
            raise section
        found, seconds = done[PHYSICAL_TASK, FOLDS]
        joined[PHYSICAL_TASK] = with_physical_folds(section, found, physical, seconds)
    return joined


def _one_copy_of_segments(done: dict[str, Any]) -> dict[str, Any]:
    """Fits made in worker processes each bring back their own copy of the held-out segments;
    the first copy of equal ones serves them all again, as in one process."""
    known: list[list[Segment]] = []

    def canonical(segments: list[Segment]) -> list[Segment]:
        same = next((k for k in known if same_segments(k, segments)), None)
        if same is None:
            known.append(segments)
        return segments if same is None else same

    def scores(found: Any) -> Any:
        if found is None:
            return None
        segments = canonical(found.segments)
        if segments is found.segments:
            return found
        if isinstance(found, ValidationResult):
            return dataclasses.replace(found, segments=segments,
                                       measured=[s.centred_force for s in segments])
        return dataclasses.replace(found, segments=segments)

    fields = ("validation", "validation_unconstrained", "in_sample", "records",
              "cross_validation")
    return {task: dataclasses.replace(item, **{name: scores(getattr(item, name))
                                               for name in fields if hasattr(item, name)})
            for task, item in done.items()}


@one_blas_thread()
def compare_methods(experiments: Sequence[Dataset | str | Path], platform: Platform | str | Path,
                    methods: str | Sequence[str] = ALL_METHODS,
                    validate: Sequence[Dataset | str | Path] | None = None,
                    folds: int = DEFAULT_FOLDS, *, settings: Mapping[str, Any] | None = None,
                    consistent: bool = False, physical: PhysicalRequest | None = None,
                    nominal: tuple[np.ndarray, np.ndarray] | None = None,
                    nominal_source: str | None = None,
                    check: bool | Callable[[IdentificationResult], None] = True,
                    entries: Sequence[str] | None = None,
                    policy: VerdictPolicy = DEFAULT_POLICY,
                    delay: str | float | None = None,
                    averaging: AveragingPolicy | None = None,
                    jobs: int | None = 1) -> Comparison:
    """Fit every method to the same experiments, validate each on held-out time segments and
    say which to trust; writes no file.

    Parameters
    ----------
    experiments : sequence of Dataset (or data files)
        Together they must excite every DOF.
    platform : Platform, or ``"paper"`` or a TOML file
    methods : str or sequence of str
        ``"all"`` (every method the verdict compares), a registered name or several.
    validate : sequence of Dataset (or data files), optional
        Records of another excitation, not fitted: every method predicts them and the verdict
        judges the prediction on them instead of on held-out segments.
    folds : int
        Time segments per experiment for the held-out validation (>= 2).
    settings : mapping, optional
        Settings given to every method that has them (e.g. ``{"gravity": False}``).
    consistent : bool
        Replace every method's Mt, Bt by the nearest physically consistent pair (needs the
        ``convex`` extra) and validate those.
    physical : PhysicalRequest, optional
        Fit the physical model beside the compared methods (not ranked by the verdict); with
        ``physical.required``, :attr:`Comparison.result` is its result.
    nominal : (M, B), optional
        Reference matrices, shape (6, 6) each, the results are compared with; the platform
        description's at neutral by default.
    nominal_source : str, optional
        Where ``nominal`` comes from.
    check : bool or callable
        Check each result against the platform description (:func:`plausibility_check`,
        default) or with a callable that raises a StewartidError; a result that fails counts
        as the method not applying.
    entries : sequence of str, optional
        The entries the verdict judges the methods on, as labels (``"Mt(1,5)"``); by default
        every entry the platform's nominal matrices (with its payload) make non-negligible
        (:func:`~stewartid.verdict.policy.scored_entries`).
    policy : VerdictPolicy
        The verdict's thresholds.
    delay : float, ``"auto"`` or None
        The force channels' delay behind the motion (s; 0: as logged); by default estimated
        where the motion tells it from damping and applied when beyond noise
        (:func:`~stewartid.comparison.align_experiments`).
    averaging : AveragingPolicy or None
        Average experiments sampled well above what the fits need over blocks of samples before
        anything else sees them, as this rule allows (e.g.
        :data:`~stewartid.identification.averaging.DEFAULT_AVERAGING`;
        :func:`~stewartid.identification.averaging.average_experiments`); None (default) keeps
        every sample. The validation records are predicted as logged.
    jobs : int or None
        Worker processes fitting and validating the methods (and the physical model) side by
        side; None: every core (one where workers cannot start by fork,
        :func:`~stewartid.parallel.inheriting_workers`). The results do not depend on it.

    Returns
    -------
    Comparison

    Raises
    ------
    StewartidError
        Bad settings, experiments that fail the checks before any fit (one given twice, a DOF
        left unexcited, force channels numbered differently from the legs:
        :func:`~stewartid.datasets.set_checks.check_experiment_set`), or no method could be
        applied (the first method's message).
    """
    started = time.perf_counter()
    check_jobs(jobs)
    if not isinstance(platform, Platform):
        platform = load_platform(platform)
    if not (isinstance(folds, int | np.integer) and folds >= 2):
        raise ConfigError(f"the validation needs at least 2 folds; got {folds!r}.")
    experiments = _experiments(experiments, platform)
    check_experiment_set(experiments, platform)
    averaged = average_experiments(experiments, averaging)
    alignment = align_experiments(averaged.experiments, platform, delay, jobs)
    datasets = alignment.experiments
    records = _experiments(validate or (), platform)
    if records and alignment.entry is not None and alignment.entry["applied"]:
        records = align_forces(records, alignment.entry["seconds"])
    names = method_names(methods)
    if nominal is None:
        nominal = nominal_matrices(platform)
        nominal_source = nominal_source or (f"platform description '{platform.name}' at the "
                                            "neutral pose")
    checker = plausibility_check(platform) if check is True else (check or None)
    # where one frequency moves a DOF, a fit absorbs a delay into Bt and leaves none to see
    identifiable = alignment.sensitivity is None and delay_identifiable(datasets)
    work = _Work(dict(settings or {}), datasets, platform, folds, consistent, checker,
                 records, identifiable, physical)
    names = tuple(dict.fromkeys(names))
    fitted = (*names, *([PHYSICAL_TASK] if physical is not None else ()))
    tasks = longest_first([(name, part) for name in fitted for part in (FIT, FOLDS)],
                          LONGEST_FIRST)
    workers = inheriting_workers(jobs, len(tasks))
    if workers > 1:  # every task asks for the records' frequencies: found once, inherited
        for dataset in datasets:
            acceleration_frequency(dataset.pose, dataset.sample_rate)
    done = _assembled(names, physical, dict(zip(
        tasks, run_in_order(_run_task, tasks, workers, shared=work), strict=True)))
    if workers > 1:
        done = _one_copy_of_segments(done)
    runs = [done[name] for name in names]
    if all(run.result is None for run in runs):
        raise runs[0].exception
    scored = (parse_entries(entries) if entries is not None
              else scored_entries(*nominal_matrices(platform), policy.negligible_coupling))
    runs, verdict = judge(runs, consistent, scored, policy)
    section = done.get(PHYSICAL_TASK)
    if len(runs) > 1:
        runs = [dataclasses.replace(run, result=dataclasses.replace(
            run.result, verdict=verdict.to_dict())) if run.name == verdict.trusted else run
            for run in runs]
    for record in datasets:  # the fits' terms and time pieces: nothing reads them after the fits
        record.clear_derived()
    comparison = Comparison(
        tuple(runs), verdict, platform, tuple(datasets), tuple(records), folds, nominal[0],
        nominal[1], nominal_source or "", section, physical is not None and physical.required,
        time.perf_counter() - started, alignment.entry, alignment.sensitivity, averaged.entry,
        () if alignment.sensitivity is None else (delay_note(alignment.sensitivity),))
    added = {"averaging": averaged.entry, "delay_sensitivity": alignment.sensitivity}
    added = {key: value for key, value in added.items() if value is not None}
    fields: dict[str, Any] = {}
    if alignment.entry is not None:
        fields["delay"] = alignment.entry
    if added:
        fields["diagnostics"] = {**comparison.result.diagnostics, **added}
    return comparison.with_result(**fields) if fields else comparison


__all__ = ["ALL_METHODS", "Comparison", "compare_methods", "method_names", "plausibility_check"]
