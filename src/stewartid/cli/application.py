"""The ``stewartid`` command-line application: the typer app, its error policy and its
commands (one module per command in :mod:`stewartid.cli`; heavy imports happen inside them).

Error policy: a :class:`~stewartid.errors.StewartidError` (bad input, failed numerics) or an
OSError (a user's file cannot be read or written) becomes one line ``error: ...`` on stderr
and exit code 2. Anything else is a bug and propagates with its traceback. ``--debug`` shows
the traceback of the expected errors too.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from contextvars import ContextVar
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


#: ``--debug`` of the running invocation (set by the root callback on every run).
_DEBUG: ContextVar[bool] = ContextVar("stewartid_debug", default=False)


@app.callback()
def _root(
    debug: Annotated[bool, typer.Option(
        "--debug", help="Show the full traceback of errors instead of one line.")] = False,
) -> None:
    """Dynamic parameter identification of Stewart platforms (Zhang 2020, wavelet method)."""
    _DEBUG.set(debug)



def _debugging() -> bool:
    return _DEBUG.get()


def fail(message: str) -> None:
    """Print ``message`` as one error line on stderr and exit with code 2."""
    typer.echo(f"error: {message}", err=True)
    raise typer.Exit(code=2)


def clean_errors(command: Callable[..., Any]) -> Callable[..., Any]:
    """Decorator: StewartidError and OSError become one error line and exit code 2 (unless
    ``--debug``); every other exception propagates."""

    @functools.wraps(command)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        try:
            return command(*args, **kwargs)
        except StewartidError as exc:
            if _debugging():
                raise
            fail(str(exc))
        except OSError as exc:
            if _debugging():
                raise
            fail(f"{type(exc).__name__}: {exc}")

    return wrapper


def _register() -> None:
    from stewartid.cli import identify, methods, nominal, reproduce, simulate

    for command in (nominal.nominal, simulate.simulate, identify.identify,
                    reproduce.reproduce, methods.methods):
        app.command()(clean_errors(command))
    from stewartid.cli import study

    app.command()(clean_errors(study.study))


_register()


def main(argv: list[str] | None = None) -> None:
    """Console-script entry point."""
    app(args=argv, prog_name="stewartid")


__all__ = ["app", "clean_errors", "fail", "main"]
