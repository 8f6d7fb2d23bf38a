"""The force channels aligned with the motion before any method sees them: a given delay, or
one estimated where the motion tells a delay from damping."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from stewartid.datasets.alignment import align_forces
from stewartid.datasets.dataset import Dataset
from stewartid.errors import IdentificationError
from stewartid.identification.delay import (
    apply_delay,
    describe_bias,
    estimate_delay,
    single_frequency_bias,
)
from stewartid.platform import Platform

#: By default an estimated delay is applied when it is this many standard errors from zero (the
#: residual-delay test of the held-out validation uses the same): model error leans the
#: estimate by about one standard error on some platforms' logs without a delay.
DELAY_SIGNIFICANCE = 3.0


@dataclass(frozen=True)
class Alignment:
    """Experiments with their forces aligned, and what ``result.json`` says of it.

    Attributes
    ----------
    experiments : list of Dataset
    entry : dict or None
        The ``"delay"`` entry of ``result.json`` (``seconds``, ``std_error``, ``applied``,
        ``source``); None when the motion cannot tell a delay from damping.
    sensitivity : dict or None
        Then, the DOFs moved at one frequency and the Bt bias per ms of delay
        (:func:`~stewartid.identification.delay.single_frequency_bias`).
    """

    experiments: list[Dataset]
    entry: dict[str, Any] | None
    sensitivity: dict[str, Any] | None


def delay_note(sensitivity: dict[str, Any]) -> str:
    """One sentence: where a force delay passes for damping and its bias on Bt per ms."""
    return (f"{', '.join(sensitivity['dofs'])} moved at one frequency only, where a delay of "
            "the force channels behind the motion passes for damping: each ms of delay adds "
            f"{describe_bias(sensitivity)} to Bt. Give a known delay (--delay SECONDS), or "
            "excite two or more frequencies per DOF and estimate it (--delay auto).")


#: Why the default leaves an electric drive's log as logged.
ELECTRIC_REASON = ("an electric drive logs its currents and encoder positions in one cycle: no "
                   "delay estimated (--delay auto estimates one, --delay SECONDS gives it)")


def align_experiments(experiments: Sequence[Dataset], platform: Platform,
                      delay: str | float | None = None, jobs: int | None = 1) -> Alignment:
    """Align the force channels with the motion.

    Parameters
    ----------
    experiments : sequence of Dataset
    platform : Platform
    delay : float, ``"auto"`` or None
        Seconds the forces lag the motion (0: as logged); ``"auto"``: estimated and applied,
        refused where the motion cannot tell it from damping; None (default): estimated where
        the motion can (two or more frequencies in every DOF) and applied when more than
        :data:`DELAY_SIGNIFICANCE` standard errors from zero, else as logged; an electric
        actuator's log as logged (:data:`ELECTRIC_REASON`).
    jobs : int or None
        Worker processes of the delay's estimate (None: every core); the result does not
        depend on it.

    Returns
    -------
    Alignment

    Raises
    ------
    StewartidError
        A delay that is neither a number nor ``"auto"``; ``"auto"`` where it cannot be
        estimated.
    """
    experiments = list(experiments)
    if delay is not None:
        aligned, entry = apply_delay(experiments, platform, delay, jobs)
        return Alignment(aligned, entry, None)
    if platform.actuator.kind == "electric":
        # a servo drive samples its currents and encoders in one cycle; the screw's friction
        # would bias the estimate (measured in docs/benchmarks.md, "Electric hexapods")
        return Alignment(experiments, {"seconds": None, "std_error": None, "applied": False,
                                       "source": "not estimated", "reason": ELECTRIC_REASON},
                         None)
    sensitivity = single_frequency_bias(experiments, platform)
    if sensitivity is not None:
        return Alignment(experiments, None, sensitivity)
    try:
        estimate = estimate_delay(experiments, platform, jobs=jobs)
    except IdentificationError as exc:
        return Alignment(experiments, {"seconds": None, "std_error": None, "applied": False,
                                       "source": "not estimated", "reason": str(exc)}, None)
    applied = abs(estimate.seconds) > DELAY_SIGNIFICANCE * estimate.std_error
    aligned = align_forces(experiments, estimate.seconds) if applied else experiments
    return Alignment(aligned, estimate.to_dict(applied=applied), None)


__all__ = ["DELAY_SIGNIFICANCE", "ELECTRIC_REASON", "Alignment", "align_experiments", "delay_note"]
