"""The identification report on a user's own measured experiments (``stewartid identify
--report DIR``).

:func:`write_identification_report` fits one or several registered methods to the same
experiments, validates each on held-out time segments (:mod:`.validation`), checks the
physical consistency of the matrices and, on request, replaces them by the nearest consistent
pair (:mod:`stewartid.identification.consistency`), and writes into ``DIR``:

- ``report.md`` and a self-contained ``report.html`` (:mod:`.user_report_text`): the data,
  the constant-direction intervals, Mt and Bt with standard errors beside the nominal values,
  residuals, validation, consistency, friction and, for several methods, which one to trust;
- ``figures/``: every figure as PNG and SVG (:mod:`.user_report_figures` chooses them,
  :mod:`.identification_figures` draws them);
- ``result.json``: the trusted method's result with its ``validation`` and ``consistency``
  objects, and the CSV and MATLAB exports of every method (:mod:`.exports`).
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from stewartid.assessment.validation import (
    DEFAULT_FOLDS,
    Segment,
    ValidationResult,
    coulomb_levels,
    cross_validate,
    held_out_segments,
    in_sample,
)
from stewartid.datasets.dataset import Dataset
from stewartid.errors import ConfigError, StewartidError
from stewartid.identification.consistency import (
    ConsistentEstimate,
    project_consistent,
    require_cvxpy,
)
from stewartid.identification.result import IdentificationResult
from stewartid.model.joints import FRICTION_TYPES
from stewartid.platform import Platform
from stewartid.reporting.exports import ExportedModel, write_exports

#: ``identify --method`` value that runs every registered method.
ALL_METHODS = "all"


@dataclass(frozen=True)
class MethodReport:
    """One method applied to the experiments, with everything the report says about it.

    Attributes
    ----------
    name, display_name, color : str
        From the registry.
    result : IdentificationResult or None
        The reported result (the consistent one with ``consistent=True``), with
        ``validation`` set; None if the method could not be applied.
    unconstrained : IdentificationResult or None
        The method's own estimate.
    validation : ValidationResult or None
        Held-out scores of ``result``'s fold models.
    validation_unconstrained : ValidationResult or None
        Of the unconstrained fold models, when ``result`` is the consistent one.
    in_sample : ValidationResult or None
        The full fit on the same segments (residuals over time).
    projection : ConsistentEstimate or None
    seconds : float
        Fit and validation time.
    error : str or None
        Why the method could not be applied.
    """

    name: str
    display_name: str
    color: str
    result: IdentificationResult | None = None
    unconstrained: IdentificationResult | None = None
    validation: ValidationResult | None = None
    validation_unconstrained: ValidationResult | None = None
    in_sample: ValidationResult | None = None
    projection: ConsistentEstimate | None = None
    seconds: float = 0.0
    error: str | None = None
    exception: StewartidError | None = field(default=None, repr=False, compare=False)

    @property
    def coulomb(self) -> tuple[np.ndarray, np.ndarray]:
        """Coulomb level and standard error per joint type (N m), NaN where not estimated."""
        nan = np.full(len(FRICTION_TYPES), np.nan)
        levels = None if self.result is None else coulomb_levels(self.result)
        if levels is None:
            return nan, nan
        std = self.result.diagnostics.get("coulomb_std") or {}
        return levels, np.array([std.get(k, np.nan) for k in FRICTION_TYPES], dtype=float)


@dataclass(frozen=True)
class IdentificationReport:
    """What :func:`write_identification_report` found and wrote.

    Attributes
    ----------
    runs : list of MethodReport
    trusted : str
        Name of the method the report trusts (the only one for a single method).
    verdict : list of str
        The plain-language reasons, Markdown.
    directory : Path
    files : list of Path
    """

    runs: list[MethodReport]
    trusted: str
    verdict: list[str]
    directory: Path
    files: list[Path] = field(default_factory=list)

    @property
    def result(self) -> IdentificationResult:
        """The trusted method's result (with ``validation``)."""
        return next(run.result for run in self.runs if run.name == self.trusted)


def _consistent_result(result: IdentificationResult) -> tuple[IdentificationResult,
                                                              ConsistentEstimate]:
    """``result`` with M and B replaced by the nearest consistent pair; the unconstrained
    matrices and the change are kept in the diagnostics."""
    projection = project_consistent(result.M, result.B, result.std_errors_M,
                                    result.std_errors_B)
    diagnostics = {**result.diagnostics, "consistent_fit": {
        **projection.to_dict(), "unconstrained_M": result.M, "unconstrained_B": result.B}}
    return dataclasses.replace(result, M=projection.M, B=projection.B,
                               diagnostics=diagnostics), projection


def _project(result: IdentificationResult) -> IdentificationResult:
    return _consistent_result(result)[0]


