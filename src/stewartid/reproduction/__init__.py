"""Reproduction of the paper's Section 5 comparison (``stewartid reproduce``).

:func:`~stewartid.reproduction.run.run_reproduce` simulates, identifies and writes the
results, tables, figures and report of one run.
"""
