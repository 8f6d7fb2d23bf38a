"""Assessment of identified models: prediction of data the fit did not see
(:mod:`~stewartid.assessment.validation`) and which of several models to trust
(:mod:`~stewartid.assessment.verdict`)."""
