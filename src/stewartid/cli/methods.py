"""``stewartid methods``: the registered identification methods, one per line."""

from __future__ import annotations

import typer


def methods() -> None:
    """List the identification methods and presets (name, description, reference)."""
    from stewartid.identification.registry import registered_methods

    for spec in registered_methods():
        typer.echo(f"{spec.name}: {spec.description}. Reference: {spec.reference}")
