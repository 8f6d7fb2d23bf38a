"""Each method fitted, validated on held-out segments and judged: the steps of
:func:`~stewartid.comparison.compare_methods`."""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from stewartid.comparison._records import MethodFit
from stewartid.datasets.dataset import Dataset
from stewartid.errors import StewartidError
from stewartid.identification import registry
from stewartid.identification.consistency import ConsistentEstimate, project_consistent
from stewartid.identification.result import IdentificationResult
from stewartid.platform import Platform
from stewartid.reference.published import PAPER_ENTRIES, EntryKey
from stewartid.validation.heldout import (
    CrossValidation,
    Segment,
    ValidationResult,
    cross_validate,
    held_out_segments,
    in_sample,
    record_segments,
    validate_on_records,
    validation_entry,
    with_companion_friction,
)
from stewartid.verdict.close_call import CONSENSUS, consensus_members, trust_consensus
from stewartid.verdict.consensus import combine_results
from stewartid.verdict.policy import DEFAULT_POLICY, VerdictPolicy
from stewartid.verdict.rule import Verdict, choose_trusted


def consistent_result(result: IdentificationResult) -> tuple[IdentificationResult,
                                                              ConsistentEstimate]:
    """Replace a result's M and B by the nearest physically consistent pair (needs the
    ``convex`` extra).

    Returns
    -------
    result : IdentificationResult
        ``result`` with the consistent M and B; ``diagnostics["consistent_fit"]`` keeps the
        unconstrained matrices and the change.
    projection : ConsistentEstimate
    """
    projection = project_consistent(result.M, result.B, result.std_errors_M,
                                    result.std_errors_B)
    diagnostics = {**result.diagnostics, "consistent_fit": {
        **projection.to_dict(), "unconstrained_M": result.M, "unconstrained_B": result.B}}
    return dataclasses.replace(result, M=projection.M, B=projection.B,
                               diagnostics=diagnostics), projection


def _project(result: IdentificationResult) -> IdentificationResult:
    return consistent_result(result)[0]


@dataclass(frozen=True)
class FoldFits:
    """One method refitted without each time segment and scored on the held-out segments: the
    half of :func:`run_method` that :func:`~stewartid.comparison.compare_methods` runs beside the
    full fit, in another process.

    Attributes
    ----------
    cross_validation : CrossValidation or None
    validation : ValidationResult or None
        Scores of the fold models (the consistent ones with ``consistent=True``).
    validation_unconstrained : ValidationResult or None
        Of the unconstrained fold models, with ``consistent=True``.
    exception : StewartidError or None
        Why the folds could not be fitted.
    seconds : float
    """

    cross_validation: CrossValidation | None = None
    validation: ValidationResult | None = None
    validation_unconstrained: ValidationResult | None = None
    exception: StewartidError | None = None
    seconds: float = 0.0


def _own_settings(name: str, settings: Mapping[str, Any]) -> dict[str, Any]:
    """The settings the method ``name`` has."""
    accepted = registry.method_spec(name).estimator_class.param_names()
    return {k: v for k, v in settings.items() if k in accepted}


def _terms(params: Mapping[str, Any]) -> tuple[bool, bool]:
    """The model terms (``gravity``, ``remainder``) a method with ``params`` removes: the measured
    side of its held-out prediction."""
    return bool(params.get("gravity", True)), bool(params.get("remainder", False))


def held_out_for(segments: dict[tuple[bool, bool], list[Segment]], terms: tuple[bool, bool],
                 datasets: Sequence[Dataset], platform: Platform, folds: int) -> list[Segment]:
    """The held-out segments prepared with the model ``terms`` (``gravity``, ``remainder``) a
    method removes, from ``segments`` or made there on first use (shared by every task of a
    process)."""
    if terms not in segments:
        segments[terms] = held_out_segments(datasets, platform, folds, *terms)
    return segments[terms]


def _companion(name: str, own: Mapping[str, Any]) -> Callable[[], Any] | None:
    """The friction-estimating identifier that lends a method its Coulomb levels, if it has a
    friction setting."""
    if "friction" not in registry.method_spec(name).estimator_class.param_names():
        return None
    return lambda: registry.estimates_only(name, **{**own, "friction": "uniform"})


