"""The two reports: :mod:`~stewartid.reports.identification` (``identify --report``) and
:mod:`~stewartid.reports.reproduction` (``stewartid reproduce``)."""
