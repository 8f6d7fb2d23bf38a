"""Physical consistency of measured data with the platform description: a
:class:`~stewartid.errors.DataError` naming the likely cause (unit, frame, leg numbering, file)
and its fix, or a :class:`~stewartid.errors.DataWarning` for a mismatch a user may mean.
"""

from __future__ import annotations

import itertools
import warnings

import numpy as np

from stewartid.arrays import median
from stewartid.errors import DataError, DataWarning
from stewartid.model.kinematics import compute_leg_terms, leg_lengths
from stewartid.model.linearization import nominal_matrices
from stewartid.platform import Platform

#: Largest |rx|, |ry|, |rz| (rad) a hexapod reaches; larger values are angles in degrees.
MAX_ANGLE_RAD = 1.0
#: Largest distance of the logged position from neutral, as a fraction of neutral_height.
MAX_POSITION_OFFSET = 0.5
#: Largest relative deviation of the median leg length from the neutral leg length.
MAX_LENGTH_DEVIATION = 0.5
#: Inverse kinematics: the varying part of (logged - computed) leg lengths may reach the
#: larger of this (m) and IK_EXCURSION_FRACTION of the legs' RMS excursion.
IK_TOLERANCE_M = 0.5e-3
IK_EXCURSION_FRACTION = 0.1
#: A constant leg-length offset above IK_TOLERANCE_M is a warning; above this fraction of the
#: neutral leg length it is an error (strokes logged instead of gimbal-to-gimbal lengths).
MAX_LENGTH_OFFSET = 0.05
#: Static balance: relative deviation of the mean vertical force from the weight that gives
#: a warning, and one below the weight that gives an error.
BALANCE_WARNING = 0.05
BALANCE_ERROR = 0.2
#: The weight the forces may carry, in multiples of the file's: by default (a payload not in
#: the file warns), and when the data identify the rigid-body model, whose payload the
#: weight is evidence of.
CARRIED_WEIGHT = (1.0 - BALANCE_ERROR, 5.0)
PHYSICAL_CARRIED_WEIGHT = (0.5, 5.0)
#: A single leg's mean force may differ from its static share by this fraction.
LEG_BALANCE_ERROR = 0.5
#: Forces that carry no weight but vary by more than this fraction of the legs' static loads
#: (median over the legs) follow the motion: channels zeroed at rest, not unplugged.
TARED_VARIATION = 0.005
#: Identified diagonal of Mt or Bt beyond this factor of the nominal one: a warning.
NOMINAL_WARNING_FACTOR = 2.0
#: Identified diagonal of Mt beyond this factor of the nominal one: an error (units).
NOMINAL_ERROR_FACTOR = 10.0
#: Identified diagonal of Bt this many standard errors below zero: an error (the mechanism
#: only dissipates; Gaussian noise puts one of six entries there once in 500,000 fits).
NEGATIVE_DAMPING_SE = 5.0

#: Samples used by the checks (an evenly strided subset keeps them fast on long logs).
CHECK_SAMPLES = 2000
_FLIP_Z_UP = np.array([1.0, -1.0, -1.0, 1.0, -1.0, -1.0])


def _warn(message: str) -> None:
    warnings.warn(message, DataWarning, stacklevel=3)


def _subsample(*arrays: np.ndarray) -> tuple[np.ndarray, ...]:
    stride = max(1, int(np.ceil(len(arrays[0]) / CHECK_SAMPLES)))
    return tuple(a[::stride] for a in arrays)


def check_leg_lengths(lengths: np.ndarray, platform: Platform, where: str) -> None:
    """Logged leg lengths (N, 6), m, must be near the neutral leg length; ``where`` names the file.

    Raises
    ------
    DataError
        Lengths in mm or cm, strokes instead of gimbal-to-gimbal lengths, wrong platform.
    """
    neutral = platform.neutral_leg_length
    ratio = median(lengths) / neutral
    if abs(ratio - 1.0) <= MAX_LENGTH_DEVIATION:
        return
    if abs(ratio / 1000.0 - 1.0) <= MAX_LENGTH_DEVIATION:
        cause = "they look like millimetres: map them with --columns l1..l6=:mm"
    elif abs(ratio / 100.0 - 1.0) <= MAX_LENGTH_DEVIATION:
        cause = "they look like centimetres: map them with --columns l1..l6=:cm"
    elif ratio < 1.0:
        cause = ("actuator strokes instead of gimbal-to-gimbal lengths? add the length at zero "
                 "stroke as an offset (docs/logs.md), or check --platform")
    else:
        cause = "check the length unit (m) and --platform"
    raise DataError(f"{where}: leg lengths l1..l6 have median {median(lengths):.4g}, but "
                    f"platform '{platform.name}' has {neutral:.4g} m legs at neutral; {cause}.")


