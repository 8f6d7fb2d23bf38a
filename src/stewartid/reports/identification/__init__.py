"""``stewartid identify``: the run behind the command
(:mod:`~stewartid.reports.identification.run`) and the report of ``--report``
(:mod:`~stewartid.reports.identification.report`; its data in
:mod:`~stewartid.reports.identification.records`, its text, figures and drawings in
:mod:`~stewartid.reports.identification.text`,
:mod:`~stewartid.reports.identification.figures` and
:mod:`~stewartid.reports.identification.method_figures`)."""
