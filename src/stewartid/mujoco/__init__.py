"""MuJoCo as an independent engine: the platform as an MJCF model, its state at a pose, and
experiments played on it as logs. Needs the ``[mujoco]`` extra.
"""
