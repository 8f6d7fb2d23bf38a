"""Which of several identified models to trust on the same data, and why: the thresholds
(:class:`VerdictPolicy`), the entries judged (:func:`scored_entries`), the rule
(:func:`choose_trusted`), the consensus of close methods and the entries the trusted result is
unsure of. ``docs/verdict.md`` states the whole rule."""

from stewartid.verdict.policy import (
    DEFAULT_POLICY,
    VerdictPolicy,
    parse_entries,
    scored_entries,
)
from stewartid.verdict.rule import Standing, Verdict, choose_trusted

__all__ = ["DEFAULT_POLICY", "Standing", "Verdict", "VerdictPolicy", "choose_trusted",
           "parse_entries", "scored_entries"]
