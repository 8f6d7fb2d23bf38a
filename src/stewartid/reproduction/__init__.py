"""Reproduction of the paper's Section 5 comparison (``stewartid reproduce``).

Modules: :mod:`~stewartid.reproduction.settings` (what runs),
:mod:`~stewartid.reproduction.run` (simulate, identify, tabulate, plot, report in worker
processes), :mod:`~stewartid.reproduction.comparison` (the identifications of a run with
the nominal and published values), :mod:`~stewartid.reproduction.noisy` (the case with
sensor noise), :mod:`~stewartid.reproduction.traces` (model terms along a simulated
experiment for the signal figures), :mod:`~stewartid.reproduction.tables` (the paper's
Tables 3-6, the comparison per level and the summary), :mod:`~stewartid.reproduction.figures`
(the figures only a reproduction draws), :mod:`~stewartid.reproduction.plots` (the
figures in report order), :mod:`~stewartid.reproduction.report` (``report.md``,
``report.html`` and the summary sentences) and :mod:`~stewartid.reproduction.document`
(``results.json``).
"""
