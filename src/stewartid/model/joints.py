"""The five rotational joint axes of a leg (two per gimbal, then the revolute), which carry viscous
friction, and the joint types the Coulomb levels are identified per; see ``docs/conventions.md``.
"""

from __future__ import annotations

#: Names of the five rotational joint axes of a leg, in the order of the joint-rate Jacobians.
JOINT_AXES = ("lower_1", "lower_2", "upper_1", "upper_2", "revolute")
#: Number of rotational joint axes per leg.
N_JOINTS = len(JOINT_AXES)
#: Axes (indices into :data:`JOINT_AXES`) with viscous friction: the four gimbal axes, which
#: come first.
GIMBAL_AXES = (0, 1, 2, 3)
#: Number of gimbal axes; axis j is a gimbal axis when j < N_GIMBAL_AXES.
N_GIMBAL_AXES = len(GIMBAL_AXES)
#: Joint types and their axes (indices into :data:`JOINT_AXES`); one Coulomb level each.
JOINT_TYPES = {"lower_gimbal": (0, 1), "upper_gimbal": (2, 3), "revolute": (4,)}
#: Joint types of the Coulomb levels, in the order of the regressors.
FRICTION_TYPES = tuple(JOINT_TYPES)

__all__ = ["FRICTION_TYPES", "GIMBAL_AXES", "JOINT_AXES", "JOINT_TYPES", "N_GIMBAL_AXES",
           "N_JOINTS"]
