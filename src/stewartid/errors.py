"""Exception hierarchy: each error derives from :class:`StewartidError` and from the built-in
exception a caller would expect, so ``except ValueError`` keeps working.
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
    """A data set was usable only after a correction, or looks doubtful against the platform."""


class NotFittedError(StewartidError, ValueError, AttributeError):
    """A learned attribute (ending in ``_``) was read before ``fit``.

    Also an AttributeError, so ``hasattr(estimator, "M_")`` is False before fitting.
    """
