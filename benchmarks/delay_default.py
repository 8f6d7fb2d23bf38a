"""The force delay by default: estimated and applied where the motion tells it from damping,
left alone where it is noise. Our plant's three-sine and all-DOF logs (Coulomb 30 N m,
6 x 20 s at 1 kHz, :func:`noise_study.kind_logs`), the reference sensor noise per seed, the
forces logged ``--late`` seconds late or on time; per log the estimated delay, whether it was
applied, and Method B's and least squares' errors against the nominal matrices.

Usage::

    python benchmarks/delay_default.py [--kinds three,alldof] [--seeds 4] [--late 0.002]
        [--clean DIR]
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import noise_study  # noqa: E402  (a sibling script)

import stewartid as sid  # noqa: E402
from stewartid.comparison import align_experiments  # noqa: E402
from stewartid.reference.published import PAPER_ENTRIES, relative_error_percent  # noqa: E402


def scores(result, M, B) -> str:
    """Largest Mt-diagonal error, largest error (%) and entries within 3 SE of the 20."""
    truth = {"M": M, "B": B}
    found = {"M": result.M, "B": result.B}
    std = {"M": result.std_errors_M, "B": result.std_errors_B}
    errors = [relative_error_percent(found[m][i, j], truth[m][i, j]) for m, i, j in PAPER_ENTRIES]
    within = sum(abs(found[m][i, j] - truth[m][i, j]) <= 3 * std[m][i, j]
                 for m, i, j in PAPER_ENTRIES)
    return f"{max(errors[:6]):.2f} | {max(errors):.1f} | {within}/20"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--kinds", default="three,alldof")
    parser.add_argument("--seeds", type=int, default=4)
    parser.add_argument("--late", type=float, default=0.002)
    parser.add_argument("--clean", type=Path, default=Path("results/delay_default"))
    options = parser.parse_args()
    platform = sid.load_platform("paper").replace(friction__coulomb=noise_study.KIND_COULOMB)
    M, B = sid.nominal_matrices(platform)
    print("| log | late (ms) | seed | delay ± SE (ms) | applied | Method B: Mt diag (%) | "
          "largest (%) | in 3 SE | least squares: Mt diag (%) | largest (%) | in 3 SE |")
    print("|---" * 11 + "|")
    for kind in options.kinds.split(","):
        clean = noise_study.kind_logs(kind, platform, options.clean / kind)
        for late in (options.late, 0.0):
            noise = dataclasses.replace(sid.reference_noise(platform), force_delay=late)
            for seed in range(options.seeds):
                data = [sid.degrade(d, platform, noise, np.random.default_rng(seed + 101 * k))
                        for k, d in enumerate(clean)]
                aligned = align_experiments(data, platform)
                entry = aligned.entry
                fits = [sid.create_identifier(name).fit(aligned.experiments, platform).result_
                        for name in ("wavelet", "ls")]
                print(f"| {kind} | {late * 1e3:g} | {seed} | {entry['seconds'] * 1e3:.3f} ± "
                      f"{entry['std_error'] * 1e3:.3f} | {entry['applied']} | "
                      + " | ".join(scores(fit, M, B) for fit in fits) + " |", flush=True)


if __name__ == "__main__":
    main()
