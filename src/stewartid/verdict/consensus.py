"""The consensus of several methods: each member's symmetric pairs pooled, then their
estimates of each entry averaged by inverse variance where they agree with the first member.

A member that disagrees beyond ``agreement`` standard errors of the difference is left out of
that entry (one of the two has a model error its standard errors do not cover). The members
fit the same record and their errors correlate, so the standard error is the bound for fully
correlated members, sum_k w_k s_k. ``docs/verdict.md`` gives the measurements behind it.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from stewartid.datasets.dataset import Dataset
from stewartid.errors import ConfigError
from stewartid.fields import BOOLEAN, InstanceOf, positive
from stewartid.identification.base import BaseIdentifier
from stewartid.identification.registry import create_identifier, method_spec, register_method
from stewartid.identification.result import (
    IdentificationResult,
    own_std_errors,
    with_model_floor,
)
from stewartid.platform import Platform
from stewartid.verdict.policy import DEFAULT_POLICY

#: The members of :class:`ConsensusIdentifier` by default: the paper's Method B and least
#: squares, the two methods the verdict most often finds in a close call.
DEFAULT_MEMBERS = ("wavelet", "ls")


def combine_estimates(values: np.ndarray, std_errors: np.ndarray, agreement: float = DEFAULT_POLICY.agreement
                      ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Inverse-variance mean of the members that agree with the first one, entry by entry.

    Parameters
    ----------
    values, std_errors : ndarray, shape (m, ...)
        Estimates and standard errors of m members (the first is the reference).
    agreement : float
        Members agree on an entry within this many standard errors of their difference.

    Returns
    -------
    value, std_error : ndarray, shape (...)
        The mean and its standard error for fully correlated members (sum of w_k s_k). An
        entry whose first standard error is zero or not finite is the first member's.
    used : ndarray of bool, shape (m, ...)
        Which members entered each entry.
    """
    values, std_errors = np.asarray(values, dtype=float), np.asarray(std_errors, dtype=float)
    valid = np.isfinite(values) & np.isfinite(std_errors) & (std_errors > 0)
    used = valid & valid[:1] & (np.abs(values - values[:1])
                                <= agreement * np.hypot(std_errors, std_errors[:1]))
    used[0] = True  # the reference, also where its standard error gives no weight
    safe = np.where(valid, std_errors, 1.0)
    weights = np.where(used & valid, 1.0 / safe ** 2, 0.0)
    weights[0] = np.where(valid[0], weights[0], 1.0)
    weights = weights / weights.sum(axis=0)
    value = np.sum(np.where(weights > 0, weights * values, 0.0), axis=0)
    std = np.sum(np.where(weights > 0, weights * std_errors, 0.0), axis=0)
    return value, std, used


