"""Which of several identified models to trust on the same data, and why.

:func:`choose_trusted` compares the methods by what their held-out validation
(:mod:`stewartid.assessment.validation`) and their matrices show and returns the finding as
data (:class:`Verdict`); the identification report puts it into words.

Rule: among the methods whose matrices are physically plausible (symmetric parts of Mt
positive definite and of Bt positive semidefinite; all methods, if none is), the one whose
worst DOF leaves the least force unexplained on held-out data; methods within
:data:`TIE_FACTOR` of that are tied and the one with the smaller median relative standard
error wins. What set the others back is recorded per method: more unexplained force,
inconsistency, friction pulled into Bt or left in the residuals.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Literal

import numpy as np

from stewartid.assessment.validation import (
    ValidationResult,
    coulomb_estimate,
    friction_signature,
)
from stewartid.identification.consistency import consistency_metrics
from stewartid.identification.result import IdentificationResult
from stewartid.platform import COORDINATES

#: Methods whose unexplained force is within this factor of the least are tied.
TIE_FACTOR = 1.25
#: A Coulomb level counts as present above this many standard errors.
SIGNIFICANT = 3.0
#: Mean relative excess of the Bt diagonal over the trusted method's above which a method
#: without friction is said to read the friction as viscous damping.
DAMPING_EXCESS = 0.05


def worst_dof(validation: ValidationResult) -> tuple[float, str]:
    """Held-out VAF (%) of the worst DOF and the DOF's name (``"x"`` ... ``"rz"``)."""
    vaf = validation.vaf_percent
    k = int(np.nanargmin(vaf))
    return float(vaf[k]), COORDINATES[k]


def relative_std(result: IdentificationResult) -> float:
    """Median relative standard error of the diagonals of Mt and Bt (a fraction)."""
    values = np.concatenate([np.diag(result.std_errors_M) / np.abs(np.diag(result.M)),
                             np.diag(result.std_errors_B) / np.abs(np.diag(result.B))])
    return float(np.nanmedian(values))


def is_definite(result: IdentificationResult) -> bool:
    """Symmetric part of Mt positive definite and of Bt positive semidefinite (what the
    energy of the model needs; a small asymmetry is reported, not disqualifying)."""
    metrics = consistency_metrics(result.M, result.B)
    scale = float(np.abs(result.B).max())
    return bool(metrics["M_min_eigenvalue"] > 0
                and metrics["B_min_eigenvalue"] >= -1e-9 * scale)


def finds_friction(result: IdentificationResult) -> bool:
    """The method estimates a Coulomb level above :data:`SIGNIFICANT` standard errors."""
    levels, std = coulomb_estimate(result)
    return bool(np.any(np.isfinite(levels) & (levels > SIGNIFICANT * np.nan_to_num(std))))


@dataclass(frozen=True)
class Standing:
    """What the verdict found about one applicable method.

    Attributes
    ----------
    name : str
        Registered method name.
    worst_vaf_percent : float
        Held-out VAF (%) in the method's worst DOF.
    worst_dof : str
        That DOF (``"x"`` ... ``"rz"``).
    unexplained_ratio : float
        Its unexplained force in the worst DOF over the trusted method's (1 for the trusted).
    compared : bool
        Among the methods the trust was chosen from (plausible matrices, or all methods when
        none has them).
    models_friction : bool
        The method estimates Coulomb levels.
    friction_effect : {"damping", "residuals"} or None
        When a method finds Coulomb friction and this one (not the trusted) does not model
        it: its friction is read as viscous damping (Bt diagonal above the trusted method's
        by more than :data:`DAMPING_EXCESS`) or stays in its residuals; else None.
    damping_excess : float
        Mean relative excess of its Bt diagonal over the trusted method's, where
        ``friction_effect`` is set (NaN elsewhere).
    friction_share : float
        Share of its held-out residual that has the shape of Coulomb friction
        (:func:`~stewartid.assessment.validation.friction_signature`).
    """

    name: str
    worst_vaf_percent: float
    worst_dof: str
    unexplained_ratio: float
    compared: bool
    models_friction: bool
    friction_effect: Literal["damping", "residuals"] | None
    damping_excess: float
    friction_share: float

    @property
    def unexplained_percent(self) -> float:
        """Held-out force left unexplained in the worst DOF (%)."""
        return 100 - self.worst_vaf_percent


@dataclass(frozen=True)
class Verdict:
    """Which method to trust, the ranking and the reasons.

    Attributes
    ----------
    trusted : str
        The method to trust.
    ranking : tuple of str
        The applicable methods, trusted first, then the compared ones before the others,
        each group by unexplained force.
    tied : tuple of str
        The compared methods within :data:`TIE_FACTOR` of the least unexplained force (the
        standard errors decided between them).
    standings : dict of str to Standing
        Per applicable method, in the order given.
    friction_source : str or None
        The first method that finds Coulomb friction, if any.
    not_applicable : tuple of str
        Methods that could not be applied to the data.
    """

    trusted: str
    ranking: tuple[str, ...]
    tied: tuple[str, ...]
    standings: dict[str, Standing]
    friction_source: str | None
    not_applicable: tuple[str, ...]


def choose_trusted(assessed: Mapping[str, tuple[IdentificationResult, ValidationResult] | None]
                   ) -> Verdict:
    """Which method to trust on these data (see the module docstring for the rule).

    Parameters
    ----------
    assessed : mapping
        Method name -> (result, its held-out validation), or None for a method that could
        not be applied. At least one must be applicable.

    Returns
    -------
    Verdict
    """
    ok = {name: pair for name, pair in assessed.items() if pair is not None}
    worst = {name: worst_dof(validation) for name, (_, validation) in ok.items()}
    unexplained = {name: 100.0 - vaf for name, (vaf, _) in worst.items()}
    compared = [name for name, (result, _) in ok.items() if is_definite(result)] or list(ok)
    floor = min(unexplained[name] for name in compared)
    tied = [name for name in compared if unexplained[name] <= TIE_FACTOR * floor + 1e-12]
    trusted = min(tied, key=lambda name: relative_std(ok[name][0]))
    friction_source = next((name for name, (result, _) in ok.items()
                            if finds_friction(result)), None)
    reference_B = np.diag(ok[trusted][0].B)
    standings = {}
    for name, (result, validation) in ok.items():
        models_friction = bool(np.all(np.isfinite(coulomb_estimate(result)[0])))
        excess, effect = float("nan"), None
        if friction_source is not None and not models_friction and name != trusted:
            excess = float(np.mean(np.diag(result.B) / reference_B) - 1.0)
            effect = "damping" if excess > DAMPING_EXCESS else "residuals"
        standings[name] = Standing(
            name, worst[name][0], worst[name][1],
            (100 - worst[name][0]) / max(100 - worst[trusted][0], 1e-12), name in compared,
            models_friction, effect, excess, friction_signature(validation))
    others = sorted((name for name in ok if name != trusted),
                    key=lambda name: (name not in compared, unexplained[name]))
    return Verdict(trusted, (trusted, *others), tuple(tied), standings, friction_source,
                   tuple(name for name, pair in assessed.items() if pair is None))


__all__ = ["DAMPING_EXCESS", "SIGNIFICANT", "TIE_FACTOR", "Standing", "Verdict",
           "choose_trusted", "finds_friction", "is_definite", "relative_std", "worst_dof"]
