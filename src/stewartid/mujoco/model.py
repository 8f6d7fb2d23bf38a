"""The platform as a MuJoCo model, an independent engine for the same mechanism (``[mujoco]``
extra). MuJoCo's world is the paper frame turned about x: p_mujoco = T p_paper, T = diag(1, -1, -1),
so pose q has position T [x, y, z], angles (rx, -ry, -rz); forces and rates take diag(T, T).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

from stewartid.model.kinematics import inverse_kinematics
from stewartid.platform import GRAVITY, Platform

if TYPE_CHECKING:  # pragma: no cover - typing only
    import mujoco

#: MuJoCo world coordinates = T @ paper coordinates (half a turn about x).
T = np.diag([1.0, -1.0, -1.0])
#: Share of the platform's mass carried by each leg's end body (see the module docstring).
END_MASS_FRACTION = 1e-4
#: Radius (m) of the sphere whose inertia the end bodies carry: the welds' rotational rows'
#: compliance scales with 1/inertia.
END_RADIUS = 0.3
#: Integrators accepted by :func:`build_mjcf` (MuJoCo's names).
INTEGRATORS = ("Euler", "RK4", "implicit", "implicitfast")
#: MuJoCo's default time step here (s).
DEFAULT_TIMESTEP = 5e-4


def require_mujoco() -> Any:
    """Import MuJoCo, or explain which extra installs it.

    Raises
    ------
    ImportError
        If MuJoCo is not installed.
    """
    try:
        import mujoco
    except ImportError as exc:  # pragma: no cover - depends on the environment
        raise ImportError(
            "the MuJoCo model needs the optional dependency mujoco>=3.1; install it with "
            'pip install "stewartid[mujoco]"') from exc
    return mujoco


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


def leg_frames(platform: Platform) -> np.ndarray:
    """Leg frames (6, 3, 3) at the neutral pose, paper frame: columns e1 = unit(z x u), e2 = u x e1, u."""
    legs = inverse_kinematics(platform, platform.neutral_pose)
    frames = np.empty((6, 3, 3))
    for k, u in enumerate(legs.directions[0]):
        e1 = _unit(np.cross([0.0, 0.0, 1.0], u))
        frames[k] = np.column_stack([e1, np.cross(u, e1), u])
    return frames


def _vec(v: Any) -> str:
    return " ".join(f"{float(x):.17g}" for x in np.ravel(v))


def _platform_inertial(platform: Platform) -> tuple[float, np.ndarray, np.ndarray, float, float]:
    """Mass (kg), centre of mass (3,) (m, body frame), ``fullinertia`` (6,) about it (kg m^2) of the
    platform body without the ends, and each end body's mass and inertia.
    """
    i = platform.inertia
    end_mass = END_MASS_FRACTION * i.platform_mass
    end_inertia = 0.4 * end_mass * END_RADIUS ** 2
    r = platform.upper_joints @ T  # rows: T a_k (T is symmetric)
    mass = i.platform_mass - 6 * end_mass
    com = -end_mass * r.sum(axis=0) / mass
    # inertia about the reference point, less the ends (parallel-axis theorem), then moved to
    # the remaining body's own centre of mass
    I_ref = np.diag(i.platform_inertia).astype(float)
    for rk in r:
        I_ref -= end_mass * (rk @ rk * np.eye(3) - np.outer(rk, rk)) + end_inertia * np.eye(3)
    I_com = I_ref - mass * (com @ com * np.eye(3) - np.outer(com, com))
    full = np.array([I_com[0, 0], I_com[1, 1], I_com[2, 2], I_com[0, 1], I_com[0, 2],
                     I_com[1, 2]])
    return mass, com, full, end_mass, end_inertia


def build_mjcf(platform: Platform, *, integrator: str = "RK4",
               timestep: float = DEFAULT_TIMESTEP,
               constraint_timeconst: float | None = None, constraint_impedance: float = 0.9999,
               coulomb: bool = True) -> str:
    """MJCF text of the platform's mechanism.

    Each leg is an open chain from the base closed on the platform by a weld: cylinder on the lower
    Cardan hinges (e1, e2), rod on a slide (qpos = l - l_0) driven by motor ``leg<k>`` (N, extending),
    end body on the upper hinges and the revolute. The platform is a free body, a payload a body fixed
    in it; each end takes ``END_MASS_FRACTION`` of the platform's mass. Gimbal damping; Coulomb as
    ``frictionloss`` on the five hinges (a constraint, as stiff as the welds). An ``[actuator]``
    gives each slide its reflected mass as ``armature`` (inertia of the joint's own coordinate,
    without weight), its viscous friction as ``damping`` and its Coulomb friction as
    ``frictionloss``; electric legs (``platform.electric_legs``) get motors with a current loop
    (:func:`_electric_lines`). The Cardan axes move with
    their bodies, so joint friction differs from ours at the order of the gimbal deflection.

    Parameters
    ----------
    integrator : {"RK4", "implicitfast", "implicit", "Euler"}
    timestep : float
        s.
    constraint_timeconst : float, optional
        Of the welds (s); ``2 * timestep`` by default, MuJoCo's smallest stable.
    constraint_impedance : float
        Of the welds, in (0, 1); closer to 1 is stiffer.
    coulomb : bool
        Model Coulomb friction as ``frictionloss``.
    """
    if integrator not in INTEGRATORS:
        raise ValueError(f"integrator must be one of {INTEGRATORS}; got {integrator!r}.")
    if not (timestep > 0 and math.isfinite(timestep)):
        raise ValueError(f"timestep must be > 0 s; got {timestep!r}.")
    tau = 2.0 * timestep if constraint_timeconst is None else float(constraint_timeconst)
    if not 0.0 < constraint_impedance < 1.0:
        raise ValueError(f"constraint_impedance must lie in (0, 1); got {constraint_impedance!r}.")
    friction = platform.friction.coulomb if coulomb else 0.0
    # the friction rows as stiff as the welds: at MuJoCo's default softness the light end
    # bodies' hinges would not pass their full friction
    imp = f"{constraint_impedance:.17g}"
    frictionloss = (f' frictionloss="{friction:.17g}" solreffriction="{tau:.17g} 1" '
                    f'solimpfriction="{imp} {imp} 0.001 0.5 2"') if friction > 0 else ""
    mass, com, full, end_mass, end_inertia = _platform_inertial(platform)
    lines = _world_lines(platform, integrator, timestep, mass, com, full)
    frames = leg_frames(platform)
    slide = _slide_attributes(platform, tau, imp, coulomb)
    for k in range(6):
        lines += _leg_lines(platform, k, frames[k], frictionloss, end_mass, end_inertia, slide)
    lines += ["  </worldbody>", *_closure_lines(tau, constraint_impedance, platform), "</mujoco>",
              ""]
    return "\n".join(lines)


def _world_lines(platform: Platform, integrator: str, timestep: float, mass: float,
                 com: np.ndarray, full: np.ndarray) -> list[str]:
    """MJCF from the opening tag to the platform body: options, base and platform."""
    g = platform.geometry
    p0 = T @ platform.neutral_pose[:3]
    return [
        f'<mujoco model="stewartid-{platform.name}">',
        '  <compiler angle="radian" inertiafromgeom="false" autolimits="true"/>',
        f'  <option timestep="{timestep:.17g}" integrator="{integrator}" '
        f'gravity="0 0 {-GRAVITY:.17g}" jacobian="dense" solver="Newton" '
        'iterations="50" tolerance="1e-12">',
        '    <flag contact="disable"/>',
        "  </option>",
        "  <default>",
        '    <geom contype="0" conaffinity="0" group="1"/>',
        "  </default>",
        "  <worldbody>",
        f'    <light pos="0 0 {3 * (g.neutral_height + g.reference_height):.6g}"/>',
        f'    <geom name="base" type="cylinder" size="{g.lower_radius:.6g} 0.02" '
        'pos="0 0 -0.02" rgba="0.4 0.4 0.4 1"/>',
        f'    <body name="platform" pos="{_vec(p0)}">',
        "      <freejoint name=\"platform\"/>",
        f'      <inertial pos="{_vec(com)}" mass="{mass:.17g}" fullinertia="{_vec(full)}"/>',
        f'      <geom type="cylinder" size="{g.upper_radius:.6g} 0.05" '
        f'pos="0 0 {-g.reference_height:.17g}" rgba="0.2 0.4 0.8 0.6"/>',
        *_payload_lines(platform),
        "    </body>",
    ]


def _payload_lines(platform: Platform) -> list[str]:
    """MJCF of the payload, a body fixed in the platform's; none without one or of zero mass."""
    payload = platform.payload
    if payload is None or payload.mass == 0.0:
        return []
    I = T @ payload.inertia_matrix @ T
    full = I[[0, 1, 2, 0, 0, 1], [0, 1, 2, 1, 2, 2]]
    return [
        '      <body name="payload">',
        f'        <inertial pos="{_vec(T @ np.asarray(payload.com))}" '
        f'mass="{payload.mass:.17g}" fullinertia="{_vec(full)}"/>',
        "      </body>",
    ]


