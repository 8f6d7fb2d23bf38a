"""Layout of the packed parameter vector (:meth:`stewartid.platform.Platform.parameters`) that
the kernels and leg terms index; the moving body is the platform with its payload.
"""

from __future__ import annotations

# Moving body: mass (kg); inertia about the reference point, platform frame, products with the
# matrix's sign -sum x y dm (kg m^2); centre of mass from the reference point (m).
# Leg parts: mass (kg), gimbal point to centre of mass (m), transverse inertia about it (kg m^2).
# Gimbal viscous coefficient (N m s/rad), joint Coulomb torque (N m), gravity along +z (m/s^2).
# Along each leg ([actuator]): reflected mass (kg), viscous (N s/m) and Coulomb (N) friction.
MASS, IXX, IYY, IZZ = 0, 1, 2, 3
M_UPPER, M_LOWER, D_UPPER, D_LOWER, I_UPPER, I_LOWER = 4, 5, 6, 7, 8, 9
VISCOUS, COULOMB, GRAVITY = 10, 11, 12
IXY, IXZ, IYZ, COM_X, COM_Y, COM_Z = 13, 14, 15, 16, 17, 18
REFLECTED_MASS, LEG_VISCOUS, LEG_COULOMB = 19, 20, 21
#: Length of the packed vector.
N_PARAMETERS = 22

__all__ = ["COM_X", "COM_Y", "COM_Z", "COULOMB", "D_LOWER", "D_UPPER", "GRAVITY", "IXX", "IXY",
           "IXZ", "IYY", "IYZ", "IZZ", "I_LOWER", "I_UPPER", "LEG_COULOMB", "LEG_VISCOUS", "MASS",
           "M_LOWER", "M_UPPER", "N_PARAMETERS", "REFLECTED_MASS", "VISCOUS"]
