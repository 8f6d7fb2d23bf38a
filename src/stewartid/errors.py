"""Exception hierarchy.

Every error the package raises on bad input derives from :class:`StewartidError` and from
the built-in exception a caller would expect, so ``except ValueError`` keeps working.
Messages say what is wrong, where, what was expected and how to fix it.
"""

from __future__ import annotations


class StewartidError(Exception):
    """Base class of all errors raised by stewartid on bad input or failed numerics."""


class ConfigError(StewartidError, ValueError):
    """A platform description or a setting is missing, mistyped or out of range."""


class DataError(StewartidError, ValueError):
    """A data set is malformed: missing columns, non-finite values, bad time base, too short."""


class KinematicsError(StewartidError, ArithmeticError):
    """Forward kinematics did not converge, or the pose is singular or cannot be built."""


class IdentificationError(StewartidError, ValueError):
    """The identification problem cannot be solved as posed (no usable interval, rank loss)."""


class OutputExistsError(ConfigError):
    """An output folder already holds results and overwriting was not asked for."""


class DataWarning(UserWarning):
    """A data set was usable only after a correction (for instance resampling), or looks
    doubtful against the platform description."""


class NotFittedError(StewartidError, ValueError, AttributeError):
    """A learned attribute (ending in ``_``) was read before ``fit``.

    Like scikit-learn's ``NotFittedError`` it is both a ValueError and an AttributeError, so
    ``hasattr(estimator, "M_")`` is False before fitting.
    """
