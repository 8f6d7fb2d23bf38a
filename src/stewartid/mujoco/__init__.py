"""MuJoCo as an independent engine: the platform as an MJCF model
(:mod:`~stewartid.mujoco.model`) and its state at a pose (:mod:`~stewartid.mujoco.state`).
Needs the ``[mujoco]`` extra.
"""
