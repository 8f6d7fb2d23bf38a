"""The packed platform-parameter vector the model's kernels read: its one layout.

:meth:`stewartid.platform.Platform.parameters` packs the ``[inertia]`` and ``[friction]``
sections and the gravity into a float vector of length :data:`N_PARAMETERS`, which the
compiled kernels (:mod:`stewartid.model.kernels`) and the numpy leg terms
(:mod:`stewartid.model.leg_terms`) index with the constants below.

=============================  ==========================================================
index                          entry (``Platform`` field; unit)
=============================  ==========================================================
``MASS``                       platform mass (``inertia.platform_mass``; kg)
``IXX``, ``IYY``, ``IZZ``      principal platform inertias (``inertia.platform_inertia``;
                               kg m^2)
``M_UPPER``, ``M_LOWER``       mass of a leg's upper and lower part (kg)
``D_UPPER``, ``D_LOWER``       gimbal point to that part's centre of mass
                               (``inertia.upper_leg_com``, ``lower_leg_com``; m)
``I_UPPER``, ``I_LOWER``       transverse inertia of that part about its centre of mass
                               (kg m^2)
``VISCOUS``                    viscous coefficient of each gimbal axis
                               (``friction.gimbal_viscous``; N m s/rad)
``COULOMB``                    Coulomb torque of each joint axis (``friction.coulomb``; N m)
``GRAVITY``                    gravitational acceleration along +z (m/s^2)
=============================  ==========================================================
"""

from __future__ import annotations

MASS, IXX, IYY, IZZ = 0, 1, 2, 3
M_UPPER, M_LOWER, D_UPPER, D_LOWER, I_UPPER, I_LOWER = 4, 5, 6, 7, 8, 9
VISCOUS, COULOMB, GRAVITY = 10, 11, 12
#: Length of the packed vector.
N_PARAMETERS = 13

__all__ = ["COULOMB", "D_LOWER", "D_UPPER", "GRAVITY", "IXX", "IYY", "IZZ", "I_LOWER", "I_UPPER",
           "MASS", "M_LOWER", "M_UPPER", "N_PARAMETERS", "VISCOUS"]
