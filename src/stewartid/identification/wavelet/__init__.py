"""Method B (Zhang 2020): the wavelet method on constant-direction intervals.

The pipeline, one module a step: :mod:`~stewartid.identification.wavelet.noise` (the sensor
noise estimated from the data), :mod:`~stewartid.identification.wavelet.detection` and
:mod:`~stewartid.identification.wavelet.intervals` (constant-direction intervals),
:mod:`~stewartid.identification.wavelet.weak_form` and
:mod:`~stewartid.identification.wavelet.point_equations` (the equations on each interval),
:mod:`~stewartid.identification.wavelet.gls` (their generalised least-squares solution) and
:mod:`~stewartid.identification.wavelet.estimator` (the estimator).
"""

from stewartid.identification.wavelet.estimator import WaveletIdentifier

__all__ = ["WaveletIdentifier"]
