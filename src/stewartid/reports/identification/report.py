"""The identification report on a user's own measured experiments (``stewartid identify
--report DIR``).

:func:`write_identification_report` fits one or several registered methods to the same
experiments, validates each on held-out time segments (:mod:`stewartid.validation.heldout`),
checks the physical consistency of the matrices and, on request, replaces them by the nearest
consistent pair (:mod:`stewartid.identification.consistency`), chooses the method to trust
(:mod:`stewartid.verdict.rule`) and writes into ``DIR``:

- ``report.md`` and a self-contained ``report.html`` (:mod:`.text`): the data, the
  constant-direction intervals, Mt and Bt with standard errors beside the nominal values,
  residuals, validation, consistency, friction and, for several methods, which one to trust;
- ``figures/``: every figure as PNG and SVG (:mod:`~stewartid.reports.identification.figures` chooses them,
  :mod:`~stewartid.reports.identification.method_figures` draws them);
- ``result.json``: the trusted method's result with its ``validation`` and ``consistency``
  objects (with ``identify --model physical``, the physical model's result with the compared
  methods' ``verdict``), and the CSV and MATLAB exports of every method
  (:mod:`stewartid.reports.exports`);
- with the physical model asked for (:class:`~.physical_section.PhysicalRequest`), its
  section (:mod:`.physical_section`): Mt and Bt across the measured poses, its parameters and
  its held-out prediction beside the others', not ranked by the verdict; ``physical.json`` its
  result when ``result.json`` holds the trusted method's.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from stewartid.datasets.dataset import Dataset
from stewartid.errors import ConfigError, StewartidError
from stewartid.files import write_text_atomic
from stewartid.identification import registry
from stewartid.identification.consistency import ConsistentEstimate, project_consistent
from stewartid.identification.result import IdentificationResult
from stewartid.model.linearization import nominal_matrices
from stewartid.platform import Platform
from stewartid.reports.exports import ExportedModel, write_exports
from stewartid.reports.html import render_html
from stewartid.reports.identification.figures import (
    FigureDrawer,
    data_figures,
    physical_figures,
    result_figures,
)
from stewartid.reports.identification.physical_section import PhysicalRequest, fit_physical
from stewartid.reports.identification.records import IdentificationReport, MethodReport
from stewartid.reports.identification.text import data_rows, render_report
from stewartid.validation.heldout import (
    DEFAULT_FOLDS,
    CrossValidation,
    Segment,
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
from stewartid.verdict.rule import Verdict, choose_trusted


def consistent_result(result: IdentificationResult) -> tuple[IdentificationResult,
                                                              ConsistentEstimate]:
    """``result`` with M and B replaced by the nearest consistent pair (needs the ``convex``
    extra), and the projection; the unconstrained matrices and the change are kept in the
    diagnostics."""
    projection = project_consistent(result.M, result.B, result.std_errors_M,
                                    result.std_errors_B)
    diagnostics = {**result.diagnostics, "consistent_fit": {
        **projection.to_dict(), "unconstrained_M": result.M, "unconstrained_B": result.B}}
    return dataclasses.replace(result, M=projection.M, B=projection.B,
                               diagnostics=diagnostics), projection


def _project(result: IdentificationResult) -> IdentificationResult:
    return consistent_result(result)[0]


def run_method(name: str, settings: Mapping[str, Any], datasets: Sequence[Dataset],
               platform: Platform, folds: int, consistent: bool,
               segments: dict[tuple[bool, bool], list[Segment]],
               check: Callable[[IdentificationResult], None] | None = None,
               records: Sequence[Dataset] = (),
               record_cache: dict[tuple[bool, bool], list[Segment]] | None = None
               ) -> MethodReport:
    """Fit, validate and check one method; a method that cannot be applied to these data
    (a :class:`~stewartid.errors.StewartidError`) is reported with its message.

    Parameters
    ----------
    name : str
        Registered method or preset.
    settings : mapping
        Settings for it (those it does not have are ignored).
    datasets, platform, folds, consistent
        As :func:`write_identification_report`.
    segments : dict
        Held-out segments by (``gravity``, ``remainder``) setting, filled on first use and
        shared between methods.
    check : callable, optional
        Raises a StewartidError for an implausible result (the method is then reported as
        not applicable).
    records : sequence of Dataset
        Validation records of another excitation (``identify --validate``), predicted by the
        full fit.
    record_cache : dict, optional
        Their filtered segments by (``gravity``, ``remainder``) setting, filled on first use.
    """
    spec = registry.method_spec(name)
    accepted = spec.estimator_class.param_names()
    own = {k: v for k, v in settings.items() if k in accepted}
    start = time.perf_counter()
    try:
        estimator = registry.create_identifier(name, **own).fit(list(datasets), platform)
        if check is not None:
            check(estimator.result_)
        params = estimator.get_params()
        # the measured side of the prediction with the model terms the method removed
        terms = (bool(params.get("gravity", True)), bool(params.get("remainder", False)))
        if terms not in segments:
            segments[terms] = held_out_segments(datasets, platform, folds, *terms)
        # the folds and the companion predict: their standard errors are never read
        companion = None
        if "friction" in accepted:
            def companion():
                return registry.estimates_only(name, **{**own, "friction": "uniform"})
        folds_fit = cross_validate(lambda: registry.estimates_only(name, **own), datasets,
                                   platform, folds, terms[0], segments[terms], companion)
    except StewartidError as exc:
        return MethodReport(name, spec.display_name, spec.color, error=str(exc),
                            exception=exc, seconds=time.perf_counter() - start)
    unconstrained = with_companion_friction(estimator.result_, companion, datasets, platform)
    validation = folds_fit.scores()
    result, projection, before = unconstrained, None, None
    if consistent:
        result, projection = consistent_result(unconstrained)
        before, validation = validation, folds_fit.scores(_project)
    external = None
    if records:
        cache = {} if record_cache is None else record_cache
        if terms not in cache:
            cache[terms] = record_segments(records, platform, *terms)
        # ``result`` holds the companion's levels: the consistent one keeps the diagnostics
        external = validate_on_records(result, cache[terms])
    result = dataclasses.replace(result, validation=validation_entry(validation, external))
    return MethodReport(name, spec.display_name, spec.color, result=result,
                        unconstrained=unconstrained, validation=validation,
                        validation_unconstrained=before,
                        in_sample=in_sample(segments[terms], result), projection=projection,
                        records=external, seconds=time.perf_counter() - start,
                        cross_validation=folds_fit)


def same_segments(a: Sequence[Segment], b: Sequence[Segment]) -> bool:
    """Whether two methods' held-out segments are the same pieces, prepared alike (the same
    ``gravity`` setting gives the same measured force)."""
    return a is b or (len(a) == len(b) and all(
        x.name == y.name and np.array_equal(x.force, y.force) for x, y in zip(a, b, strict=True)))


def consensus_run(members: Sequence[MethodReport], consistent: bool) -> MethodReport | None:
    """The consensus of fitted methods (:func:`~stewartid.verdict.consensus.combine_results`),
    validated as :func:`run_method` validates a method: each fold's consensus of the members'
    fold fits predicts the held-out segments, the full consensus the validation records.
    None when the members were validated on differently prepared segments (their ``gravity``
    settings differ)."""
    start = time.perf_counter()
    names = [run.name for run in members]
    folds = [run.cross_validation for run in members]
    if any(f is None or not same_segments(f.segments, folds[0].segments) for f in folds):
        return None
    unconstrained = combine_results([run.unconstrained for run in members], names)
    fitted = CrossValidation(folds[0].folds, [
        combine_results([f.fold_results[k] for f in folds], names)
        for k in range(folds[0].folds)], folds[0].segments)
    validation = fitted.scores()
    result, projection, before = unconstrained, None, None
    if consistent:
        result, projection = consistent_result(unconstrained)
        before, validation = validation, fitted.scores(_project)
    records = members[0].records
    external = None if records is None else validate_on_records(result, records.segments)
    result = dataclasses.replace(result, validation=validation_entry(validation, external))
    spec = registry.method_spec(CONSENSUS)
    return MethodReport(CONSENSUS, spec.display_name, spec.color, result=result,
                        unconstrained=unconstrained, validation=validation,
                        validation_unconstrained=before,
                        in_sample=in_sample(fitted.segments, result), projection=projection,
                        records=external, seconds=time.perf_counter() - start,
                        cross_validation=fitted)


def judge(runs: Sequence[MethodReport], consistent: bool = False
          ) -> tuple[list[MethodReport], Verdict]:
    """The verdict on the methods' runs (:func:`~stewartid.verdict.rule.choose_trusted`)
    and, where it names a close call, the consensus of the close methods added to the runs
    and trusted (:mod:`stewartid.verdict.close_call`).

    Returns
    -------
    runs : list of MethodReport
        ``runs``, with the consensus's last when it was built.
    verdict : Verdict
    """
    runs = list(runs)
    verdict = choose_trusted({run.name: None if run.result is None else
                              (run.result, run.evidence) for run in runs},
                             {run.name: None if run.cross_validation is None else
                              run.cross_validation.fold_results for run in runs})
    by_name = {run.name: run for run in runs}
    members = consensus_members(verdict)
    if not members or CONSENSUS in by_name:
        return runs, verdict
    consensus = consensus_run([by_name[name] for name in members], consistent)
    if consensus is None:
        return runs, verdict
    compared = {name: by_name[name].result for name, standing in verdict.standings.items()
                if standing.compared}
    return [*runs, consensus], trust_consensus(verdict, consensus.result, consensus.evidence,
                                               compared)


def write_identification_report(datasets: Sequence[Dataset], platform: Platform,
                                directory: str | Path, methods: Sequence[str] = ("wavelet",),
                                settings: Mapping[str, Any] | None = None,
                                consistent: bool = False, folds: int = DEFAULT_FOLDS,
                                nominal: tuple[np.ndarray, np.ndarray] | None = None,
                                nominal_source: str | None = None,
                                sources: Sequence[str] = (),
                                check: Callable[[IdentificationResult], None] | None = None,
                                records: Sequence[Dataset] = (), notes: Sequence[str] = (),
                                physical: PhysicalRequest | None = None
                                ) -> IdentificationReport:
    """Identify, validate and report on measured experiments.

    Parameters
    ----------
    datasets : sequence of Dataset
        The experiments (together they must excite every DOF).
    platform : Platform
        Description of the measured hexapod.
    directory : str or Path
        Output folder (created; files in it are replaced). Check it first with
        :func:`stewartid.files.check_output_folder` when it must not hold results.
    methods : sequence of str
        Registered methods or presets; with several, the report compares them and says which
        to trust.
    settings : mapping, optional
        Settings given to every method that has them (e.g. ``{"gravity": False}``).
    consistent : bool
        Replace every method's Mt, Bt by the nearest physically consistent pair (needs the
        ``convex`` extra) and validate those.
    folds : int
        Time segments per experiment for the validation (>= 2).
    nominal : (M, B), optional
        Reference matrices (6, 6); by default the platform description's at neutral.
    nominal_source : str, optional
        Where ``nominal`` comes from, for the report.
    sources : sequence of str
        The data files, listed in the report.
    check : callable, optional
        See :func:`run_method`.
    records : sequence of Dataset
        Validation records of another excitation: every method predicts them, and the
        verdict judges the prediction on them instead of on held-out segments.
    notes : sequence of str
        Sentences added to the report's summary.
    physical : PhysicalRequest, optional
        Add the physical model's section (:func:`~.physical_section.fit_physical`); with
        ``physical.required``, ``result.json`` holds its result.

    Returns
    -------
    IdentificationReport

    Raises
    ------
    StewartidError
        If no method could be applied (the first method's message).
    """
    started = time.perf_counter()
    if not (isinstance(folds, int | np.integer) and folds >= 2):
        raise ConfigError(f"the validation needs at least 2 folds; got {folds!r}.")
    directory = Path(directory)
    datasets = list(datasets)
    if nominal is None:
        nominal = nominal_matrices(platform)
        nominal_source = nominal_source or (f"platform description '{platform.name}' at the "
                                            "neutral pose")
    rows = data_rows(datasets, platform)
    segments: dict[tuple[bool, bool], list[Segment]] = {}
    record_cache: dict[tuple[bool, bool], list[Segment]] = {}
    runs = [run_method(name, settings or {}, datasets, platform, folds, consistent, segments,
                       check, records, record_cache) for name in dict.fromkeys(methods)]
    if all(run.result is None for run in runs):
        raise runs[0].exception
    runs, verdict = judge(runs, consistent)
    trusted = verdict.trusted
    section = None if physical is None else fit_physical(
        datasets, platform, physical, folds, segments, records, record_cache)
    drawer = FigureDrawer(directory / "figures")
    data_figures(drawer, datasets, platform, rows)
    result_figures(drawer, runs, datasets, platform, nominal, trusted, rows)
    physical_figures(drawer, section)
    models = [ExportedModel(run.name, run.result, *run.coulomb) for run in runs
              if run.result is not None]
    files = drawer.files + write_exports(models, directory, trusted)
    if len(runs) > 1:
        runs = [dataclasses.replace(run, result=dataclasses.replace(
            run.result, verdict=verdict.to_dict())) if run.name == trusted else run
            for run in runs]
    report = IdentificationReport(runs, verdict, directory, physical=section,
                                  physical_primary=physical is not None and physical.required)
    files.append(report.main_result.to_json(directory / "result.json"))
    if section is not None and section.result is not None and not report.physical_primary:
        files.append(section.result.to_json(directory / "physical.json"))
    text = render_report(report, datasets, platform, nominal, nominal_source or "", rows,
                         drawer.entries, sources, folds, time.perf_counter() - started,
                         [d.name for d in records], notes)
    files.append(write_text_atomic(directory / "report.md", text))
    files.append(write_text_atomic(directory / "report.html", render_html(
        text, directory, title=f"stewartid identification report: {platform.name}")))
    return dataclasses.replace(report, files=files)


__all__ = ["consensus_run", "consistent_result", "judge", "run_method", "same_segments",
           "write_identification_report"]
