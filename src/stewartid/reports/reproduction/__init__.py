"""Reproduction of the paper's Section 5 comparison (``stewartid reproduce``).

Modules: :mod:`~stewartid.reports.reproduction.settings` (what runs),
:mod:`~stewartid.reports.reproduction.run` (simulate, identify, tabulate, plot, report in worker
processes), :mod:`~stewartid.reports.reproduction.traces` (model terms along a simulated experiment
for the signal figures), :mod:`~stewartid.reports.reproduction.plots` (the figures in report order)
and :mod:`~stewartid.reports.reproduction.document` (``results.json``).
"""
