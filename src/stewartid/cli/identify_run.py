"""``stewartid identify`` behind its flags: experiments read and aligned, the method(s) fitted,
report and result written; every output and flag combination checked before any computation."""

from __future__ import annotations

import dataclasses
import json
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np

from stewartid.comparison import (
    ALL_METHODS,
    PhysicalRequest,
    align_experiments,
    check_jobs,
    compare_methods,
    consistent_result,
    method_names,
    plausibility_check,
)
from stewartid.datasets import read_experiments
from stewartid.datasets.dataset import expand_paths
from stewartid.datasets.log_format import load_log_format
from stewartid.datasets.meta import nominal_from_meta, platform_for_data
from stewartid.datasets.set_checks import check_experiment_set
from stewartid.errors import ConfigError
from stewartid.files import check_output_file, check_output_folder
from stewartid.identification import registry
from stewartid.identification.averaging import DEFAULT_AVERAGING, average_experiments
from stewartid.identification.delay import (
    parse_delay,
)
from stewartid.identification.result import IdentificationResult, comparison_rows
from stewartid.model.linearization import nominal_matrices
from stewartid.physical.identified_platform import IDENTIFIED_HEADER, write_identified
from stewartid.platform import Platform
from stewartid.validation.heldout import DEFAULT_FOLDS
from stewartid.verdict.policy import scored_entries

if TYPE_CHECKING:
    from stewartid.reports.identification.report import IdentificationReport

#: Values of ``identify --model``.
MODELS = ("physical",)

#: Suffixes of data and description files, which a JSON result must not be named like.
INPUT_SUFFIXES = (".csv", ".parquet", ".pq", ".toml")


class FlagSetting(NamedTuple):
    """The estimator setting a command-line flag sets.

    Attributes
    ----------
    name : str
        The setting (``"gravity"``, ``"frequency_hz"``, ...).
    value : object
    given : bool
        The flag was given (an error for a method without the setting).
    """

    name: str
    value: Any
    given: bool


@dataclass(frozen=True)
class IdentifyRun:
    """What :func:`identify_files` found and wrote.

    Attributes
    ----------
    result : IdentificationResult
        The trusted (or only) method's result.
    report : IdentificationReport or None
    platform : Platform
    experiments : int
    nominal_M, nominal_B : ndarray, shape (6, 6)
        Reference: a ``meta.json``/``truth.json`` beside the data, else the platform at neutral.
    nominal_source : str
    delay : dict or None
        The force delay the data were aligned by; None when used as logged.
    delay_sensitivity : dict or None
        Bias a force delay would put on the Bt diagonal per ms, for single-frequency DOFs
        (:func:`~stewartid.identification.delay.single_frequency_bias`).
    averaging : dict or None
        The samples averaged into one before the fits, when asked
        (:func:`~stewartid.identification.averaging.average_experiments`).
    """

    result: IdentificationResult
    report: IdentificationReport | None
    platform: Platform
    experiments: int
    nominal_M: np.ndarray
    nominal_B: np.ndarray
    nominal_source: str
    delay: dict[str, Any] | None = None
    delay_sensitivity: dict[str, Any] | None = None
    averaging: dict[str, Any] | None = None

    def comparison(self) -> list[dict[str, Any]]:
        """The platform's scored entries, identified against nominal."""
        result = self.result
        return comparison_rows(result.M, result.B, self.nominal_M, self.nominal_B,
                               result.std_errors_M, result.std_errors_B,
                               scored_entries(*nominal_matrices(self.platform)))


def settings_for(methods: Sequence[str], method: str, flags: Mapping[str, FlagSetting]
                 ) -> dict[str, Any]:
    """The settings the flags give the methods (``friction`` only when given).

    Raises
    ------
    ConfigError
        A flag given for a method without its setting.
    """
    accepted = {name for each in methods for name in registry.method_spec(each).estimator_class.param_names()}
    settings = {}
    for flag, (name, value, given) in flags.items():
        if name in accepted and (given or name != "friction"):
            settings[name] = value
        elif given:
            raise ConfigError(f"{flag} does not apply to --method {method}; it has the "
                              f"settings {', '.join(accepted)}.")
    return settings


def _is_result(path: Path) -> bool:
    """True for a JSON file that ``identify --out`` wrote."""
    try:
        document = json.loads(path.read_text())
    except (OSError, ValueError):
        return False
    return isinstance(document, dict) and {"M", "B", "method"} <= set(document)


