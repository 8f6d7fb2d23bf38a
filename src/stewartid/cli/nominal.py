"""``stewartid nominal``: a platform description's nominal Mt and Bt, at neutral or ``--pose``."""

from __future__ import annotations

import json
import math
import sys
from typing import Annotated

import numpy as np
import typer

from stewartid.errors import ConfigError

#: What ``--pose`` takes, as its help and its refusals say it.
POSE_FORM = ("X,Y,Z,RX,RY,RZ: the absolute pose of the reference point in the paper frame "
             "(m, rad; z down), as the x..rz columns of a log in the interchange format")


def parse_pose(text: str) -> np.ndarray:
    """The six numbers of ``--pose``, shape (6,) (m, rad).

    Raises
    ------
    ConfigError
        ``text`` is not six finite comma-separated numbers.
    """
    parts = [part.strip() for part in text.split(",")]
    try:
        values = [float(part) for part in parts]
    except ValueError:
        values = []
    if len(values) != 6 or not all(math.isfinite(v) for v in values):
        raise ConfigError(f"--pose must be six numbers {POSE_FORM}. Got {text!r} instead.")
    return np.array(values)


def nominal(
    platform: Annotated[str, typer.Option(
        "--platform", metavar="NAME|FILE",
        help="'paper' for the preset, or a platform TOML file.")] = "paper",
    as_json: Annotated[bool, typer.Option("--json", help="Print {\"M\": ..., \"B\": ...} "
                                          "(and \"G\" with --pose).")] = False,
    gravity: Annotated[bool, typer.Option("--gravity-stiffness",
                                          help="Also print K_G = dG/dq.")] = False,
    pose: Annotated[str | None, typer.Option(
        "--pose", metavar="POSE",
        help=f"Evaluate at this pose instead of neutral, and print G(q) too; {POSE_FORM}, "
             "within the stroke and gimbal limits.")] = None,
) -> None:
    """Nominal Mt and Bt of the linearised model at the neutral pose (paper frame), or Mt, Bt
    and the gravity force G at the pose given with --pose; with the reflected masses and the
    viscous friction along the legs of an [actuator] section."""
    from stewartid.model.linearization import gravity_stiffness, nominal_matrices, nominal_terms
    from stewartid.platform import load_platform

    description = load_platform(platform)
    if pose is None:
        M, B = nominal_matrices(description)
        G = q = None
    else:
        from stewartid.design.limits import require_within_limits

        q = parse_pose(pose)
        require_within_limits(description, q, f"--pose {pose}")
        M, B, G = nominal_terms(description, q)
    if as_json:
        out = {"M": M.tolist(), "B": B.tolist()}
        if G is not None:
            out["G"] = G.tolist()
        if gravity:
            out["K_G"] = gravity_stiffness(description, q).tolist()
        sys.stdout.write(json.dumps(out) + "\n")
        return
    from stewartid.reports.terminal import print_matrix, print_vector

    where = "neutral pose" if q is None else f"pose {','.join(f'{v:g}' for v in q)}"
    actuator = description.actuator
    # what [actuator] adds, named in the titles only when it adds something
    mass = f"; legs +{actuator.reflected_mass:g} kg" if actuator.reflected_mass else ""
    damping = f"; legs +{actuator.viscous:g} N s/m" if actuator.viscous else ""
    print_matrix(M, f"Mt ({description.name}, {where}{mass})")
    print_matrix(B, f"Bt ({description.name}, {where}{damping})")
    if G is not None:
        print_vector(G, f"G ({description.name}, {where}; N, N m)")
    if gravity:
        print_matrix(gravity_stiffness(description, q), "K_G = dG/dq")
