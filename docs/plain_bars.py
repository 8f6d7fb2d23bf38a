"""Docstrings write absolute values and norms as in the code, ``|x|`` and ``|a - b|``, which
reStructuredText would read as substitution references. This Sphinx hook escapes every bar
outside literals (inline ``...``, interpreted `...` text, literal and math blocks), so that
the docstrings stay readable in the terminal and render as written on the site."""

from __future__ import annotations

import re

#: Inline spans left alone: ``literal``, `interpreted` (roles included: :math:`...`).
_SPANS = re.compile(r"(``.+?``|`[^`]+`)")


def escape_line(line: str) -> str:
    """``line`` with each bar outside inline literals escaped."""
    pieces = _SPANS.split(line)
    return "".join(piece if index % 2 else re.sub(r"(?<!\\)\|", r"\\|", piece)
                   for index, piece in enumerate(pieces))


def _indent(line: str) -> int:
    return len(line) - len(line.lstrip())


def escape_bars(lines: list[str]) -> None:
    """Escape, in place, the bars of a docstring's lines outside literal and math blocks."""
    block_indent: int | None = None
    for index, line in enumerate(lines):
        if block_indent is not None:
            if not line.strip() or _indent(line) > block_indent:
                continue
            block_indent = None
        text = line.strip()
        if text.startswith(".. "):
            block_indent = _indent(line)
            continue
        lines[index] = escape_line(line)
        if text.endswith("::"):
            block_indent = _indent(line)


def process_docstring(app, what, name, obj, options, lines) -> None:  # noqa: ANN001
    """The ``autodoc-process-docstring`` handler."""
    escape_bars(lines)