def check_pose(pose: np.ndarray, platform: Platform, where: str) -> None:
    """Logged pose (N, 6), absolute [x, y, z, rx, ry, rz] in m, rad, z down, must be near neutral.

    Raises
    ------
    DataError
        Angles in degrees; positions in mm, relative to neutral or z up.
    """
    angles = np.max(np.abs(pose[:, 3:]), axis=0)
    if np.max(angles) > MAX_ANGLE_RAD:
        name = ("rx", "ry", "rz")[int(np.argmax(angles))]
        raise DataError(f"{where}: column {name} reaches {np.max(angles):.4g} rad, beyond any "
                        f"hexapod (> {MAX_ANGLE_RAD} rad); angles in degrees? map them with "
                        "--columns rx..rz=:deg.")
    neutral = platform.neutral_pose
    height = platform.geometry.neutral_height
    offset = np.max(np.abs(pose[:, :3] - neutral[:3]))
    if offset <= MAX_POSITION_OFFSET * height:
        return
    z = median(pose[:, 2])
    if abs(z) < MAX_POSITION_OFFSET * height:
        cause = (f"the pose looks relative to neutral; add offset = {neutral[2]:.6g} to z "
                 "(docs/logs.md)")
    elif abs(z + neutral[2]) < MAX_POSITION_OFFSET * height:
        cause = ("z points up; the paper frame is z down (docs/conventions.md): map y, z, ry, "
                 "rz with scale = -1")
    elif abs(z / (1000.0 * neutral[2]) - 1.0) < MAX_POSITION_OFFSET:
        cause = "x, y, z look like millimetres: map them with --columns x..z=:mm"
    else:
        cause = "check the position unit (m), the frame and --platform"
    raise DataError(f"{where}: the position is {offset:.4g} m from the neutral pose of platform "
                    f"'{platform.name}' (z = {neutral[2]:.6g} m); {cause}.")


def _ik_misfit(pose: np.ndarray, lengths: np.ndarray, platform: Platform
               ) -> tuple[float, np.ndarray]:
    """RMS of the varying part of lengths - IK(pose) (m), and its constant part per leg."""
    residual = lengths - leg_lengths(platform, pose)
    constant = residual.mean(axis=0)
    return float(np.sqrt(np.mean((residual - constant) ** 2))), constant


