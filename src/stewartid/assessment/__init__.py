"""Assessment of identified models: prediction of data the fit did not see."""
