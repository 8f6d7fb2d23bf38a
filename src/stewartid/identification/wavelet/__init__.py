"""Method B (Zhang 2020): the wavelet method on constant-direction intervals.

The data path of :meth:`WaveletIdentifier.fit`, steps 1-5 per experiment, step 6 over all:

1. :func:`stewartid.identification.preparation.prepare_experiment`: every model term at
   every measured pose (J_lq, G(q), joint-axis Jacobians, y and dy/dq).
2. :func:`.detection.excitation_scales`: smoothing window and interval margin.
3. :func:`.noise.estimate_noise`: pose rates, white pose and force noise, joint-rate noise.
4. :func:`.detection.detect_intervals`: constant-direction intervals of the joint rates.
5. :func:`.weak_form.experiment_equations`: each interval's weak-form equations
   (:func:`.point_equations.point_equations` at (a, b) points).
6. :func:`.gls.solve_weak_form`: generalised least squares over all intervals, the pose
   noise weighted and its bias removed.

:mod:`.estimator` holds the estimator, which runs these steps with its settings.
"""

from stewartid.identification.wavelet.estimator import WaveletIdentifier

__all__ = ["WaveletIdentifier"]