def check_inverse_kinematics(pose: np.ndarray, lengths: np.ndarray, platform: Platform,
                             where: str) -> None:
    """Logged leg lengths (N, 6), m, must match the inverse kinematics of the logged pose (N, 6).

    Raises
    ------
    DataError
        Naming the likely cause (unit, frame, leg numbering, platform file).

    Warns
    -----
    DataWarning
        Constant offset between logged and computed lengths (sensor calibration).
    """
    pose, lengths = _subsample(pose, lengths)
    excursion = float(np.sqrt(np.mean((lengths - lengths.mean(axis=0)) ** 2)))
    tolerance = max(IK_TOLERANCE_M, IK_EXCURSION_FRACTION * excursion)
    limit = MAX_LENGTH_OFFSET * platform.neutral_leg_length

    def fits(candidate_pose: np.ndarray, candidate_lengths: np.ndarray) -> bool:
        misfit, constant = _ik_misfit(candidate_pose, candidate_lengths, platform)
        return misfit <= tolerance and np.max(np.abs(constant)) <= limit

    misfit, constant = _ik_misfit(pose, lengths, platform)
    if misfit <= tolerance and np.max(np.abs(constant)) <= limit:
        if np.max(np.abs(constant)) > IK_TOLERANCE_M:
            leg = int(np.argmax(np.abs(constant)))
            _warn(f"{where}: l{leg + 1} is {constant[leg] * 1e3:+.3g} mm off the inverse "
                  "kinematics of the logged pose, constantly (a calibration offset?); the "
                  "pose is used.")
        return
    degrees = pose.copy()
    degrees[:, 3:] *= np.pi / 180.0
    millimetres = pose.copy()
    millimetres[:, :3] /= 1000.0
    candidates = [
        ("rx, ry, rz look like degrees: map them with --columns rx..rz=:deg", degrees, lengths),
        ("x, y, z look like millimetres: map them with --columns x..z=:mm", millimetres,
         lengths),
        ("the pose is in a z-up frame; the paper frame is z down (docs/conventions.md)",
         pose * _FLIP_Z_UP, lengths),
    ]
    cause = next((cause for cause, candidate_pose, candidate_lengths in candidates
                  if fits(candidate_pose, candidate_lengths)), None)
    cause = cause or _leg_order(pose, lengths, platform, fits) or (
        "wrong platform file (--platform), leg numbering or frame? see docs/logs.md")
    raise DataError(f"{where}: leg lengths l1..l6 differ from the inverse kinematics of the "
                    f"logged pose by {misfit * 1e3:.3g} mm RMS (tolerance "
                    f"{tolerance * 1e3:.2g} mm); {cause}.")


def _leg_order(pose: np.ndarray, lengths: np.ndarray, platform: Platform, fits) -> str | None:
    """A renumbering of the logged legs matching the inverse kinematics, as a message."""
    computed = leg_lengths(platform, pose)
    computed = computed - computed.mean(axis=0)
    logged = lengths - lengths.mean(axis=0)
    cost = np.sqrt(np.mean((logged[:, :, None] - computed[:, None, :]) ** 2, axis=0))
    totals = {p: sum(cost[j, p[j]] for j in range(6)) for p in itertools.permutations(range(6))}
    lowest = min(totals.values())
    # legs that move alike in one experiment tie; the renumbering that moves fewest wins
    best = min((p for p, total in totals.items() if total <= lowest + IK_TOLERANCE_M),
               key=lambda p: sum(j != p[j] for j in range(6)))
    if best == tuple(range(6)) or not fits(pose, lengths[:, np.argsort(best)]):
        return None
    mapping = ",".join(f"l{best[j] + 1}=l{j + 1}" for j in range(6) if best[j] != j)
    return (f"the legs are numbered differently from docs/conventions.md: map them with "
            f"--columns {mapping}")


#: The static balance's advice for logged forces, and for logged motor currents.
_FORCE_HINTS = {"columns": "f1..f6", "kilo": "forces in kN? map them with --columns f1..f6=:kN",
                "unplugged": "force channels unplugged or not logged",
                "unit": "wrong platform file (--platform) or force unit (N)", "warning": ""}
_CURRENT_HINTS = {"columns": "i1..i6",
                  "kilo": "wrong force_constant in [actuator] (N/A) or current unit (A)",
                  "unplugged": "current channels unplugged or not logged",
                  "unit": "wrong force_constant in [actuator] or current unit (A)",
                  "warning": ", or a wrong force_constant in [actuator]"}