def _slide_attributes(platform: Platform, tau: float, impedance: str, coulomb: bool) -> str:
    """MJCF attributes of a slide joint for the ``[actuator]``; none for one adding nothing."""
    a = platform.actuator
    attributes = ""
    if a.reflected_mass > 0.0:
        attributes += f' armature="{a.reflected_mass:.17g}"'
    if a.viscous > 0.0:
        attributes += f' damping="{a.viscous:.17g}"'
    if coulomb and a.coulomb > 0.0:
        attributes += (f' frictionloss="{a.coulomb:.17g}" solreffriction="{tau:.17g} 1" '
                       f'solimpfriction="{impedance} {impedance} 0.001 0.5 2"')
    return attributes


def _leg_lines(platform: Platform, k: int, frame: np.ndarray, frictionloss: str,
               end_mass: float, end_inertia: float, slide: str = "") -> list[str]:
    """MJCF of leg ``k``'s chain in its leg ``frame`` (3, 3); ``slide`` the slide joint's attributes."""
    i = platform.inertia
    damping = platform.friction.gimbal_viscous
    l0 = platform.neutral_leg_length
    # MuJoCo refuses a zero principal inertia; the Cardan joints let a leg turn about its axis
    # only at second order in the deflection, so a token value stands for our none.
    axial = f"{max(1e-9 * max(i.lower_leg_inertia, i.upper_leg_inertia), 1e-10):.3g}"
    lower_t = max(i.lower_leg_inertia, 1e-10)
    upper_t = max(i.upper_leg_inertia, 1e-10)
    n = k + 1
    R0 = T @ frame  # leg frame in MuJoCo world coordinates, columns e1, e2, u
    return [
        f'    <body name="leg{n}_cylinder" pos="{_vec(T @ platform.base_joints[k])}" '
        f'xyaxes="{_vec(R0[:, 0])} {_vec(R0[:, 1])}">',
        f'      <joint name="leg{n}_lower1" type="hinge" axis="1 0 0" '
        f'damping="{damping:.17g}"{frictionloss}/>',
        f'      <joint name="leg{n}_lower2" type="hinge" axis="0 1 0" '
        f'damping="{damping:.17g}"{frictionloss}/>',
        f'      <inertial pos="0 0 {i.lower_leg_com:.17g}" mass="{i.lower_leg_mass:.17g}" '
        f'diaginertia="{lower_t:.17g} {lower_t:.17g} {axial}"/>',
        f'      <geom type="capsule" size="0.06" fromto="0 0 0 0 0 {0.55 * l0:.6g}" '
        'rgba="0.6 0.6 0.6 1"/>',
        f'      <body name="leg{n}_rod" pos="0 0 {l0:.17g}">',
        f'        <joint name="leg{n}_slide" type="slide" axis="0 0 1"{slide}/>',
        f'        <inertial pos="0 0 {-i.upper_leg_com:.17g}" '
        f'mass="{i.upper_leg_mass:.17g}" diaginertia="{upper_t:.17g} {upper_t:.17g} '
        f'{axial}"/>',
        f'        <geom type="capsule" size="0.035" fromto="0 0 {-0.55 * l0:.6g} 0 0 0" '
        'rgba="0.8 0.8 0.8 1"/>',
        f'        <body name="leg{n}_end">',
        f'          <joint name="leg{n}_upper1" type="hinge" axis="1 0 0" '
        f'damping="{damping:.17g}"{frictionloss}/>',
        f'          <joint name="leg{n}_upper2" type="hinge" axis="0 1 0" '
        f'damping="{damping:.17g}"{frictionloss}/>',
        f'          <joint name="leg{n}_revolute" type="hinge" axis="0 0 1"{frictionloss}/>',
        f'          <inertial pos="0 0 0" mass="{end_mass:.17g}" '
        f'diaginertia="{end_inertia:.17g} {end_inertia:.17g} {end_inertia:.17g}"/>',
        "        </body>",
        "      </body>",
        "    </body>",
    ]