def method_folds(name: str, settings: Mapping[str, Any], datasets: Sequence[Dataset],
                 platform: Platform, folds: int, consistent: bool,
                 segments: dict[tuple[bool, bool], list[Segment]],
                 delay_identifiable: bool | None = None) -> FoldFits:
    """The fold fits of one method and their held-out scores (arguments as :func:`run_method`)."""
    start = time.perf_counter()
    own = _own_settings(name, settings)
    terms = _terms(registry.create_identifier(name, **own).get_params())
    try:
        held_out = held_out_for(segments, terms, datasets, platform, folds)
        # the folds and the companion predict: their standard errors are never read
        folds_fit = cross_validate(lambda: registry.estimates_only(name, **own), datasets,
                                   platform, folds, terms[0], held_out,
                                   _companion(name, own), delay_identifiable)
    except StewartidError as exc:
        return FoldFits(exception=exc, seconds=time.perf_counter() - start)
    validation, before = folds_fit.scores(), None
    if consistent:
        before, validation = validation, folds_fit.scores(_project)
    return FoldFits(folds_fit, validation, before, seconds=time.perf_counter() - start)


def fit_method(name: str, settings: Mapping[str, Any], datasets: Sequence[Dataset],
               platform: Platform, folds: int, consistent: bool,
               segments: dict[tuple[bool, bool], list[Segment]],
               check: Callable[[IdentificationResult], None] | None = None,
               records: Sequence[Dataset] = (),
               record_cache: dict[tuple[bool, bool], list[Segment]] | None = None) -> MethodFit:
    """The full fit of one method, checked, with its in-sample residuals and its prediction of
    the validation records, not yet validated on held-out segments (:func:`with_folds`);
    arguments as :func:`run_method`."""
    spec = registry.method_spec(name)
    own = _own_settings(name, settings)
    start = time.perf_counter()
    try:
        estimator = registry.create_identifier(name, **own).fit(list(datasets), platform)
        if check is not None:
            check(estimator.result_)
        terms = _terms(estimator.get_params())
        held_out = held_out_for(segments, terms, datasets, platform, folds)
        unconstrained = with_companion_friction(estimator.result_, _companion(name, own),
                                                datasets, platform)
    except StewartidError as exc:
        return MethodFit(name, spec.display_name, spec.color, error=str(exc),
                         exception=exc, seconds=time.perf_counter() - start)
    result, projection = unconstrained, None
    if consistent:
        result, projection = consistent_result(unconstrained)
    external = None
    if records:
        cache = {} if record_cache is None else record_cache
        if terms not in cache:
            cache[terms] = record_segments(records, platform, *terms)
        # ``result`` holds the companion's levels: the consistent one keeps the diagnostics
        external = validate_on_records(result, cache[terms])
    return MethodFit(name, spec.display_name, spec.color, result=result,
                     unconstrained=unconstrained, in_sample=in_sample(held_out, result),
                     projection=projection, records=external,
                     seconds=time.perf_counter() - start, estimator=estimator)


def with_folds(run: MethodFit, folds: FoldFits) -> MethodFit:
    """A method's full fit (:func:`fit_method`) validated by its fold fits (:func:`method_folds`);
    the full fit's error first, then the folds'."""
    seconds = run.seconds + folds.seconds
    if run.result is None:
        return dataclasses.replace(run, seconds=seconds)
    if folds.exception is not None:
        return MethodFit(run.name, run.display_name, run.color, error=str(folds.exception),
                         exception=folds.exception, seconds=seconds)
    result = dataclasses.replace(run.result,
                                 validation=validation_entry(folds.validation, run.records))
    return dataclasses.replace(run, result=result, validation=folds.validation,
                               validation_unconstrained=folds.validation_unconstrained,
                               seconds=seconds, cross_validation=folds.cross_validation)


def run_method(name: str, settings: Mapping[str, Any], datasets: Sequence[Dataset],
               platform: Platform, folds: int, consistent: bool,
               segments: dict[tuple[bool, bool], list[Segment]],
               check: Callable[[IdentificationResult], None] | None = None,
               records: Sequence[Dataset] = (),
               record_cache: dict[tuple[bool, bool], list[Segment]] | None = None,
               delay_identifiable: bool | None = None) -> MethodFit:
    """Fit, validate and check one method of the comparison.

    Parameters
    ----------
    name : str
        Registered method or preset.
    settings : mapping
        Settings for it (those it does not have are ignored).
    datasets, platform, folds, consistent
        As :func:`~stewartid.comparison.compare_methods`.
    segments : dict
        Held-out segments by (``gravity``, ``remainder``) setting, filled on first use and
        shared between methods.
    check : callable, optional
        Raises a StewartidError for an implausible result (the method then counts as not
        applicable).
    records : sequence of Dataset
        Validation records of another excitation (``identify --validate``), predicted by the
        full fit.
    record_cache : dict, optional
        Their filtered segments by (``gravity``, ``remainder``) setting, filled on first use.
    delay_identifiable : bool, optional
        Whether the experiments tell a force delay from damping; when given, the held-out
        validation measures the delay left in the residuals
        (:func:`~stewartid.validation.heldout.residual_delay`).

    Returns
    -------
    MethodFit
        With ``error`` and ``exception`` instead of a result when the method cannot be
        applied to these data (a :class:`~stewartid.errors.StewartidError`).
    """
    run = fit_method(name, settings, datasets, platform, folds, consistent, segments, check,
                     records, record_cache)
    if run.result is None:
        return run
    return with_folds(run, method_folds(name, settings, datasets, platform, folds, consistent,
                                        segments, delay_identifiable))