def run_method(name: str, settings: Mapping[str, Any], datasets: Sequence[Dataset],
               platform: Platform, folds: int, consistent: bool,
               segments: dict[bool, list[Segment]],
               check: Callable[[IdentificationResult], None] | None = None) -> MethodReport:
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
        Held-out segments by ``gravity`` setting, filled on first use and shared between
        methods.
    check : callable, optional
        Raises a StewartidError for an implausible result (the method is then reported as
        not applicable).
    """
    from stewartid.identification.registry import create_identifier, method_spec

    spec = method_spec(name)
    accepted = spec.estimator_class._param_names()
    own = {k: v for k, v in settings.items() if k in accepted}
    start = time.perf_counter()
    try:
        estimator = create_identifier(name, **own).fit(list(datasets), platform)
        if check is not None:
            check(estimator.result_)
        gravity = bool(estimator.get_params().get("gravity", True))
        if gravity not in segments:
            segments[gravity] = held_out_segments(datasets, platform, folds, gravity)
        folds_fit = cross_validate(lambda: create_identifier(name, **own), datasets, platform,
                                   folds, gravity, segments[gravity])
    except StewartidError as exc:
        return MethodReport(name, spec.display_name, spec.color, error=str(exc),
                            exception=exc, seconds=time.perf_counter() - start)
    unconstrained = estimator.result_
    validation = folds_fit.scores()
    result, projection, before = unconstrained, None, None
    if consistent:
        result, projection = _consistent_result(unconstrained)
        before, validation = validation, folds_fit.scores(_project)
    result = dataclasses.replace(result, validation=validation.to_dict())
    return MethodReport(name, spec.display_name, spec.color, result=result,
                        unconstrained=unconstrained, validation=validation,
                        validation_unconstrained=before,
                        in_sample=in_sample(segments[gravity], result), projection=projection,
                        seconds=time.perf_counter() - start)


def write_identification_report(datasets: Sequence[Dataset], platform: Platform,
                                directory: str | Path, methods: Sequence[str] = ("wavelet",),
                                settings: Mapping[str, Any] | None = None,
                                consistent: bool = False, folds: int = DEFAULT_FOLDS,
                                nominal: tuple[np.ndarray, np.ndarray] | None = None,
                                nominal_source: str | None = None,
                                sources: Sequence[str] = (),
                                check: Callable[[IdentificationResult], None] | None = None
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

    Returns
    -------
    IdentificationReport

    Raises
    ------
    StewartidError
        If no method could be applied (the first method's message).
    """
    from stewartid.files import write_text_atomic
    from stewartid.model.linearization import nominal_matrices
    from stewartid.reporting.document import render_html
    from stewartid.reports.identification.figures import (
        FigureDrawer,
        data_figures,
        result_figures,
    )
    from stewartid.reports.identification.text import choose_trusted, data_rows, render_report

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
    segments: dict[bool, list[Segment]] = {}
    runs = [run_method(name, settings or {}, datasets, platform, folds, consistent, segments,
                       check) for name in dict.fromkeys(methods)]
    usable = [run for run in runs if run.result is not None]
    if not usable:
        raise runs[0].exception
    trusted, verdict = choose_trusted(runs, nominal)
    drawer = FigureDrawer(directory / "figures")
    data_figures(drawer, datasets, platform, rows)
    result_figures(drawer, runs, datasets, platform, nominal, trusted, rows)
    models = [ExportedModel(run.name, run.result, *run.coulomb) for run in usable]
    files = drawer.files + write_exports(models, directory, trusted)
    report = IdentificationReport(runs, trusted, verdict, directory)
    files.append(report.result.to_json(directory / "result.json"))
    text = render_report(report, datasets, platform, nominal, nominal_source or "", rows,
                         drawer.entries, sources, folds, time.perf_counter() - started)
    files.append(write_text_atomic(directory / "report.md", text))
    files.append(write_text_atomic(directory / "report.html", render_html(
        text, directory, title=f"stewartid identification report: {platform.name}")))
    return dataclasses.replace(report, files=files)


def methods_for(name: str) -> tuple[str, ...]:
    """The methods ``identify --method NAME`` runs: every registered method (presets aside)
    for ``"all"``, else ``(NAME,)``.

    Raises
    ------
    ConfigError
        For an unknown name (the message lists the registered ones).
    """
    from stewartid.identification.registry import method_spec, registered_methods

    if name == ALL_METHODS:
        return tuple(spec.name for spec in registered_methods() if spec.preset_of is None)
    return (method_spec(name).name,)


def identify_for_command(datasets: Sequence[Dataset], platform: Platform, method: str,
                         settings: Mapping[str, Any], directory: Path | None,
                         consistent: bool, folds: int = DEFAULT_FOLDS,
                         nominal: tuple[np.ndarray, np.ndarray, str] | None = None,
                         sources: Sequence[str] = (),
                         check: Callable[[IdentificationResult], None] | None = None
                         ) -> tuple[IdentificationResult, IdentificationReport | None]:
    """``identify`` with ``--report``, ``--consistent`` or ``--method all``.

    Without ``directory`` one method is fitted and, with ``consistent``, replaced by the
    nearest consistent pair (no validation, no files); with it, the full report is written.
    ``check`` (e.g. the plausibility check of the command line) runs on every fitted result
    before anything is written; a method it rejects is reported as not applicable.

    Returns
    -------
    result : IdentificationResult
        The trusted (or only) method's result.
    report : IdentificationReport or None
    """
    from stewartid.identification.registry import create_identifier

    names = methods_for(method)
    if consistent:
        require_cvxpy()
    if directory is None:
        if len(names) > 1:
            raise ConfigError(f"--method {method} compares the methods in a report; add "
                              "--report DIR.")
        result = create_identifier(names[0], **settings).fit(list(datasets), platform).result_
        if check is not None:
            check(result)
        return (_consistent_result(result)[0] if consistent else result), None
    report = write_identification_report(
        datasets, platform, directory, names, settings, consistent, folds,
        None if nominal is None else nominal[:2], None if nominal is None else nominal[2],
        sources, check)
    return report.result, report


__all__ = ["ALL_METHODS", "IdentificationReport", "MethodReport", "identify_for_command",
           "methods_for", "run_method", "write_identification_report"]
