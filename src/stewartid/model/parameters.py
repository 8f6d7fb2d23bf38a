"""The packed platform-parameter vector the model's kernels read: its one layout.

:meth:`stewartid.platform.Platform.parameters` packs the ``[inertia]``, ``[payload]`` and
``[friction]`` sections and the gravity into a float vector of length :data:`N_PARAMETERS`,
which the compiled kernels (:mod:`stewartid.model.kernels`) and the numpy leg terms
(:mod:`stewartid.model.leg_terms`) index with the constants below. The moving body is the
platform with its payload (:attr:`stewartid.platform.Platform.moving_body`); without a
payload it is the platform alone, centre of mass at the reference point, inertia diagonal.

=============================  ==========================================================
index                          entry (``Platform`` field; unit)
=============================  ==========================================================
``MASS``                       mass of the moving body (``inertia.platform_mass`` plus
                               ``payload.mass``; kg)
``IXX``, ``IYY``, ``IZZ``      diagonal of the moving body's inertia matrix about the
                               reference point, platform frame (kg m^2)
``IXY``, ``IXZ``, ``IYZ``      its off-diagonal entries (products of inertia with the
                               matrix's sign, -sum x y dm; kg m^2)
``COM_X``, ``COM_Y``,          the moving body's centre of mass, platform frame, from the
``COM_Z``                      reference point (m)
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
IXY, IXZ, IYZ, COM_X, COM_Y, COM_Z = 13, 14, 15, 16, 17, 18
#: Length of the packed vector.
N_PARAMETERS = 19

__all__ = ["COM_X", "COM_Y", "COM_Z", "COULOMB", "D_LOWER", "D_UPPER", "GRAVITY", "IXX", "IXY",
           "IXZ", "IYY", "IYZ", "IZZ", "I_LOWER", "I_UPPER", "MASS", "M_LOWER", "M_UPPER",
           "N_PARAMETERS", "VISCOUS"]