def check_static_balance(pose: np.ndarray, forces: np.ndarray, platform: Platform,
                         where: str, carried: tuple[float, float] = CARRIED_WEIGHT,
                         currents: bool = False) -> None:
    """Mean actuator forces (N, 6), N, positive extends, must carry the implied weight: over whole
    periods the mean J_lq(q)^T f balances G(q); ``carried`` is the allowed range in multiples of
    the file's weight (:data:`PHYSICAL_CARRIED_WEIGHT` for payload fits). ``currents``: the
    forces are logged motor currents (A) times ``[actuator] force_constant``, and the messages
    speak of the currents and of the force constant.

    Raises
    ------
    DataError
        Forces near zero, in kN (currents in mA), of opposite sign, a dead channel, or weight
        outside ``carried``.

    Warns
    -----
    DataWarning
        Weight off by more than :data:`BALANCE_WARNING`, unless the range is the physical model's.
    """
    pose, forces = _subsample(pose, forces)
    # the pose-only leg terms that preparation uses too: no mass matrix, no compiled kernel
    gravity, leg_jacobian, _, _ = compute_leg_terms(platform, np.ascontiguousarray(pose))
    generalized = np.einsum("nij,ni->nj", leg_jacobian, forces)
    weight = -float(np.mean(gravity[:, 2]))
    ratio = round(-float(np.mean(generalized[:, 2])) / weight, 6) + 0.0  # no "-0"
    if currents:
        hints = _CURRENT_HINTS
        constant = f"force_constant = {platform.actuator.force_constant:g} N/A in [actuator]"
        what = (f"{where}: the currents i1..i6 carry {ratio:.3g} times the weight of platform "
                f"'{platform.name}' ({weight:.4g} N) with its {constant}")
    else:
        hints = _FORCE_HINTS
        what = (f"{where}: the forces f1..f6 carry {ratio:.3g} times the weight of platform "
                f"'{platform.name}' ({weight:.4g} N)")
    static = np.linalg.solve(np.transpose(leg_jacobian, (0, 2, 1)), gravity[..., None])[..., 0]
    if abs(ratio) < 0.02:
        # zeroed at rest, the channels still follow the motion; unplugged, they do not
        loads = static.mean(axis=0)
        varying = float(np.median(forces.std(axis=0) / np.abs(loads)))
        if varying > TARED_VARIATION:
            # a current channel's offset is in amperes: its load over the force constant
            unit, scale = ("A", 1.0 / platform.actuator.force_constant) if currents else ("N", 1.0)
            offsets = ", ".join(f"{hints['columns'][0]}{k + 1} {scale * load:.5g}"
                                for k, load in enumerate(loads))
            raise DataError(f"{what}, but vary with the motion ({100 * varying:.2g} % of the "
                            "legs' static loads): zeroed at rest? give each channel its static "
                            f"load as offset in a mapping file ({unit}: {offsets}; docs/logs.md).")
    if abs(ratio * 1000.0 - 1.0) <= BALANCE_ERROR:
        raise DataError(f"{what}; {hints['kilo']}.")
    if currents and abs(ratio / 1000.0 - 1.0) <= BALANCE_ERROR:
        raise DataError(f"{what}; currents in mA? map them with --columns i1..i6=:mA.")
    if abs(ratio) < 0.02:
        raise DataError(f"{what}; {hints['unplugged']}?")
    if abs(ratio + 1.0) <= BALANCE_ERROR:
        raise DataError(f"{what}; positive must extend the leg: map {hints['columns']} with "
                        "scale = -1 (docs/logs.md).")
    # each leg against the others before the total: one reversed or dead channel moves the
    # total too (a reversed one to 2/3 of the weight), where the unit or the file is not at fault
    shares = forces.mean(axis=0) / static.mean(axis=0)
    typical = float(np.median(shares))
    if typical > 0:
        shares = shares / typical
        leg = int(np.argmax(np.abs(shares - 1.0)))
        column = f"{hints['columns'][0]}{leg + 1}"
        if abs(shares[leg] + 1.0) <= LEG_BALANCE_ERROR:
            raise DataError(f"{where}: column {column} carries {shares[leg]:.3g} times its static "
                            f"load, the other legs about their share; positive must extend the "
                            f"leg: map {column} with scale = -1 (docs/logs.md).")
        if abs(shares[leg] - 1.0) > LEG_BALANCE_ERROR:
            raise DataError(f"{where}: column {column} carries {shares[leg]:.3g} times its static "
                            "load, the other legs about their share; check that channel "
                            "(unplugged, unit, sign).")
    if not carried[0] <= ratio <= carried[1]:
        raise DataError(f"{what}; {hints['unit']}?")
    if carried == PHYSICAL_CARRIED_WEIGHT:
        return
    if ratio > 1.0 + BALANCE_WARNING:
        _warn(f"{what}: a payload missing from the platform file? `stewartid identify --model "
              "physical --payload` identifies it (docs/physical-model.md), or add its "
              f"[payload] section{hints['warning']}.")
    elif abs(ratio - 1.0) > BALANCE_WARNING:
        _warn(f"{what}: a payload missing from the platform file (its [payload] "
              f"section){hints['warning']}?")


