"""Method B (Zhang 2020): the wavelet method on constant-direction intervals.

Per experiment: prepare, noise, intervals, weak-form equations; then one generalized least squares.
"""

from stewartid.identification.wavelet.estimator import WaveletIdentifier

__all__ = ["WaveletIdentifier"]
