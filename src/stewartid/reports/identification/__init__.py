"""The identification report (``stewartid identify --report``) of a comparison: its text,
figures and files (:func:`~stewartid.reports.identification.report.write_report`)."""
