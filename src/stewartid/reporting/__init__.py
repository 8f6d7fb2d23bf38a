"""Reports: what a comparison run found, as tables, figures and a Markdown/HTML report, and
terminal tables for the command line.

Modules: :mod:`~stewartid.reporting.comparison` (the data a report is built from, method
labels and colours from the registry), :mod:`~stewartid.reporting.tables` (Markdown/CSV
tables beside the paper's published values), :mod:`~stewartid.reporting.figures`
(matplotlib figures, PNG and SVG), :mod:`~stewartid.reporting.document` (``report.md`` and a
self-contained ``report.html``) and :mod:`~stewartid.reporting.terminal` (rich tables).

The report on a user's own measured experiments (``identify --report``):
:mod:`~stewartid.reports.identification.report` (fits, validation, consistency, files),
:mod:`~stewartid.assessment.validation` (held-out prediction, VAF and NRMSE),
:mod:`~stewartid.reports.identification.text` (which method to trust, ``report.md``),
:mod:`~stewartid.reports.identification.figures` and
:mod:`~stewartid.reports.identification.method_figures` (its figures) and
:mod:`~stewartid.reporting.exports` (CSV and MATLAB files).
"""
