"""Command-line interface: ``stewartid COMMAND ...``. :mod:`~stewartid.cli.application` holds
the application and its error policy; one module per command (``nominal``, ``simulate``,
``identify`` with :mod:`~stewartid.cli.identify_run`, ``reproduce``, ``methods``, ``study``,
``design``)."""

from stewartid.cli.application import app, main

__all__ = ["app", "main"]
