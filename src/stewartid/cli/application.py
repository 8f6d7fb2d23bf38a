"""The ``stewartid`` typer app and its error policy: an expected error is one line ``error: ...``
on stderr and exit code 2; anything else is a bug with its traceback (every one with ``--debug``)."""

from __future__ import annotations

import functools
import gc
import sys
import warnings
from collections.abc import Callable
from contextvars import ContextVar
from typing import Annotated, Any

import typer
from typer.core import TyperCommand, TyperGroup

from stewartid.errors import StewartidError

try:  # typer >= 0.20 carries its own copy of click
    from typer._click import exceptions as _usage
except ImportError:  # pragma: no cover - older typer on click
    from click import exceptions as _usage


class OneLineUsageErrors(TyperGroup):
    """The command group, usage errors as one line ``error: ...`` and exit code 2, not a usage box."""

    def main(self, *args: Any, standalone_mode: bool = True, **kwargs: Any) -> Any:
        """Run the application; exit with the command's code (2 after a usage error)."""
        if not standalone_mode:
            return super().main(*args, standalone_mode=False, **kwargs)
        try:
            code = super().main(*args, standalone_mode=False, **kwargs)
        except _usage.UsageError as exc:
            if isinstance(exc, getattr(_usage, "NoArgsIsHelpError", ())):
                exc.show()
                sys.exit(0)
            path = exc.ctx.command_path if exc.ctx is not None else "stewartid"
            message = exc.format_message().rstrip(".") + "."
            parameter = getattr(exc, "param", None)
            if getattr(parameter, "help", None) and getattr(parameter, "opts", None):
                message += f" {parameter.opts[0]}: {parameter.help.rstrip('.')}."
            typer.echo(f"error: {message} See '{path} --help'.", err=True)
            sys.exit(2)
        except _usage.ClickException as exc:
            typer.echo(f"error: {exc.format_message()}", err=True)
            sys.exit(exc.exit_code)
        except typer.Abort:
            typer.echo("Aborted.", err=True)
            sys.exit(1)
        sys.exit(code if isinstance(code, int) else 0)


class PlainHelpCommand(TyperCommand):
    """A command whose ``--help`` reads like git's or pip's: ``FILE...``, ``--out DIR``, reflowed text."""

    def collect_usage_pieces(self, ctx: Any) -> list[str]:
        """The usage line after the command: the options placeholder, then each argument."""
        pieces = [self.options_metavar] if self.options_metavar else []
        for parameter in self.get_params(ctx):
            if parameter.param_type_name == "argument":
                pieces.append(_argument_label(parameter, usage=True))
        return pieces

    def format_options(self, ctx: Any, formatter: Any) -> None:
        """Write the "Arguments:" and "Options:" sections."""
        arguments = [(_argument_label(parameter, usage=False), parameter.help or "")
                     for parameter in self.get_params(ctx)
                     if parameter.param_type_name == "argument"]
        options = [record for parameter in self.get_params(ctx)
                   if parameter.param_type_name == "option"
                   and (record := parameter.get_help_record(ctx)) is not None]
        if arguments:
            with formatter.section("Arguments"):
                formatter.write_dl(arguments)
        if options:
            with formatter.section("Options"):
                formatter.write_dl(options)


def _argument_label(parameter: Any, usage: bool) -> str:
    """``FILE...`` for a required argument of several values, ``[FILE]`` for an optional one."""
    label = parameter.metavar or parameter.name.upper()
    if parameter.nargs != 1:
        label += "..."
    return f"[{label}]" if usage and not parameter.required else label


app = typer.Typer(
    cls=OneLineUsageErrors,
    rich_markup_mode=None,
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


def _show_warning(message: Warning | str, category: type[Warning], *args: Any,
                  **kwargs: Any) -> None:
    typer.echo(f"warning: {message}", err=True)


def clean_errors(command: Callable[..., Any]) -> Callable[..., Any]:
    """Decorator: StewartidError and OSError become one error line and exit code 2 (unless
    ``--debug``); warnings are one line ``warning: ...``."""

    @functools.wraps(command)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("default")
                warnings.showwarning = _show_warning
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
        app.command(cls=PlainHelpCommand)(clean_errors(command))
    from stewartid.cli import study

    app.command(cls=PlainHelpCommand)(clean_errors(study.study))
    from stewartid.cli import design

    app.command(cls=PlainHelpCommand)(clean_errors(design.design))


_register()


def main(argv: list[str] | None = None) -> None:
    """Console-script entry point; BLAS on one thread (the commands' matrices are small). The
    process ends with it: its objects are frozen out of the shutdown's cyclic collections."""
    from threadpoolctl import threadpool_limits

    try:
        with threadpool_limits(limits=1, user_api="blas"):
            app(args=argv, prog_name="stewartid")
    finally:
        # the interpreter's shutdown would walk every object the command left; the process
        # hands its memory back anyway
        gc.freeze()


__all__ = ["app", "clean_errors", "fail", "main"]