def same_segments(a: Sequence[Segment], b: Sequence[Segment]) -> bool:
    """Whether two methods' held-out segments are the same pieces, prepared alike: the same
    ``gravity`` setting gives the same measured force."""
    return a is b or (len(a) == len(b) and all(
        x.name == y.name and np.array_equal(x.force, y.force) for x, y in zip(a, b, strict=True)))


def consensus_run(members: Sequence[MethodFit], consistent: bool,
                  agreement: float = DEFAULT_POLICY.agreement) -> MethodFit | None:
    """The consensus of fitted methods (:func:`~stewartid.verdict.consensus.combine_results`),
    validated as :func:`run_method` validates a method: each fold's consensus of the members'
    fold fits predicts the held-out segments, the full consensus the validation records.

    Parameters
    ----------
    members : sequence of MethodFit
        The close methods, each with its fold fits (``cross_validation``).
    consistent : bool
        As :func:`~stewartid.comparison.compare_methods`.
    agreement : float
        As :func:`~stewartid.verdict.consensus.combine_results`.

    Returns
    -------
    MethodFit or None
        None when the members were validated on differently prepared segments (their
        ``gravity`` settings differ).
    """
    start = time.perf_counter()
    names = [run.name for run in members]
    folds = [run.cross_validation for run in members]
    if any(f is None or not same_segments(f.segments, folds[0].segments) for f in folds):
        return None
    unconstrained = combine_results([run.unconstrained for run in members], names,
                                    agreement)
    fitted = CrossValidation(folds[0].folds, [
        combine_results([f.fold_results[k] for f in folds], names, agreement)
        for k in range(folds[0].folds)], folds[0].segments, folds[0].delay_identifiable)
    validation = fitted.scores()
    result, projection, before = unconstrained, None, None
    if consistent:
        result, projection = consistent_result(unconstrained)
        before, validation = validation, fitted.scores(_project)
    records = members[0].records
    external = None if records is None else validate_on_records(result, records.segments)
    result = dataclasses.replace(result, validation=validation_entry(validation, external))
    spec = registry.method_spec(CONSENSUS)
    return MethodFit(CONSENSUS, spec.display_name, spec.color, result=result,
                        unconstrained=unconstrained, validation=validation,
                        validation_unconstrained=before,
                        in_sample=in_sample(fitted.segments, result), projection=projection,
                        records=external, seconds=time.perf_counter() - start,
                        cross_validation=fitted)


def judge(runs: Sequence[MethodFit], consistent: bool = False,
          entries: Sequence[EntryKey] = PAPER_ENTRIES, policy: VerdictPolicy = DEFAULT_POLICY
          ) -> tuple[list[MethodFit], Verdict]:
    """The verdict on the methods' runs (:func:`~stewartid.verdict.rule.choose_trusted`) and,
    where it names a close call, the consensus of the close methods added to the runs and
    trusted (:mod:`stewartid.verdict.close_call`).

    Parameters
    ----------
    runs : sequence of MethodFit
        From :func:`run_method`.
    consistent : bool
        As :func:`~stewartid.comparison.compare_methods`, for the consensus.
    entries : sequence of EntryKey
        The entries the verdict judges the methods on.
    policy : VerdictPolicy
        The verdict's thresholds.

    Returns
    -------
    runs : list of MethodFit
        ``runs``, with the consensus's last when it was built.
    verdict : Verdict
    """
    runs = list(runs)
    verdict = choose_trusted({run.name: None if run.result is None else
                              (run.result, run.evidence) for run in runs}, entries, policy,
                             {run.name: run.validation.residual_delay for run in runs
                              if run.validation is not None})
    by_name = {run.name: run for run in runs}
    members = consensus_members(verdict)
    if not members or CONSENSUS in by_name:
        return runs, verdict
    consensus = consensus_run([by_name[name] for name in members], consistent,
                              policy.agreement)
    if consensus is None:
        return runs, verdict
    compared = {name: by_name[name].result for name, standing in verdict.standings.items()
                if standing.compared}
    return [*runs, consensus], trust_consensus(verdict, consensus.result, consensus.evidence,
                                               compared, consensus.validation.residual_delay)


__all__ = ["FoldFits", "consensus_run", "consistent_result", "fit_method", "held_out_for", "judge",
           "method_folds", "run_method", "same_segments", "with_folds"]