def _check_outputs(paths: Sequence[Path], inputs: Sequence[str | Path | None],
                   out: Path | None, report: Path | None, force: bool, method: str,
                   several: bool, folds: int | None) -> None:
    """Refuse outputs that would overwrite inputs or earlier work, and report-only options."""
    if out is not None:
        named = [*paths, *(p for p in inputs if p and Path(p).is_file())]
        check_output_file(out, force, named, is_result=_is_result)
        if out.suffix.lower() in INPUT_SUFFIXES:
            raise ConfigError(f"--out {str(out)!r}: the result is JSON; give a .json file name.")
    if report is not None:
        inside = [p for p in paths if report.resolve() in p.resolve().parents]
        if inside:
            raise ConfigError(f"--report {str(report)!r} holds the input {str(inside[0])!r}; "
                              "choose another folder for the report.")
        check_output_folder(report, force)
    elif several:
        raise ConfigError(f"--method {method} compares the methods in a report; add "
                          "--report DIR.")
    elif folds is not None:
        raise ConfigError("--folds sets the report's validation; add --report DIR.")


def _physical_request(model: str | None, method: str, payload: bool, consistent: bool,
                      settings: Mapping[str, Any]) -> PhysicalRequest | None:
    """The report's physical section, or None when neither ``--model`` nor ``--method all``."""
    if model is None and method != ALL_METHODS:
        return None
    own = registry.method_spec("physical").estimator_class.param_names()
    return PhysicalRequest(payload=payload, consistent=consistent and model is not None,
                           required=model is not None,
                           settings={k: v for k, v in settings.items() if k in own})


def _is_identified(path: Path) -> bool:
    """True for a platform file that ``identify --platform-out`` wrote."""
    try:
        return path.read_text(encoding="utf-8").startswith(IDENTIFIED_HEADER)
    except (OSError, UnicodeDecodeError):
        return False


def _check_model_options(model: str, platform_out: Path | None, forbidden: dict[str, bool]
                        ) -> None:
    """Refuse an unknown model and the options (``forbidden``: flag -> given) it does not take."""
    if model not in MODELS:
        raise ConfigError(f"--model {model!r}: expected one of {', '.join(MODELS)}.")
    given = [flag for flag, on in forbidden.items() if on]
    if given:
        raise ConfigError(f"{given[0]} does not apply to --model {model}; leave it out.")
    if platform_out is not None and platform_out.suffix.lower() != ".toml":
        raise ConfigError(f"--platform-out {str(platform_out)!r}: the platform description "
                          "is TOML; give a .toml file name.")


def model_method(model: str | None, method: str, payload: bool,
                 platform_out: Path | None) -> str:
    """The method ``identify`` runs: ``method``, or the ``--model`` estimator.

    Raises
    ------
    ConfigError
        An unknown model, or ``--payload``/``--platform-out`` without ``--model``.
    """
    if model is None:
        if payload or platform_out is not None:
            raise ConfigError("--payload and --platform-out go with --model physical; add it.")
        return method
    if model not in MODELS:
        raise ConfigError(f"--model {model!r}: expected one of {', '.join(MODELS)}.")
    return model


def _check_model_outputs(model: str, platform_out: Path | None,
                        refused: dict[str, bool] | None = None,
                        inputs: Sequence[str | Path] = ()) -> None:
    """:func:`_check_model_options`; refuse a ``platform_out`` replacing an input or a foreign file."""
    _check_model_options(model, platform_out, refused or {})
    if platform_out is not None:
        check_output_file(platform_out, False, inputs, is_result=_is_identified,
                          option="--platform-out")




def _fit_alone(datasets: list, platform: Platform, method: str, settings: Mapping[str, Any],
               consistent: bool, model: str | None, payload: bool) -> IdentificationResult:
    """One method (or the physical model) without a report, made consistent on request."""
    if model is not None:
        from stewartid.physical.estimator import PhysicalIdentifier

        return PhysicalIdentifier(**settings, payload=payload, consistent=consistent).fit(
            datasets, platform).result_
    result = registry.create_identifier(method, **settings).fit(datasets, platform).result_
    if consistent:
        plausibility_check(platform)(result)
        result = consistent_result(result)[0]
    return result


