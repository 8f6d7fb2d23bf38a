"""
Sensor noise and the information bound
======================================

How accurately can *any* unbiased estimator identify Bt from a given motion?
:func:`~stewartid.identification.bounds.information_bound` gives the Cramér–Rao bound for
white leg-force noise, with the Coulomb force known (``friction="known"``, the oracle) or with
a free constant per constant-direction interval (``friction="immune"``, all that a
friction-immune estimator such as Method B may assume). The bound grows in proportion to the
noise, so one computation per motion gives every noise level (``docs/accuracy-bounds.md``).
"""

import matplotlib.pyplot as plt
import numpy as np

from stewartid import load_platform
from stewartid.design.candidates import paper_design
from stewartid.identification.bounds import information_bound
from stewartid.model.linearization import nominal_matrices
from stewartid.simulation.sensors import static_leg_force

paper = load_platform("paper")
_, nominal_B = nominal_matrices(paper)
#: The motions are sampled at 200 Hz for speed; white noise logged at the plant's 1 kHz
#: carries 5 times the information, so every bound below is divided by sqrt(5).
AT_1KHZ = 1 / np.sqrt(5)


def sine_motions(duration_s, rate_hz=200.0):
    """The paper's excitation played exactly (record k a 0.5 Hz sine on DOF k, with a
    one-period fade-in and fade-out), as (t, q, q_dot, q_ddot) per record."""
    records = paper_design(duration_s=duration_s).playable(paper)
    return [(t, *record.evaluate(t)) for record in records
            for t in [np.arange(0.0, record.record.duration, 1 / rate_hz)]]


# %%
# The reference noise: 0.5 % of the static leg force. On the paper's 6 x 20 s of sines the
# Bt diagonal cannot be known better than this, whatever the estimator (the table of
# ``docs/accuracy-bounds.md`` gives nearly the same numbers for the plant's records).
sigma = 0.005 * static_leg_force(paper)
print(f"reference force noise {sigma:.1f} N per leg")
motions = sine_motions(20.0)
bounds = {friction: information_bound(paper, motions, sigma, friction)
          for friction in ("known", "immune")}
for friction, bound in bounds.items():
    relative = 100 * bound.std[:, 6:].diagonal() / np.abs(nominal_B.diagonal()) * AT_1KHZ
    print(f"{friction:6s}: Bt diagonal bound " + ", ".join(f"{v:.2f}" for v in relative) + " %")

# %%
# The Bt diagonal bound for the heave, Bt(3,3), against the force noise and the record
# length (the bound falls as 1/sqrt(record length) for a stationary motion).
noise = np.linspace(0.25, 2.0, 8) * sigma
fig, axes = plt.subplots(1, 2, figsize=(9, 3.5))
for friction, bound in bounds.items():
    heave = bound.std[2, 8] / abs(nominal_B[2, 2]) * 100 * AT_1KHZ
    axes[0].plot(noise, heave * noise / sigma, "o-", label=friction)
lengths = [5.0, 10.0, 20.0, 40.0]
for friction in ("known", "immune"):
    heave = [information_bound(paper, sine_motions(length), sigma, friction).std[2, 8]
             / abs(nominal_B[2, 2]) * 100 * AT_1KHZ for length in lengths]
    axes[1].loglog(lengths, heave, "o-", label=friction)
axes[0].set_xlabel("force noise per leg (N)")
axes[1].set_xlabel("record length (s)")
for ax in axes:
    ax.set_ylabel("Bt(3,3) bound (% of nominal)")
    ax.legend(title="Coulomb force")
fig.tight_layout()
plt.show()
