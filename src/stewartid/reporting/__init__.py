"""Reports: what a comparison run found, as tables, figures and a Markdown/HTML report, and
terminal tables for the command line.

Modules: :mod:`~stewartid.reporting.comparison` (the data a report is built from, method
labels and colours from the registry), :mod:`~stewartid.reporting.tables` (Markdown/CSV
tables beside the paper's published values), :mod:`~stewartid.reporting.figures`
(matplotlib figures, PNG and SVG), :mod:`~stewartid.reporting.report` (``report.md`` and a
self-contained ``report.html``) and :mod:`~stewartid.reporting.terminal` (rich tables).
"""
