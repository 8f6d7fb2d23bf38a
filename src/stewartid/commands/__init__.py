"""CLI command implementations, registered by :mod:`stewartid.cli`."""
