"""Command-line interface: ``stewartid COMMAND ...``.

Every command turns a :class:`~stewartid.errors.StewartidError` (bad input, failed numerics)
into one line on stderr and exit code 2, with no traceback. Commands live in
``stewartid.commands`` modules and are registered here; heavy imports happen inside them.
"""

from __future__ import annotations

import functools
import json
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Annotated, Any

import typer

from stewartid.errors import StewartidError

app = typer.Typer(
    name="stewartid",
    help="Dynamic parameter identification of Stewart platforms (Zhang 2020, wavelet method).",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)


@app.callback()
def _root() -> None:
    """Dynamic parameter identification of Stewart platforms (Zhang 2020, wavelet method)."""


def fail(message: str) -> None:
    """Print ``message`` as one error line on stderr and exit with code 2."""
    typer.echo(f"error: {message}", err=True)
    raise typer.Exit(code=2)


def clean_errors(command: Callable[..., Any]) -> Callable[..., Any]:
    """Decorator: StewartidError and OSError become one error line and exit code 2."""

    @functools.wraps(command)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        try:
            return command(*args, **kwargs)
        except StewartidError as exc:
            fail(str(exc))
        except (OSError, ValueError) as exc:
            fail(f"{type(exc).__name__}: {exc}")

    return wrapper


PlatformOption = Annotated[
    str, typer.Option("--platform", help="'paper' for the preset, or a platform TOML file.")
]


@app.command()
@clean_errors
def nominal(
    platform: PlatformOption = "paper",
    as_json: Annotated[bool, typer.Option("--json", help="Print {\"M\": ..., \"B\": ...}.")] = False,
    gravity: Annotated[bool, typer.Option("--gravity-stiffness",
                                          help="Also print K_G = dG/dq.")] = False,
) -> None:
    """Nominal Mt and Bt of the linearised model at the neutral pose (paper frame)."""
    from stewartid.linearization import gravity_stiffness, nominal_matrices
    from stewartid.platform import load_platform

    description = load_platform(platform)
    M, B = nominal_matrices(description)
    if as_json:
        out = {"M": M.tolist(), "B": B.tolist()}
        if gravity:
            out["K_G"] = gravity_stiffness(description).tolist()
        sys.stdout.write(json.dumps(out) + "\n")
        return
    from stewartid.report_tables import print_matrix

    print_matrix(M, f"Mt ({description.name}, neutral pose)")
    print_matrix(B, f"Bt ({description.name}, neutral pose)")
    if gravity:
        print_matrix(gravity_stiffness(description), "K_G = dG/dq")


def register(module: str, name: str) -> None:
    """Register ``stewartid.<module>.<name>`` as a command, if that module is installed."""
    import importlib

    try:
        mod = importlib.import_module(f"stewartid.{module}")
    except ModuleNotFoundError as exc:
        if exc.name != f"stewartid.{module}":
            raise
        return
    app.command(name=name)(clean_errors(getattr(mod, name)))


for _module, _name in (("commands.simulate", "simulate"), ("commands.identify", "identify"),
                       ("commands.reproduce", "reproduce")):
    register(_module, _name)


def main(argv: list[str] | None = None) -> None:
    """Console-script entry point."""
    app(args=argv, prog_name="stewartid")


__all__ = ["Path", "app", "clean_errors", "fail", "main"]
