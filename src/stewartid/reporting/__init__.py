"""Reports: what a comparison run found, as tables, figures and a Markdown/HTML report, and
terminal tables for the command line.

Modules: :mod:`~stewartid.reporting.comparison` (the data a report is built from, method
labels and colours from the registry), :mod:`~stewartid.reporting.tables` (Markdown/CSV
tables beside the paper's published values), :mod:`~stewartid.reporting.figures`
(matplotlib figures, PNG and SVG), :mod:`~stewartid.reporting.document` (``report.md`` and a
self-contained ``report.html``) and :mod:`~stewartid.reporting.terminal` (rich tables).

The two products built on these parts are :mod:`stewartid.reports.identification`
(``identify --report``: the run in :mod:`~stewartid.reports.identification.run`, the report in
:mod:`~stewartid.reports.identification.report`, its text and figures, and
:mod:`~stewartid.reporting.exports` for the CSV and MATLAB files) and
:mod:`stewartid.reports.reproduction` (``reproduce``). Held-out validation and the choice of
the method to trust are in :mod:`stewartid.assessment`.
"""
