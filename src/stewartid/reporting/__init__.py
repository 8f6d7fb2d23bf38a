"""Reports of a comparison run: paper-layout tables, figures and a Markdown/HTML report.

Modules: :mod:`~stewartid.reporting.results` (the data a report is built from),
:mod:`~stewartid.reporting.tables` (Markdown/CSV tables beside the paper's published values),
:mod:`~stewartid.reporting.figures` (matplotlib figures, PNG and SVG) and
:mod:`~stewartid.reporting.report` (``report.md`` and a self-contained ``report.html``).
"""
