"""The model of the platform: pure batched functions, time on axis 0.

- :mod:`~stewartid.model.joints`: the joint axes of a leg and their types;
- :mod:`~stewartid.model.parameters`: the layout of the packed parameter vector;
- :mod:`~stewartid.model.kinematics`: inverse and forward kinematics, Jacobians;
- :mod:`~stewartid.model.leg_terms`: leg geometry and joint rates;
- :mod:`~stewartid.model.dynamics`: inverse and forward dynamics with joint friction;
- :mod:`~stewartid.model.linearization`: the nominal Mt, Bt and the gravity stiffness;
- :mod:`~stewartid.model.kernels` and :mod:`~stewartid.model.compiled`: the per-sample
  kernels the plant steps with, as Python source and compiled with numba.
"""
