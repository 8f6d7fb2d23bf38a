"""Force channels numbered differently from the legs: what the check before any fit sees on
logs numbered right, and on the same logs with their channels renumbered.

For each folder of logs (``DIR@PLATFORM``): the mean correlation of the channels with the leg
forces the platform's model predicts (``force_channel_correlation``) as logged and for the best
numbering, and the gain of that numbering over the logged one (the check names a numbering
from ``CHANNEL_ORDER_GAIN``, 0.5). Then the same logs with their channels renumbered (two
swaps, a rotation by one leg, the reversed order): each renumbering's gain and whether the
check names the numbering that undoes it.

Usage::

    python benchmarks/force_channel_check.py DIR@paper DIR@src/stewartid/data/electric.toml ...
"""

from __future__ import annotations

import argparse
import time
import warnings

from stewartid.datasets import read_experiments
from stewartid.datasets.dataset import Dataset
from stewartid.datasets.set_checks import check_force_channels, numbering_scores
from stewartid.errors import DataError
from stewartid.platform import load_platform

#: Renumberings applied: channel k holds leg RENUMBERINGS[name][k]'s force.
RENUMBERINGS = {"swap 1-2": [1, 0, 2, 3, 4, 5], "swap 1-4": [3, 1, 2, 0, 4, 5],
                "rotation": [5, 0, 1, 2, 3, 4], "reversed": [5, 4, 3, 2, 1, 0]}


def renumbered(data: list[Dataset], legs: list[int]) -> list[Dataset]:
    return [Dataset(t=d.t, pose=d.pose, lengths=d.lengths, forces=d.forces[:, legs],
                    name=d.name) for d in data]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("logs", nargs="+", metavar="DIR@PLATFORM")
    args = parser.parse_args()
    warnings.simplefilter("ignore")
    print("| logs | as logged | best | gain | check (ms) | " + " | ".join(RENUMBERINGS) + " |")
    print("|---" * (5 + len(RENUMBERINGS)) + "|")
    for item in args.logs:
        folder, platform_name = item.split("@")
        platform = load_platform(platform_name)
        column = "i" if platform.actuator.kind == "electric" else "f"
        data = read_experiments(folder, platform, payload_unknown=True)
        start = time.perf_counter()
        found = numbering_scores(data, platform)
        spent = time.perf_counter() - start
        cells = []
        for legs in RENUMBERINGS.values():
            records = renumbered(data, legs)
            moved = numbering_scores(records, platform)
            try:
                check_force_channels(records, platform)
                verdict = "not named"
            except DataError as exc:
                # the named numbering undoes the renumbering: channel k follows leg legs[k]
                verdict = "named" if all(f"{column}{k + 1} follows leg {legs[k] + 1}" in str(exc)
                                         for k in range(6) if legs[k] != k) else "another named"
            cells.append(f"{moved.max() - moved[0]:.2f}, {verdict}")
        print(f"| {folder} | {found[0] / 6:.3f} | {found.max() / 6:.3f} | "
              f"{found.max() - found[0]:.3f} | {spent * 1e3:.0f} | " + " | ".join(cells) + " |")

if __name__ == "__main__":
    main()
