"""Time to identify six experiments of 20 s at 1 kHz with every available method.

Data: the linear model itself (helper of the test suite) on the paper's platform, one sine
per DOF at 0.5 Hz. Run: ``python benchmarks/bench_identification.py``.
"""

from __future__ import annotations

import importlib
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from linear_model_data import make_experiment, random_matrices  # noqa: E402
from stewartid.platform import load_platform  # noqa: E402

METHODS = {
    "fourier": ("stewartid.identification.fourier", "FourierIdentifier"),
    "ls": ("stewartid.identification.least_squares", "LeastSquaresIdentifier"),
    "wavelet": ("stewartid.identification.wavelet", "WaveletIdentifier"),
}


def main() -> None:
    platform = load_platform("paper")
    M, B = random_matrices(np.random.default_rng(0))
    data = [make_experiment(platform, M, B, k, frequency_hz=0.5, periods=10,
                            sample_rate=1000.0) for k in range(6)]
    print(f"{len(data)} experiments x {data[0].duration + 1e-3:.0f} s at "
          f"{data[0].sample_rate:.0f} Hz")
    for method, (module, name) in METHODS.items():
        try:
            cls = getattr(importlib.import_module(module), name)
        except (ImportError, AttributeError) as exc:
            print(f"{method:8s} skipped ({exc})")
            continue
        cls().fit(data[:6], platform)  # warm-up: numba caches, imports
        start = time.perf_counter()
        est = cls().fit(data, platform)
        elapsed = time.perf_counter() - start
        error = np.max(np.abs(est.M_ - M)) / np.max(np.abs(M))
        print(f"{method:8s} {elapsed:6.2f} s   max |dM| / max|M| = {error:.1e}")


if __name__ == "__main__":
    main()
