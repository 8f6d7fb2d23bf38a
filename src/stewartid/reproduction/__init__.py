"""Reproduction of the paper's Section 5 comparison (``stewartid reproduce``).

Modules: :mod:`~stewartid.reproduction.settings` (what runs),
:mod:`~stewartid.reproduction.run` (simulate, identify, tabulate, plot, report in worker
processes), :mod:`~stewartid.reproduction.traces` (model terms along a simulated experiment
for the signal figures), :mod:`~stewartid.reproduction.plots` (the figures in report order)
and :mod:`~stewartid.reproduction.document` (``results.json``).
"""
