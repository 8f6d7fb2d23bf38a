"""``stewartid nominal``: the nominal Mt and Bt of a platform description."""

from __future__ import annotations

import json
import sys
from typing import Annotated

import typer


def nominal(
    platform: Annotated[str, typer.Option(
        "--platform", metavar="NAME|FILE",
        help="'paper' for the preset, or a platform TOML file.")] = "paper",
    as_json: Annotated[bool, typer.Option("--json", help="Print {\"M\": ..., \"B\": ...}.")] = False,
    gravity: Annotated[bool, typer.Option("--gravity-stiffness",
                                          help="Also print K_G = dG/dq.")] = False,
) -> None:
    """Nominal Mt and Bt of the linearised model at the neutral pose (paper frame)."""
    from stewartid.model.linearization import gravity_stiffness, nominal_matrices
    from stewartid.platform import load_platform

    description = load_platform(platform)
    M, B = nominal_matrices(description)
    if as_json:
        out = {"M": M.tolist(), "B": B.tolist()}
        if gravity:
            out["K_G"] = gravity_stiffness(description).tolist()
        sys.stdout.write(json.dumps(out) + "\n")
        return
    from stewartid.reporting.terminal import print_matrix

    print_matrix(M, f"Mt ({description.name}, neutral pose)")
    print_matrix(B, f"Bt ({description.name}, neutral pose)")
    if gravity:
        print_matrix(gravity_stiffness(description), "K_G = dG/dq")
