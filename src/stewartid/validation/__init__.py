"""Validation of identified models on data the fit did not see."""