def pooled_pairs(value: np.ndarray, std_error: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """One member's symmetric pairs pooled: each pair of entries (i, j), (j, i) replaced by
    their inverse-variance mean.

    The two estimates may share data, so the standard error is the bound for fully correlated
    ones, w_1 s_1 + w_2 s_2 (weights w_k proportional to 1 / s_k^2, summing to one); where they
    disagree by more than the standard error of their difference, their Birge ratio
    |v_1 - v_2| / sqrt(s_1^2 + s_2^2) scales it (the Particle Data Group's scale factor for two
    measurements): a disagreement the standard errors do not cover is carried into the pooled
    one. A pair whose two entries are the same estimate is unchanged; one without two finite
    values and positive, finite standard errors is left as it is.

    Parameters
    ----------
    value, std_error : ndarray, shape (n, n)
        A member's estimate of a symmetric matrix and its standard errors.

    Returns
    -------
    value, std_error : ndarray, shape (n, n)
        Symmetric where pooled.
    """
    value, std_error = np.array(value, dtype=float), np.array(std_error, dtype=float)
    upper = np.triu_indices(value.shape[0], 1)
    lower = upper[::-1]
    a, b = value[upper], value[lower]
    s_a, s_b = std_error[upper], std_error[lower]
    usable = (np.isfinite(a) & np.isfinite(b) & np.isfinite(s_a) & np.isfinite(s_b)
              & (s_a > 0) & (s_b > 0))
    # placeholders where unusable (those entries are kept as they are below)
    a, b = np.where(usable, a, 0.0), np.where(usable, b, 0.0)
    s_a, s_b = np.where(usable, s_a, 1.0), np.where(usable, s_b, 1.0)
    w_a, w_b = 1.0 / s_a ** 2, 1.0 / s_b ** 2
    total = w_a + w_b
    mean = (w_a * a + w_b * b) / total
    birge = np.abs(a - b) / np.hypot(s_a, s_b)
    pooled_std = (w_a * s_a + w_b * s_b) / total * np.maximum(1.0, birge)
    for index in (upper, lower):
        value[index] = np.where(usable, mean, value[index])
        std_error[index] = np.where(usable, pooled_std, std_error[index])
    return value, std_error


def friction_diagnostics(results: Sequence[IdentificationResult]) -> dict[str, Any]:
    """The Coulomb levels the consensus predicts with: those of the first member that
    estimates them (``"coulomb"``, ``"coulomb_std"``; a member with free interval constants
    has none), else the levels a member was validated with (``"validation_coulomb"``)."""
    for result in results:
        found = result.diagnostics
        if isinstance(found.get("coulomb"), dict) and result.friction_model != "free":
            return {key: found[key] for key in ("coulomb", "coulomb_std") if key in found}
    for result in results:
        if isinstance(result.diagnostics.get("validation_coulomb"), dict):
            return {"validation_coulomb": dict(result.diagnostics["validation_coulomb"])}
    return {}


def combine_results(results: Sequence[IdentificationResult], names: Sequence[str],
                    agreement: float = DEFAULT_POLICY.agreement) -> IdentificationResult:
    """The consensus of fitted results (:func:`combine_estimates` on Mt and Bt, each member's
    symmetric pairs pooled first by :func:`pooled_pairs`).

    Parameters
    ----------
    results : sequence of IdentificationResult
        The members' results on the same data, the reference first.
    names : sequence of str
        Their registry names.
    agreement : float
        See :func:`combine_estimates`.

    Returns
    -------
    IdentificationResult
        Method ``"consensus"``; residual RMS of the reference; condition number the
        members' largest; ``diagnostics["consensus"]``: the members, the agreement and, per
        matrix, which members entered each entry (m, 6, 6); the friction of
        :func:`friction_diagnostics`.
    """
    if len(results) != len(names) or not results:
        raise ConfigError("a consensus needs one name per member result, and a member.")
    # each member's own errors: the model floor, shared by all, is the consensus's again
    own = [own_std_errors(r) for r in results]
    M, std_M, used_M = combine_estimates(
        *np.stack([pooled_pairs(r.M, s[0]) for r, s in zip(results, own, strict=True)],
                  axis=1), agreement)
    B, std_B, used_B = combine_estimates(
        *np.stack([pooled_pairs(r.B, s[1]) for r, s in zip(results, own, strict=True)],
                  axis=1), agreement)
    diagnostics = {"consensus": {"members": list(names), "agreement": float(agreement),
                                 "used_M": used_M, "used_B": used_B},
                   **friction_diagnostics(results)}
    return with_model_floor(IdentificationResult(
        M=M, B=B, std_errors_M=std_M, std_errors_B=std_B,
        condition_number=float(max(r.condition_number for r in results)),
        residual_rms=np.asarray(results[0].residual_rms, dtype=float), method="consensus",
        settings={"members": list(names), "agreement": float(agreement)},
        diagnostics=diagnostics))


@register_method(
    name="consensus", color="#17becf", compared=False,
    display_name="Consensus",
    description="the members' estimates (each one's symmetric pairs pooled) averaged by inverse "
                "variance where they agree within one standard error of their difference; what "
                "the verdict trusts in a close call",
    reference="Hartung, J., Knapp, G., Sinha, B. K. Statistical Meta-Analysis with "
              "Applications, ch. 4 (2008): inverse-variance weighting; Particle Data Group, "
              "Review of Particle Physics, Introduction, sec. 5.2 (2024): the scale factor")
class ConsensusIdentifier(BaseIdentifier):
    """Fits each member method and combines their Mt and Bt (:func:`combine_results`).

    ``identify --method all`` does not fit it again: where its verdict names a close call, the
    report builds the consensus of the close methods from their fits and folds.

    Parameters
    ----------
    members : tuple of str
        Registered methods (not presets' of one another), the reference first: its estimate
        stands where the others disagree.
    agreement : float
        Members agree on an entry within this many standard errors of their difference.
    gravity : bool
        Given to every member (False only for records without gravity).

    Attributes
    ----------
    M_, B_ : ndarray, shape (6, 6)
    std_errors_ : dict of ndarray (6, 6)
    members_ : dict of str to IdentificationResult
        Every member's own result.
    condition_number_ : float
    result_ : IdentificationResult
    """

    _parameter_constraints = {
        "members": [InstanceOf((tuple, list), "a list of at least two registered method names")],
        "agreement": [positive()],
        "gravity": [BOOLEAN],
    }

    def __init__(self, members: tuple[str, ...] = DEFAULT_MEMBERS,
                 agreement: float = DEFAULT_POLICY.agreement,
                 gravity: bool = True):
        self.members = members
        self.agreement = agreement
        self.gravity = gravity

    def _validate_params(self) -> None:
        super()._validate_params()
        names = list(self.members)
        if len(set(names)) < 2 or not all(isinstance(n, str) for n in names):
            raise ConfigError(f"The 'members' parameter of {type(self).__name__} must be a list "
                              f"of at least two different registered method names. Got "
                              f"{self.members!r} instead.")
        for name in names:
            if method_spec(name).estimator_class in (type(self),):
                raise ConfigError(f"The 'members' parameter of {type(self).__name__} must name "
                                  f"methods other than the consensus. Got {name!r} instead.")

    def _fit(self, datasets: list[Dataset], platform: Platform
             ) -> tuple[IdentificationResult, dict[str, Any]]:
        fitted = {}
        for name in self.members:
            accepted = method_spec(name).estimator_class.param_names()
            own = {"gravity": self.gravity} if "gravity" in accepted else {}
            fitted[name] = create_identifier(name, **own).fit(datasets, platform).result_
        result = combine_results(list(fitted.values()), list(fitted), self.agreement)
        return result, {"members_": fitted}


__all__ = ["DEFAULT_MEMBERS", "ConsensusIdentifier", "combine_estimates",
           "combine_results", "friction_diagnostics", "pooled_pairs"]
