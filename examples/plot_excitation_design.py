"""
An excitation design within the machine's limits
================================================

``stewartid design`` chooses records that identify every Mt and Bt entry to the accuracy it
needs, within the platform's ``[limits]`` (stroke, leg speed and acceleration, actuator
force, gimbal angle). Its building blocks are fast: here the paper's set of sines is
compared with a designed set of the same length, two amplitude levels per record (intervals
of two speeds, which separate viscous from Coulomb friction) at the largest amplitudes the
limits allow. The commanded limit use and the friction-immune information bound of each are
computed without simulating the plant (the full design also plays every candidate on it).
"""

import matplotlib.pyplot as plt
import numpy as np

from stewartid import load_platform
from stewartid.design.candidates import paper_design, scheduled_design
from stewartid.design.optimise import commanded_use, largest_amplitudes
from stewartid.identification.bounds import information_bound
from stewartid.model.linearization import nominal_matrices
from stewartid.simulation.sensors import static_leg_force

paper = load_platform("paper")
_, nominal_B = nominal_matrices(paper)
sigma = 0.005 * static_leg_force(paper)
amplitudes = largest_amplitudes(paper, 0.5, max_use=0.7)
designs = {"paper's sines": paper_design(duration_s=20.0),
           "two levels, largest amplitudes": scheduled_design(amplitudes, 0.5, [20.0] * 6,
                                                              levels=(1.0, 0.5))}
print("largest amplitudes (m, rad):", np.round(amplitudes, 4))


def motions_of(design, rate_hz=200.0):
    """(t, q, q_dot, q_ddot) of every record, played exactly (the motion itself, no plant)."""
    return [(t, *record.evaluate(t)) for record in design.playable(paper)
            for t in [np.arange(0.0, record.record.duration, 1 / rate_hz)]]


# %%
# Peak use of each limit over the records, and the bound on the Bt diagonal.
fig, axes = plt.subplots(1, 2, figsize=(10, 3.6))
for k, (label, design) in enumerate(designs.items()):
    peaks = {}
    for record in design.records:
        for name, value in commanded_use(paper, record).peak.items():
            peaks[name] = max(peaks.get(name, 0.0), value)
    bound = information_bound(paper, motions_of(design), sigma, "immune")
    # sampled at 200 Hz for speed; white noise logged at 1 kHz informs 5 times as much
    relative = 100 * bound.std[:, 6:].diagonal() / np.abs(nominal_B.diagonal()) / np.sqrt(5)
    print(f"{label}: {design.duration:.0f} s, Bt diagonal bound "
          + ", ".join(f"{v:.2f}" for v in relative) + " %")
    axes[0].bar(np.arange(len(peaks)) + (k - 0.5) * 0.4, list(peaks.values()), 0.4, label=label)
    axes[0].set_xticks(range(len(peaks)), list(peaks), rotation=20, fontsize=8)
    axes[1].bar(np.arange(6) + (k - 0.5) * 0.4, relative, 0.4, label=label)
axes[0].axhline(1.0, color="k", lw=0.8)
axes[0].set_ylabel("peak use of the limit")
axes[1].set_xticks(range(6), ["x", "y", "z", "rx", "ry", "rz"])
axes[1].set_ylabel("Bt diagonal bound (% of nominal)")
axes[1].legend(fontsize=8)
fig.tight_layout()
plt.show()
