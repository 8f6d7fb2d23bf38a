"""``--help`` of every command reads like the ecosystem's: metavars say what a value is, flags
take none, and the text is reflowed so that no sentence is broken by a line break of the source."""

from __future__ import annotations

import re

import click
import pytest
import typer.main

from stewartid.cli.application import app

COMMAND = typer.main.get_command(app)


def command_paths(group: click.Group, prefix: tuple[str, ...] = ()) -> list[str]:
    """Every command and subcommand under ``group``, as the words that name it
    (``"study"``, or ``"group sub"`` for a subcommand)."""
    paths = []
    for name, command in sorted(group.commands.items()):
        paths.append(" ".join((*prefix, name)))
        if isinstance(command, click.Group):
            paths.extend(command_paths(command, (*prefix, name)))
    return paths


def command_of(path: str | None) -> click.Command:
    command = COMMAND
    for name in (path or "").split():
        command = command.commands[name]
    return command


COMMANDS = command_paths(COMMAND)
#: The metavars typer derives from type annotations, which say nothing about the value.
TYPE_METAVAR = re.compile(r"<(?:bool|str|path|Path|int|float|list\[[^\]]*\])>|\{\w+\}\.\.\.")


def render_help(capsys: pytest.CaptureFixture[str], command: str | None, width: int) -> str:
    """The help text of ``stewartid [command] --help`` formatted for a terminal of ``width``."""
    arguments = [*(command or "").split(), "--help"]
    COMMAND.main(arguments, prog_name="stewartid", standalone_mode=False, terminal_width=width,
                 max_content_width=width)
    return capsys.readouterr().out


def test_the_commands_are_all_checked() -> None:
    # every command and subcommand the application registers is walked, whatever its depth
    assert set(COMMANDS) >= {"design", "identify", "methods", "nominal", "reproduce", "simulate",
                             "study"}
    registered = {group.name for group in app.registered_groups} | {
        command.name or command.callback.__name__.replace("_", "-")
        for command in app.registered_commands}
    assert registered <= set(COMMANDS)


@pytest.mark.parametrize("command", [None, *COMMANDS])
def test_help_has_no_type_metavars(capsys: pytest.CaptureFixture[str], command: str | None) -> None:
    text = render_help(capsys, command, 100)
    assert text.startswith("Usage: stewartid")
    assert TYPE_METAVAR.findall(text) == []


@pytest.mark.parametrize("command", [None, *COMMANDS])
def test_every_value_option_names_its_value_and_flags_take_none(command: str | None) -> None:
    for parameter in command_of(command).params:
        if getattr(parameter, "is_flag", False):
            assert not parameter.metavar, f"{command} {parameter.opts[0]} is a flag"
        else:
            metavar = parameter.metavar or ""
            assert re.fullmatch(r"[A-Z][A-Z_|]*(\|[a-z]+)*|[a-z]+(\|[a-z]+)+", metavar), (
                f"{command} {parameter.opts[0]}: metavar {metavar!r}")


@pytest.mark.parametrize("command", [None, *COMMANDS])
def test_no_sentence_is_broken_by_a_line_break_of_the_source(
        capsys: pytest.CaptureFixture[str], command: str | None) -> None:
    """On a terminal wide enough for every paragraph, the description and each option's help
    are one line each: a line break that survives is one the source put in by hand. (The check
    is concrete: every paragraph of the description, and every option entry, is one line.)"""
    text = render_help(capsys, command, 2000)
    sections = text.split("\n\n")
    description = [paragraph for paragraph in sections[1:]
                   if not paragraph.lstrip().startswith(("Arguments:", "Options:", "Commands:"))]
    for paragraph in description:
        assert "\n" not in paragraph.strip(), f"broken description: {paragraph!r}"
    entries = [line for section in sections
               if section.startswith(("Arguments:", "Options:", "Commands:"))
               for line in section.splitlines()[1:]]
    assert entries
    for line in entries:
        assert re.match(r"  (-|[A-Z]|[a-z])", line), f"an entry broken over lines: {line!r}"


def test_method_help_names_all() -> None:
    option = next(parameter for parameter in COMMAND.commands["identify"].params
                  if parameter.name == "method")
    assert "'all'" in option.help


def test_a_description_keeps_its_square_brackets(capsys: pytest.CaptureFixture[str]) -> None:
    # rich markup read "[limits]" as a style tag and dropped it from the design's description
    assert "within the platform's [limits]" in render_help(capsys, "design", 2000)