def identify_files(files: Sequence[str | Path], method: str = "wavelet",
                   platform: str | None = None, *, flags: Mapping[str, FlagSetting] | None = None,
                   columns: str | None = None, out: Path | None = None, force: bool = False,
                   report: Path | None = None, consistent: bool = False,
                   folds: int | None = None, delay: str | float | None = None,
                   validate: Sequence[str | Path] = (), model: str | None = None,
                   payload: bool = False, platform_out: Path | None = None,
                   jobs: int | None = None, average: bool = False) -> IdentifyRun:
    """Identify Mt and Bt from experiment files, as ``stewartid identify`` does.

    The arguments are the command's options; ``flags`` maps each estimator flag to its setting;
    ``jobs``: worker processes of the comparison or of a method that takes them (None: every
    core); ``average``: records sampled well above what the fits need averaged over blocks of
    samples first (:func:`~stewartid.identification.averaging.average_experiments`).
    With ``report`` the methods are compared and the report written; with ``model`` the physical
    model is fitted instead of ``method``.

    Raises
    ------
    StewartidError
        Bad options or outputs (before any computation), unreadable data, a repeated experiment,
        an unexcited DOF, an inapplicable method, or an implausible result.
    """
    delay = parse_delay(delay)
    check_jobs(jobs)
    names = method_names(method)
    settings = settings_for(names, method, flags or {})
    paths = expand_paths(files)
    description = platform_for_data(paths, platform)
    _check_outputs(paths, (platform, columns), out, report, force, method, len(names) > 1,
                   folds)
    if model is not None:
        _check_model_outputs(model, platform_out, {}, [*paths, *([platform] if platform else [])])
    if validate and report is None:
        raise ConfigError("--validate compares the methods' predictions in a report; add "
                          "--report DIR.")
    records_paths = expand_paths(validate) if validate else []
    shared = sorted({str(p.resolve()) for p in records_paths} & {str(p.resolve()) for p in paths})
    if shared:
        raise ConfigError(f"--validate {shared[0]!r} is also an experiment to fit; validation "
                          "records must be motion the fit does not see.")
    log_format = load_log_format(columns) if columns is not None else None
    unknown = model is not None  # the forces' weight is the payload's evidence
    datasets = read_experiments(paths, description, log_format, payload_unknown=unknown)
    check_experiment_set(datasets, description)
    records = (read_experiments(records_paths, description, log_format, payload_unknown=unknown)
               if records_paths else [])
    meta = nominal_from_meta(paths)
    check = plausibility_check(description)
    policy = DEFAULT_AVERAGING if average else None
    if consistent:
        from stewartid.identification.consistency import require_cvxpy

        require_cvxpy()
    written = None
    if report is not None:
        from stewartid.reports.identification.report import write_report  # only with --report

        comparison = compare_methods(
            datasets, description, method_names(ALL_METHODS) if model else names, records,
            DEFAULT_FOLDS if folds is None else folds, settings=settings,
            consistent=consistent and model is None,
            physical=_physical_request(model, method, payload, consistent, settings),
            nominal=None if meta is None else meta[:2],
            nominal_source=None if meta is None else meta[2], delay=delay, averaging=policy,
            jobs=jobs)
        check(comparison.result)
        written = write_report(comparison, report, sources=[str(p) for p in paths], jobs=jobs)
        result, delay_entry = comparison.result, comparison.delay
        sensitivity, averaging = comparison.delay_sensitivity, comparison.averaging
    else:
        averaged = average_experiments(datasets, policy)
        datasets, averaging = averaged.experiments, averaged.entry  # the full rate's freed
        alignment = align_experiments(datasets, description, delay, jobs)
        delay_entry, sensitivity = alignment.entry, alignment.sensitivity
        if model is None and "jobs" in registry.method_spec(method).estimator_class.param_names():
            settings = {**settings, "jobs": jobs}
        result = _fit_alone(alignment.experiments, description, method, settings, consistent,
                            model, payload)
        check(result)
        if delay_entry is not None:
            result = dataclasses.replace(result, delay=delay_entry)
        added = {"averaging": averaging, "delay_sensitivity": sensitivity}
        added = {key: value for key, value in added.items() if value is not None}
        if added:
            result = dataclasses.replace(result, diagnostics={**result.diagnostics, **added})
    if model is not None and platform_out is not None:
        write_identified(description, result, platform_out, len(datasets))
    M_nominal, B_nominal = meta[:2] if meta is not None else nominal_matrices(description)
    source = meta[2] if meta is not None else f"platform '{description.name}' at neutral"
    if out is not None:
        result.to_json(out)
    return IdentifyRun(result, written, description, len(datasets), M_nominal, B_nominal,
                       source, delay_entry, sensitivity, averaging)


__all__ = ["FlagSetting", "IdentifyRun", "MODELS", "identify_files",
           "model_method", "settings_for"]
