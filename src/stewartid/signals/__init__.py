"""Signal processing shared by the identifiers and the reports: noise-aware differentiation
(:mod:`~stewartid.signals.differentiation`) and continuous wavelets with exact quadrature
(:mod:`~stewartid.signals.wavelets`)."""
