"""Method labels of every report from the registry: display names, colours, paper letters, order."""

from __future__ import annotations

from collections.abc import Iterable

from stewartid.identification.registry import MethodSpec, registered_methods


def _spec(method: str) -> MethodSpec | None:
    return next((spec for spec in registered_methods() if spec.name == method), None)


def method_name(method: str) -> str:
    """Display name of a method (the name itself when not registered)."""
    spec = _spec(method)
    return method if spec is None else spec.display_name


def method_color(method: str) -> str:
    """Colour of a method in every figure (grey when not registered)."""
    spec = _spec(method)
    return "grey" if spec is None else spec.color


def paper_letter(method: str) -> str | None:
    """The paper's letter for a method ("A", "B"), None if the paper does not report it."""
    spec = _spec(method)
    return None if spec is None else spec.letter


def paper_methods() -> dict[str, str]:
    """Registered methods the paper reports, name -> letter, in the letters' order."""
    found = {spec.name: spec.letter for spec in registered_methods() if spec.letter}
    return dict(sorted(found.items(), key=lambda item: item[1]))


def report_order(methods: Iterable[str]) -> tuple[str, ...]:
    """``methods`` in report order: the paper's by letter, the others by registry, unknown alphabetically."""
    registry = [spec.name for spec in registered_methods()]

    def key(method: str) -> tuple[int, str, int, str]:
        letter = paper_letter(method)
        rank = registry.index(method) if method in registry else len(registry)
        return (0 if letter else 1, letter or "", rank, method)

    return tuple(sorted(set(methods), key=key))


__all__ = ["method_color", "method_name", "paper_letter", "paper_methods", "report_order"]
