"""Method B's sign-rate noise limit: where the Coulomb signs' rates come from, and what it does.

Method B takes the Coulomb signs from the shortest Savitzky-Golay window whose noise is within
``SIGN_NOISE_LIMIT`` of the rates' RMS (:mod:`stewartid.identification.wavelet.detection`). For
each log set (a platform and a kind of :func:`noise_study.kind_logs`: the paper's sines, ten
times their amplitude, three sines per DOF, all DOFs at once), noise-free and with the
reference sensor noise per seed, Method B is fitted with each limit given; printed per set and
limit: the (entry, log) pairs of the paper's 20 entries within 3 standard errors, the largest
error in standard errors and in %, and how often the free interval constants were chosen.

Usage::

    python benchmarks/sign_noise_limit.py --clean DIR [--limits 0.0005,0.002] [--seeds 6]
        [--sets paper:paper,paper:tenx,paper:three,paper:alldof,FILE:three,...]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import noise_study  # noqa: E402  (a sibling script)

from stewartid.identification.registry import create_identifier  # noqa: E402
from stewartid.identification.wavelet import detection  # noqa: E402
from stewartid.model.linearization import nominal_matrices  # noqa: E402
from stewartid.platform import load_platform  # noqa: E402
from stewartid.reference.published import PAPER_ENTRIES  # noqa: E402
from stewartid.simulation import degrade  # noqa: E402
from stewartid.simulation.sensors import reference_noise  # noqa: E402

HERE = Path(__file__).resolve().parent
#: The log sets of the default run: platform (name or file) and kind.
SETS = ("paper:paper", "paper:tenx", "paper:three", "paper:alldof",
        f"{HERE / 'small_platform.toml'}:three", f"{HERE / 'small_platform.toml'}:alldof",
        f"{HERE / 'heavy_platform.toml'}:three", f"{HERE / 'heavy_platform.toml'}:alldof")


def scores(result, M: np.ndarray, B: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Relative errors (%) and error / SE over the paper's 20 entries."""
    errors, ratios = [], []
    for matrix, i, j in PAPER_ENTRIES:
        value, std, truth = ((result.M, result.std_errors_M, M) if matrix == "M" else
                             (result.B, result.std_errors_B, B))
        errors.append(100 * (value[i, j] - truth[i, j]) / abs(truth[i, j]))
        ratios.append((value[i, j] - truth[i, j]) / std[i, j])
    return np.array(errors), np.array(ratios)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--clean", type=Path, required=True, help="noise-free logs' cache")
    parser.add_argument("--limits", default="0.0005,0.002")
    parser.add_argument("--seeds", type=int, default=6)
    parser.add_argument("--sets", default=",".join(SETS))
    args = parser.parse_args()
    limits = [float(x) for x in args.limits.split(",")]
    for item in args.sets.split(","):
        name, kind = item.rsplit(":", 1)
        platform = load_platform(name)
        if platform.friction.coulomb == 0:
            platform = platform.replace(friction__coulomb=noise_study.KIND_COULOMB)
        tag = "paper" if name == "paper" else Path(name).stem
        folder = args.clean / f"ours_{tag}_{kind}_c{platform.friction.coulomb:g}"
        clean = noise_study.kind_logs(kind, platform, folder)
        M, B = nominal_matrices(platform)
        found = {limit: [0, 0, 0.0, 0.0, 0] for limit in limits}
        for seed in [None, *range(args.seeds)]:
            data = clean if seed is None else [
                degrade(d, platform, reference_noise(platform),
                        np.random.default_rng(seed + 101 * k)) for k, d in enumerate(clean)]
            for limit in limits:
                detection.SIGN_NOISE_LIMIT = limit
                result = create_identifier("wavelet", jobs=None).fit(data, platform).result_
                errors, ratios = scores(result, M, B)
                tally = found[limit]
                tally[0] += int(np.sum(np.abs(ratios) <= 3))
                tally[1] += len(ratios)
                tally[2] = max(tally[2], float(np.max(np.abs(ratios))))
                tally[3] = max(tally[3], float(np.max(np.abs(errors))))
                tally[4] += result.diagnostics.get("friction_model") == "free"
        print(f"{tag} {kind}: " + " | ".join(
            f"limit {limit:g}: {t[0]}/{t[1]} within 3 SE, largest {t[2]:.1f} SE, "
            f"{t[3]:.1f} %, free constants on {t[4]}" for limit, t in found.items()), flush=True)


if __name__ == "__main__":
    main()
