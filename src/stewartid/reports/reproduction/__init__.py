"""Reproduction of the paper's Section 5 comparison (``stewartid reproduce``).

Modules: :mod:`~stewartid.reports.reproduction.settings` (what runs),
:mod:`~stewartid.reports.reproduction.run` (simulate, identify, tabulate, plot, report in worker
processes), :mod:`~stewartid.reports.reproduction.comparison` (the identifications of a run with
the nominal and published values), :mod:`~stewartid.reports.reproduction.noisy` (the case with
sensor noise), :mod:`~stewartid.reports.reproduction.traces` (model terms along a simulated
experiment for the signal figures), :mod:`~stewartid.reports.reproduction.tables` (the paper's
Tables 3-6, the comparison per level and the summary), :mod:`~stewartid.reports.reproduction.figures`
(the figures only a reproduction draws), :mod:`~stewartid.reports.reproduction.plots` (the
figures in report order), :mod:`~stewartid.reports.reproduction.report` (``report.md``,
``report.html`` and the summary sentences) and :mod:`~stewartid.reports.reproduction.document`
(``results.json``).
"""
