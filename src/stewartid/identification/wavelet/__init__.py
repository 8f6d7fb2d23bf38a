"""Method B (Zhang 2020): the wavelet method on constant-direction intervals.

The data path of :meth:`WaveletIdentifier.fit`, one experiment at a time through steps 1-5
(its arrays dropped once its equations are formed), then step 6 over all of them. Each step is
a function of what the steps before it returned, and no step computes a model term again:

1. :func:`stewartid.identification.preparation.prepare_experiment`: every model term at
   every measured pose, in one pass over the leg geometry: J_lq, G(q), the joint-axis
   Jacobians, the generalized force y = J_lq^T f - G(q) and its pose sensitivity dy/dq.
2. :func:`.detection.excitation_scales`: the smoothing window and the interval margin from
   the excitation frequency estimated from the pose.
3. :func:`.noise.estimate_noise` (noise model): Savitzky-Golay pose rates, the white pose and
   force noise around the smoothed signals, and the noise they put on the joint rates.
4. :func:`.detection.detect_intervals` (intervals): the joint rates from the prepared
   Jacobians, cut where a joint reverses beyond its noise band
   (:func:`.intervals.constant_direction_intervals`).
5. :func:`.weak_form.experiment_equations` (equations): each interval's weak-form equations
   (:func:`.point_equations.point_equations` at (a, b) points with ``test_functions=None``).
6. :func:`.gls.solve_weak_form` (solve): generalised least squares over all intervals, the
   pose noise weighted and its bias removed (:mod:`.variance_components`;
   :func:`~stewartid.identification.solvers.bias_compensated_least_squares` for the points).

:mod:`.estimator` holds the estimator, which runs these steps with its settings.
"""

from stewartid.identification.wavelet.estimator import WaveletIdentifier

__all__ = ["WaveletIdentifier"]
