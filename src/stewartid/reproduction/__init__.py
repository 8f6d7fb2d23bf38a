"""Reproduction of the paper's Section 5 comparison (``stewartid reproduce``,
:func:`~stewartid.reproduction.run.run_reproduce`)."""
