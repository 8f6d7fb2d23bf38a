"""Method B alone over many noise seeds: are its standard errors honest, and how large is its
largest error?

One log kind of :mod:`noise_study` (the paper's sines, ten times their amplitude, three sines
per DOF, all DOFs at once) on our plant, clean logs simulated once into ``--clean`` (or read
from there), then for each seed the reference sensor noise added as the verdict study adds it
and Method B (``wavelet``, defaults) fitted. Prints one line: the share of the paper's 20
entries over all seeds within 3 reported standard errors, the largest error in standard
errors, the root mean square of error / standard error (1 for honest Gaussian errors), and the
median and largest of the seeds' largest relative errors.

Usage::

    python benchmarks/wavelet_calibration.py [--platform paper|FILE] [--kind paper]
        [--coulomb 5] [--seeds 0:12] --clean DIR
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import noise_study  # noqa: E402  (a sibling script)

from stewartid.identification.registry import create_identifier  # noqa: E402
from stewartid.model.linearization import nominal_matrices  # noqa: E402
from stewartid.platform import load_platform  # noqa: E402
from stewartid.reference.published import PAPER_ENTRIES  # noqa: E402
from stewartid.simulation import degrade  # noqa: E402
from stewartid.simulation.sensors import reference_noise  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--platform", default="paper", help="paper or a platform TOML file")
    parser.add_argument("--kind", default="paper", choices=noise_study.KINDS)
    parser.add_argument("--coulomb", type=float, default=5.0, help="N m")
    parser.add_argument("--seeds", default="0:12", help="first:stop (stop excluded)")
    parser.add_argument("--clean", type=Path, default=Path("noise_study_logs"),
                        help="folder of the clean logs (simulated there when missing)")
    args = parser.parse_args()
    first, stop = (int(v) for v in args.seeds.split(":"))
    platform = load_platform(args.platform).replace(friction__coulomb=args.coulomb)
    tag = "paper" if args.platform == "paper" else Path(args.platform).stem
    clean = noise_study.kind_logs(args.kind, platform,
                                  args.clean / f"{tag}_{args.kind}_c{args.coulomb:g}")
    truth = dict(zip("MB", nominal_matrices(platform), strict=True))
    ratios, worst = [], []
    for seed in range(first, stop):
        data = [degrade(d, platform, reference_noise(platform),
                        np.random.default_rng(seed + 101 * k)) for k, d in enumerate(clean)]
        result = create_identifier("wavelet").fit(data, platform).result_
        found = {"M": (result.M, result.std_errors_M), "B": (result.B, result.std_errors_B)}
        errors = np.array([found[m][0][i, j] - truth[m][i, j] for m, i, j in PAPER_ENTRIES])
        stds = np.array([found[m][1][i, j] for m, i, j in PAPER_ENTRIES])
        scale = np.array([abs(truth[m][i, j]) for m, i, j in PAPER_ENTRIES])
        ratios.extend(np.abs(errors) / stds)
        worst.append(100 * float(np.max(np.abs(errors) / scale)))
        print(f"seed {seed}: largest error {worst[-1]:.2f} %, {max(ratios[-20:]):.2f} SE",
              flush=True)
    ratios = np.array(ratios)
    print(f"{tag} {args.kind} {args.coulomb:g} N m, seeds {first}-{stop - 1}: within 3 SE "
          f"{100 * np.mean(ratios <= 3):.1f} %, largest {ratios.max():.2f} SE, rms error/SE "
          f"{np.sqrt(np.mean(ratios ** 2)):.2f}; largest error median {np.median(worst):.2f} "
          f"%, max {max(worst):.2f} %")


if __name__ == "__main__":
    main()
