"""One vocabulary of constraints for every value taken from outside, declared beside what it
constrains (as scikit-learn's ``_parameter_constraints``).

Every refusal names the subject, what it must be and the value given; a number outside its
physical range is a probable unit slip.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from numbers import Integral, Real
from typing import Any, TypeVar

import numpy as np

from stewartid.errors import ConfigError

T = TypeVar("T")

_OPEN_LEFT = {"left": False, "both": False, "right": True, "neither": True}
_OPEN_RIGHT = {"left": True, "both": False, "right": False, "neither": True}


def _is_number(value: Any, kind: type = Real) -> bool:
    return isinstance(value, kind) and not isinstance(value, bool | np.bool_)


@dataclasses.dataclass(frozen=True)
class Interval:
    """Finite numbers of a type between two bounds, each open or closed.

    Parameters
    ----------
    kind : {numbers.Real, numbers.Integral}
        Booleans are neither.
    low, high : float or None
        None for no bound.
    closed : {"left", "right", "both", "neither"}
    physical : (float, float), optional
        Closed range (SI) a real machine can have; outside it, a probable unit mistake.
    """

    kind: type
    low: float | None = None
    high: float | None = None
    closed: str = "left"
    physical: tuple[float, float] | None = None

    def is_satisfied_by(self, value: Any) -> bool:
        """Whether ``value`` meets the constraint."""
        if not _is_number(value, self.kind) or not math.isfinite(value):
            return False
        if self.low is not None and (value < self.low
                                     or (_OPEN_LEFT[self.closed] and value == self.low)):
            return False
        return self.high is None or not (value > self.high
                                         or (_OPEN_RIGHT[self.closed] and value == self.high))

    @property
    def bounds(self) -> str:
        """The bounds in words: ``"> 0"``, ``">= 3"``, ``"in [0, 1)"`` or ``""``."""
        if self.low is not None and self.high is not None:
            left = "(" if _OPEN_LEFT[self.closed] else "["
            right = ")" if _OPEN_RIGHT[self.closed] else "]"
            return f"in {left}{self.low:g}, {self.high:g}{right}"
        if self.low is not None:
            return f"{'>' if _OPEN_LEFT[self.closed] else '>='} {self.low:g}"
        if self.high is not None:
            return f"{'<' if _OPEN_RIGHT[self.closed] else '<='} {self.high:g}"
        return ""

    def describe(self, value: Any) -> str:
        """What the constraint asks for, in the words of an error message about ``value``."""
        # integers are always named; real numbers only when the value given is not one
        if self.kind is Integral:
            noun = "an integer"
        else:
            noun = "" if _is_number(value) else "a number"
            noun = noun or ("" if self.bounds else "a finite number")
        return " ".join(part for part in (noun, self.bounds) if part)

    def check_physical(self, subject: str, value: Any, unit: str) -> None:
        """Refuse ``value`` (which satisfies the interval) outside the physical range."""
        if self.physical is None:
            return
        low, high = self.physical
        if not low <= value <= high:
            raise ConfigError(f"{subject} = {value:g} {unit} is outside the physical range "
                              f"{low:g} to {high:g} {unit}; check its unit (SI).")


@dataclasses.dataclass(frozen=True)
class ListOf:
    """A list (tuple, one-dimensional array) of numbers, each in ``item``, of ``length`` elements (any
    number but zero when None).
    """

    item: Interval
    length: int | None = None

    def has_shape(self, value: Any) -> bool:
        """Whether ``value`` is one-dimensional with the required number of elements."""
        if not isinstance(value, list | tuple | np.ndarray) or np.ndim(value) != 1:
            return False
        return len(value) == self.length if self.length is not None else len(value) > 0

    def is_satisfied_by(self, value: Any) -> bool:
        """Whether ``value`` meets the constraint."""
        return self.has_shape(value) and all(self.item.is_satisfied_by(v) for v in value)

    def describe(self, value: Any) -> str:
        """What the constraint asks for, in the words of an error message about ``value``."""
        count = f"{self.length} " if self.length is not None else "non-empty list of "
        nouns = "integers" if self.item.kind is Integral else "numbers"
        text = f"a list of {count}{nouns}" if self.length is not None else f"a {count}{nouns}"
        return f"{text} {self.item.bounds}".rstrip()


@dataclasses.dataclass(frozen=True)
class Options:
    """One of a few values (compared with ``==``)."""

    values: tuple

    def is_satisfied_by(self, value: Any) -> bool:
        """Whether ``value`` meets the constraint."""
        return isinstance(value, Real | str) and value in self.values

    def describe(self, value: Any) -> str:
        """What the constraint asks for, in the words of an error message about ``value``."""
        if len(self.values) == 1:
            return repr(self.values[0])
        return "one of " + ", ".join(repr(v) for v in self.values)


@dataclasses.dataclass(frozen=True)
class InstanceOf:
    """Any instance of ``kind``, described by ``noun``."""

    kind: type | tuple[type, ...]
    noun: str

    def is_satisfied_by(self, value: Any) -> bool:
        """Whether ``value`` meets the constraint."""
        return isinstance(value, self.kind)

    def describe(self, value: Any) -> str:
        """What the constraint asks for, in the words of an error message about ``value``."""
        return self.noun


Constraint = Interval | ListOf | Options | InstanceOf

#: true or false (a TOML boolean).
BOOLEAN = InstanceOf(bool, "true or false")
#: A string.
TEXT = InstanceOf(str, "a string")


def positive(low: float | None = None, high: float | None = None) -> Interval:
    """Real numbers > 0, within the physical range [low, high] when given."""
    return Interval(Real, 0.0, None, "neither", None if low is None else (low, high))


def nonnegative(low: float | None = None, high: float | None = None) -> Interval:
    """Real numbers >= 0, within the physical range [low, high] when given."""
    return Interval(Real, 0.0, None, "left", None if low is None else (low, high))


def finite(low: float | None = None, high: float | None = None) -> Interval:
    """Any finite real number, within the physical range [low, high] when given."""
    return Interval(Real, None, None, "neither", None if low is None else (low, high))


def constraint_error(subject: str, expected: str, value: Any) -> ConfigError:
    """The one refusal of a bad setting: what must hold of the subject, then the value given."""
    return ConfigError(f"{subject} must be {expected}. Got {value!r} instead.")


def check(subject: str, value: Any, constraints: Sequence[Constraint | None], unit: str = "",
          condition: str = "") -> None:
    """Refuse ``value`` unless it satisfies one of ``constraints`` (None allows None) and its physical range.

    Parameters
    ----------
    subject : str
        As the message names it: ``"[inertia] platform_mass"``, ``"--budget"``.
    value : object
    constraints : sequence of constraint or None
    unit : str
        SI unit shown after the expected values (``"-"`` or ``""``: none).
    condition : str
        When the constraints apply (``"test_functions is None"``).

    Raises
    ------
    ConfigError
        As :func:`constraint_error`, or naming the physical range and the unit to check.
    """
    if value is None and None in constraints:
        return
    allowed = [c for c in constraints if c is not None]
    for constraint in allowed:
        if constraint.is_satisfied_by(value):
            if isinstance(constraint, Interval):
                constraint.check_physical(subject, value, unit)
            elif isinstance(constraint, ListOf):
                for index, item in enumerate(value):
                    constraint.item.check_physical(f"{subject}[{index}]", item, unit)
            return
    if len(allowed) == 1 and isinstance(allowed[0], ListOf) and allowed[0].has_shape(value):
        # the list has the right shape: name the element at fault
        for index, item in enumerate(value):
            check(f"{subject}[{index}]", item, [allowed[0].item], unit, condition)
    phrases = [c.describe(value) for c in allowed] + (["None"] if None in constraints else [])
    expected = phrases[0] if len(phrases) == 1 else f"{', '.join(phrases[:-1])} or {phrases[-1]}"
    if unit not in ("", "-"):
        expected += f" ({unit})"
    if condition:
        expected += f" when {condition}"
    raise constraint_error(subject, expected, value)


def validate_parameters(constraints: Mapping[str, Sequence[Constraint | None]],
                        params: Mapping[str, Any], owner: str, condition: str = "") -> None:
    """Check each of ``params`` named in ``constraints`` (scikit-learn's parameter check).

    Raises
    ------
    ConfigError
        "The 'name' parameter of {owner} must be ... Got ... instead."
    """
    for name, allowed in constraints.items():
        check(f"The {name!r} parameter of {owner}", params[name], allowed, condition=condition)


@dataclasses.dataclass(frozen=True)
class FieldSpec:
    """A declared value: its unit, a one-line description and its constraint.

    Attributes
    ----------
    unit : str
        SI unit (``"-"`` for none).
    doc : str
    constraint : constraint
        :class:`Interval`, :class:`ListOf`, :class:`Options` or :class:`InstanceOf`.
    """

    unit: str
    doc: str
    constraint: Constraint

    def check(self, subject: str, value: Any) -> Any:
        """``value`` checked and normalised (:meth:`normalise`).

        Raises
        ------
        ConfigError
            Naming ``subject`` (see :func:`check`).
        """
        value = self.normalise(value)
        check(subject, value, [self.constraint], self.unit)
        return value

    def normalise(self, value: Any) -> Any:
        """``value`` as stored: numbers of a real field as floats, lists as tuples; other types unchanged."""
        constraint = self.constraint
        if isinstance(constraint, ListOf) and constraint.has_shape(value):
            return tuple(self._number(v, constraint.item) for v in value)
        return self._number(value, constraint) if isinstance(constraint, Interval) else value

    @staticmethod
    def _number(value: Any, interval: Interval) -> Any:
        return float(value) if interval.kind is Real and _is_number(value) else value


def spec(unit: str, doc: str, constraint: Constraint, default: Any = dataclasses.MISSING
         ) -> Any:
    """Declare a section field (a :class:`FieldSpec` in the field's metadata).

    ``constraint`` carries a number's physical range (``positive(0.01, 50.0)``); fields without a
    ``default`` are required in TOML; a default of None (derived from other sections) is not checked.
    """
    metadata = {"spec": FieldSpec(unit, doc, constraint)}
    if isinstance(default, list | tuple):
        default = tuple(default)
    return dataclasses.field(default=default, metadata=metadata)


def field_spec(field: dataclasses.Field) -> FieldSpec:
    """The :class:`FieldSpec` of a field declared with :func:`spec`."""
    return field.metadata["spec"]


class Section:
    """Base of a frozen section dataclass (declared with :func:`spec` fields, its TOML table in
    ``section``) that checks every field when built; cross-field checks call
    ``super().__post_init__()`` first.
    """

    #: Name of the TOML table, used in messages (``[geometry] upper_radius ...``).
    section = "section"

    def __post_init__(self) -> None:
        for field in dataclasses.fields(self):
            value = getattr(self, field.name)
            if value is None and field.default is None:
                continue
            check(f"[{self.section}] {field.name}", value, [field_spec(field).constraint],
                  field_spec(field).unit)


def section_from_mapping(cls: type[T], table: Any, where: str) -> T:
    """Build the section dataclass ``cls`` from a TOML table; ``where`` names it in messages.

    Raises
    ------
    ConfigError
        On an unknown key, a missing required key, a wrong type or a value out of range.
    """
    if not isinstance(table, Mapping):
        raise ConfigError(f"[{where}] must be a TOML table; got {type(table).__name__}.")
    fields = {f.name: f for f in dataclasses.fields(cls)}
    unknown = sorted(set(table) - set(fields))
    if unknown:
        raise ConfigError(
            f"[{where}] has unknown key {unknown[0]!r}; valid keys are: {', '.join(fields)}."
        )
    values = {}
    for name, field in fields.items():
        if name in table:
            values[name] = field_spec(field).normalise(table[name])
        elif field.default is dataclasses.MISSING:
            raise ConfigError(f"[{where}] is missing required key {name!r} "
                              f"({field_spec(field).doc}, {field_spec(field).unit}).")
    return cls(**values)


def section_to_mapping(section: Any) -> dict[str, Any]:
    """Inverse of :func:`section_from_mapping`: plain values ready for TOML or JSON."""
    out = {}
    for f in dataclasses.fields(section):
        value = getattr(section, f.name)
        out[f.name] = list(value) if isinstance(value, tuple) else value
    return out


__all__ = ["BOOLEAN", "TEXT", "Constraint", "FieldSpec", "InstanceOf", "Interval", "ListOf",
           "Options", "Section", "check", "constraint_error", "field_spec", "finite",
           "nonnegative", "positive", "section_from_mapping", "section_to_mapping", "spec",
           "validate_parameters"]