def check_dataset(pose: np.ndarray, lengths: np.ndarray, forces: np.ndarray,
                  platform: Platform, where: str, both_logged: bool,
                  carried: tuple[float, float] = CARRIED_WEIGHT, currents: bool = False) -> None:
    """Consistency checks needing pose (m, rad), lengths (m) and forces (N) together, each (N, 6);
    lengths must agree with the pose when ``both_logged``; ``carried`` and ``currents`` as
    :func:`check_static_balance`.
    """
    if both_logged:
        check_inverse_kinematics(pose, lengths, platform, where)
    check_static_balance(pose, forces, platform, where, carried, currents)


def check_identified(M: np.ndarray, B: np.ndarray, platform: Platform,
                     method: str | None = None, friction_blind: bool = False,
                     std_B: np.ndarray | None = None) -> None:
    """Identified Mt, Bt (6, 6) against the description's nominal ones; ``method`` is named in the
    messages; ``friction_blind`` (Method A) explains a high Bt as Coulomb friction taken for damping;
    ``std_B`` (6, 6), Bt's standard errors, lets a negative damping be told from noise.

    Raises
    ------
    DataError
        A diagonal Mt entry beyond :data:`NOMINAL_ERROR_FACTOR` of nominal, or a diagonal Bt
        entry more than :data:`NEGATIVE_DAMPING_SE` of its standard errors below zero.

    Warns
    -----
    DataWarning
        A diagonal Mt or Bt entry beyond :data:`NOMINAL_WARNING_FACTOR`.
    """
    nominal = dict(zip(("Mt", "Bt"), nominal_matrices(platform), strict=True))
    hint = ("check the units (t s, x..z m, rx..rz rad, f N), the friction model and "
            "--platform (docs/logs.md)")
    if std_B is not None:
        scores = np.diag(B) / np.where(np.diag(std_B) > 0, np.diag(std_B), np.inf)
        worst = int(np.argmin(scores))
        if scores[worst] < -NEGATIVE_DAMPING_SE:
            raise DataError(
                f"{f'{method}: ' if method else ''}identified Bt({worst + 1},{worst + 1}) = "
                f"{B[worst, worst]:.5g} ± {std_B[worst, worst]:.2g}: a negative damping, which "
                "no passive platform has; the forces lead the motion (a pose or length channel "
                "logged late: --delay with a negative value), or the time runs backwards.")
    for label, identified in (("Mt", M), ("Bt", B)):
        reference = np.diag(nominal[label])
        values = np.diag(identified)
        with np.errstate(divide="ignore", invalid="ignore"):
            ratios = np.where(reference > 0, values / reference, 1.0)
        worst = int(np.argmax(np.abs(np.log(np.abs(ratios) + 1e-300))))
        factor = ratios[worst]
        entry = (f"{f'{method}: ' if method else ''}identified {label}({worst + 1},"
                 f"{worst + 1}) = {values[worst]:.5g} is {factor:.3g} times the nominal "
                 f"{reference[worst]:.5g} of platform '{platform.name}'")
        if label == "Mt" and not 1 / NOMINAL_ERROR_FACTOR <= factor <= NOMINAL_ERROR_FACTOR:
            raise DataError(f"{entry}; {hint}.")
        if not 1 / NOMINAL_WARNING_FACTOR <= factor <= NOMINAL_WARNING_FACTOR:
            if label == "Bt" and friction_blind and factor > 1:
                _warn(f"{entry}: the method does not model Coulomb friction, which it takes "
                      "for damping (--method wavelet or ls model it; were their Bt as far off, "
                      "check the units and --platform).")
            else:
                _warn(f"{entry}; {hint}.")


__all__ = ["CARRIED_WEIGHT", "PHYSICAL_CARRIED_WEIGHT", "check_dataset", "check_identified",
           "check_inverse_kinematics", "check_leg_lengths", "check_pose", "check_static_balance"]
