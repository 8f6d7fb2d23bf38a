"""What every report of the package is built from: tables, figures, the HTML page, method
labels, terminal tables and the matrix files.

Modules: :mod:`~stewartid.reporting.methods` (display names, colours, the paper's letters and
report order, from the registry), :mod:`~stewartid.reporting.tables` (titled tables written as
Markdown and CSV), :mod:`~stewartid.reporting.figures` (the figures' style and saving as PNG and
SVG, and the signal figures of an experiment), :mod:`~stewartid.reporting.html` (Markdown to a
self-contained HTML page), :mod:`~stewartid.reporting.terminal` (rich tables) and
:mod:`~stewartid.reporting.exports` (identified matrices as CSV and MATLAB files).

The products built on these parts import from here, never the reverse:
:mod:`stewartid.reports.identification` (``identify --report``),
:mod:`stewartid.reports.reproduction` (``reproduce``), :mod:`stewartid.studies` (``study``) and
:mod:`stewartid.design` (``design``). Held-out validation and the choice of the method to trust
are in :mod:`stewartid.assessment`.
"""
