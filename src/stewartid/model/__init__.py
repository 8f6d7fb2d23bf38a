"""The model of the platform: pure batched functions, time on axis 0 (kinematics, leg terms,
dynamics, linearization, and the per-sample kernels the plant steps with).
"""
