"""Command-line interface ``stewartid COMMAND``: :mod:`stewartid.cli.application` and one module
per command."""

from stewartid.cli.application import app, main

__all__ = ["app", "main"]