def _closure_lines(tau: float, impedance: float, platform: Platform | None = None) -> list[str]:
    """MJCF of the welds (time constant ``tau`` s, impedance d) and of the leg motors: force
    actuators, or for electric legs (``platform.electric_legs``) :func:`_electric_lines`."""
    imp = f"{impedance:.17g}"
    lines = ["  <equality>"]
    for k in range(6):
        # relpose omitted: the relative pose of the neutral configuration (qpos0), where every
        # chain meets the platform exactly; anchor 0 puts the position rows at the joint A
        lines.append(f'    <weld name="leg{k + 1}" body1="platform" body2="leg{k + 1}_end" '
                     f'anchor="0 0 0" solref="{tau:.17g} 1" solimp="{imp} {imp} 0.001 0.5 2"/>')
    lines += ["  </equality>", "  <actuator>"]
    if platform is not None and platform.electric_legs:
        lines += _electric_lines(platform)
    else:
        for k in range(6):
            lines.append(f'    <motor name="leg{k + 1}" joint="leg{k + 1}_slide" gear="1"/>')
    lines.append("  </actuator>")
    return lines


def _electric_lines(platform: Platform) -> list[str]:
    """MJCF of electric leg motors: actuator ``leg<k>`` takes the current command (A) through the
    current loop, a first-order filter of time constant 1 / (2 pi current_bandwidth) whose state is
    the current, and pushes force_constant times it along the slide; ``leg<k>_integral``, of no
    force, integrates its control: the state of the servo's integral term (m s).
    """
    from stewartid.simulation.electric import current_bandwidth

    a = platform.actuator
    tau = 1.0 / (2.0 * math.pi * current_bandwidth(a))
    lines = [f'    <general name="leg{k + 1}" joint="leg{k + 1}_slide" dyntype="filter" '
             f'dynprm="{tau:.17g}" gainprm="{a.force_constant:.17g}"/>' for k in range(6)]
    lines += [f'    <general name="leg{k + 1}_integral" joint="leg{k + 1}_slide" '
              'dyntype="integrator" gainprm="0"/>' for k in range(6)]
    return lines


def load_model(platform: Platform, **options: Any) -> mujoco.MjModel:
    """Compile :func:`build_mjcf` (same keyword options) into a ``mujoco.MjModel``.

    Raises
    ------
    ImportError
        If MuJoCo is not installed.
    """
    mj = require_mujoco()
    return mj.MjModel.from_xml_string(build_mjcf(platform, **options))


# -- moving states and forces between the engines -------------------------------------------
