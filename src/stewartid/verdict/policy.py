"""The verdict's thresholds in one place, and the entries of Mt and Bt it scores.

The rule these numbers steer is described, with the measurements behind each, in
``docs/verdict.md``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from stewartid.errors import ConfigError
from stewartid.reference.published import PAPER_ENTRIES, EntryKey, entry_label


@dataclass(frozen=True)
class VerdictPolicy:
    """How :func:`~stewartid.verdict.rule.choose_trusted` weighs the methods.

    Attributes
    ----------
    close_factor : float
        Methods whose expected largest error is within this factor of the trusted one's are
        a close call: their consensus is trusted.
    misfit_factor, misfit_floor_percent : float
        A method leaving more than ``misfit_factor`` times the least held-out unexplained
        force in its worst DOF, and more than ``misfit_floor_percent`` % of it, misses part
        of the physics: it is ranked after the others.
    uncertain_relative : float
        An entry of the trusted result with a larger relative standard error is uncertain.
    disagreement : float
        Two estimates of an entry further apart than this many combined standard errors
        disagree (the entry is uncertain).
    significant : float
        A Coulomb level above this many standard errors is friction found; a force delay
        left in the held-out residuals beyond this many standard errors (and
        ``delay_floor_s``) is a delay found.
    delay_floor_s : float
        A residual force delay below this (s) is not reported: 0.2 ms biases the paper
        platform's most sensitive Bt diagonal, Bt(3,3) at 0.5 Hz, by 1.4 %, half the trusted
        result's typical largest error.
    damping_excess : float
        A method without friction whose Bt diagonal exceeds the trusted one's by more than
        this share on average reads the friction as damping.
    agreement : float
        Members of the consensus agree on an entry within this many standard errors of their
        difference.
    negligible_coupling : float
        An off-diagonal entry of the nominal matrices below this share of sqrt(|x_ii x_jj|) is
        not scored (:func:`scored_entries`).
    """

    close_factor: float = 1.25
    misfit_factor: float = 4.0
    misfit_floor_percent: float = 1.0
    uncertain_relative: float = 0.10
    disagreement: float = 3.0
    significant: float = 3.0
    delay_floor_s: float = 2e-4
    damping_excess: float = 0.05
    agreement: float = 1.0
    negligible_coupling: float = 1e-2


#: The policy of the package.
DEFAULT_POLICY = VerdictPolicy()


def scored_entries(M: np.ndarray, B: np.ndarray,
                   negligible: float = DEFAULT_POLICY.negligible_coupling
                   ) -> tuple[EntryKey, ...]:
    """The entries of Mt and Bt worth judging a method on, from a platform's nominal matrices:
    every diagonal entry and each off-diagonal one above ``negligible`` times the geometric
    mean of its two diagonal entries.

    Parameters
    ----------
    M, B : ndarray, shape (6, 6)
        Nominal inertia and viscous matrices (with the payload).
    negligible : float

    Returns
    -------
    tuple of (str, int, int)
        ``("M", i, j)`` and ``("B", i, j)`` keys, zero-based: per matrix the diagonal, then the
        couplings row by row (the order of the paper's 20 entries, which a symmetric
        platform's matrices give).
    """
    found: list[EntryKey] = []
    for name, matrix in (("M", np.asarray(M, float)), ("B", np.asarray(B, float))):
        d = np.sqrt(np.abs(np.diag(matrix)))
        found += [(name, i, i) for i in range(6)]
        found += [(name, i, j) for i in range(6) for j in range(6)
                  if i != j and abs(matrix[i, j]) > negligible * d[i] * d[j]]
    return tuple(found)


def parse_entries(labels: Sequence[str]) -> tuple[EntryKey, ...]:
    """Entry keys from labels such as ``"Mt(1,5)"`` or ``"Bt(6,6)"`` (one-based).

    Raises
    ------
    ConfigError
        For a label not of that form.
    """
    known = {entry_label((m, i, j)): (m, i, j) for m in "MB" for i in range(6) for j in range(6)}
    found = []
    for label in labels:
        key = known.get(label.replace(" ", ""))
        if key is None:
            raise ConfigError(f"entry {label!r}: expected Mt(i,j) or Bt(i,j) with i, j in 1..6.")
        found.append(key)
    return tuple(dict.fromkeys(found))


def entries_text(entries: Sequence[EntryKey]) -> str:
    """How a sentence names the scored entries: "the paper's 20 entries" when they are those,
    else "the N scored entries"."""
    if tuple(entries) == PAPER_ENTRIES:
        return f"the paper's {len(PAPER_ENTRIES)} entries"
    return f"the {len(entries)} scored entries"


__all__ = ["DEFAULT_POLICY", "VerdictPolicy", "entries_text",
           "parse_entries", "scored_entries"]
