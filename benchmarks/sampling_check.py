"""Does the sampling check change coverage, once every standard error has the model floor?

The paper's six experiments (0.5 Hz sines, 20 s, Coulomb 30 N m) on our plant without sensor
noise, simulated once at 1 kHz, then thinned to 1/4, 1/10 and 1/20 of the rate (250, 100 and
50 Hz: 1000 to 50 samples per period of the fastest excitation, 1 Hz). Each method fitted with
and without the sampling check's refits (forced at every rate, whatever the margin); for each,
the largest error over the paper's 20 entries in reported standard errors, how many are within
3, and whether the check found the result sampling-limited.

Usage::

    python benchmarks/sampling_check.py [--factors 1,4,10,20] [--methods wavelet,ls,fourier]
"""

from __future__ import annotations

import argparse
import os
import warnings

import numpy as np

import stewartid as sid
from stewartid.identification import sampling
from stewartid.identification.sampling import samples_per_period, thinned
from stewartid.reference.published import PAPER_ENTRIES


def scored(result, M: np.ndarray, B: np.ndarray) -> tuple[float, int]:
    """Largest |error| / SE over the paper's entries, and how many are within 3 SE."""
    z = [abs((result.M if name == "M" else result.B)[i, j] - (M if name == "M" else B)[i, j])
         / (result.std_errors_M if name == "M" else result.std_errors_B)[i, j]
         for name, i, j in PAPER_ENTRIES]
    return float(max(z)), int(sum(v <= 3.0 for v in z))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--factors", default="1,4,10,20")
    parser.add_argument("--methods", default="wavelet,ls,fourier")
    args = parser.parse_args()
    warnings.simplefilter("ignore")
    sampling.SAMPLES_PER_PERIOD = float("inf")   # the refits at every rate, to compare
    platform = sid.load_platform("paper")
    M, B = sid.nominal_matrices(platform)
    clean = sid.simulate_experiments(platform, coulomb=30.0, duration_s=20.0,
                                     jobs=os.cpu_count() or 1).datasets
    print(f"load average before: {os.getloadavg()[0]:.2f}")
    print("| rate | samples per period | method | with the refits | without |")
    print("|---|---|---|---|---|")
    for factor in (int(f) for f in args.factors.split(",")):
        data = [thinned(d, factor) for d in clean]
        for method in args.methods.split(","):
            cells = []
            for check in (True, False):
                try:
                    result = sid.create_identifier(method, sampling_check=check).fit(
                        data, platform).result_
                except sid.StewartidError as error:
                    cells.append(f"refused: {str(error).splitlines()[0][:60]}")
                    continue
                largest, within = scored(result, M, B)
                limited = result.diagnostics.get("sampling", {}).get("limited")
                cells.append(f"{largest:.2f} SE, {within}/20"
                             + (" (limited)" if check and limited else ""))
            print(f"| {data[0].sample_rate:.0f} Hz | {samples_per_period(data):.0f} | {method} | "
                  + " | ".join(cells) + " |", flush=True)
    print(f"load average after: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
