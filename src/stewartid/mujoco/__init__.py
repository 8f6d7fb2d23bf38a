"""MuJoCo as an independent engine: the platform as an MJCF model
(:mod:`~stewartid.mujoco.model`), its state at a pose (:mod:`~stewartid.mujoco.state`) and
experiments played on it as logs (:mod:`~stewartid.mujoco.closed_loop`). Needs the
``[mujoco]`` extra.
"""
