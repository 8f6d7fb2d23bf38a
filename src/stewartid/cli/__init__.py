"""Command-line interface: ``stewartid COMMAND ...``.

:mod:`~stewartid.cli.application` holds the application and its error policy; one module per
command: :mod:`~stewartid.cli.nominal`, :mod:`~stewartid.cli.simulate`,
:mod:`~stewartid.cli.identify`, :mod:`~stewartid.cli.reproduce`, :mod:`~stewartid.cli.methods`.
"""

from stewartid.cli.application import app, main

__all__ = ["app", "main"]
