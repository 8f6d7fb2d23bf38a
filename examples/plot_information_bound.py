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

import stewartid as sid
from stewartid.identification.bounds import information_bound

paper = sid.load_platform("paper")
_, nominal_B = sid.nominal_matrices(paper)
#: The motions are sampled at 200 Hz for speed; white noise logged at the plant's 1 kHz
#: carries 5 times the information, so every bound below is divided by sqrt(5).
AT_1KHZ = 1 / np.sqrt(5)
#: The paper's sine amplitude per DOF (m, m, m, rad, rad, rad).
AMPLITUDES = (0.02, 0.02, 0.02, 0.01, 0.01, 0.01)


def ramp(s):
    """Quintic smoothstep on s in [0, 1] and its first two derivatives in s."""
    s = np.clip(s, 0.0, 1.0)
    return s ** 3 * (10 - 15 * s + 6 * s ** 2), 30 * s ** 2 * (1 - s) ** 2, 60 * s * (1 - s) * (1 - 2 * s)


def sine_motions(duration_s, rate_hz=200.0, frequency_hz=0.5):
    """The paper's excitation played exactly: record k a 0.5 Hz sine on DOF k about the
    neutral pose, faded in and out over one period each, as (t, q, q_dot, q_ddot) per record
    (``duration_s`` whole periods)."""
    t = np.arange(0.0, duration_s, 1 / rate_hz)
    fade, omega = 1 / frequency_hz, 2 * np.pi * frequency_hz
    rise, d_rise, dd_rise = ramp(t / fade)
    fall, d_fall, dd_fall = ramp((duration_s - t) / fade)
    a = rise * fall  # the envelope and its time derivatives
    da = (d_rise * fall - rise * d_fall) / fade
    dda = (dd_rise * fall - 2 * d_rise * d_fall + rise * dd_fall) / fade ** 2
    sin, cos = np.sin(omega * t), np.cos(omega * t)
    shapes = (a * sin, da * sin + a * omega * cos,
              dda * sin + 2 * da * omega * cos - a * omega ** 2 * sin)
    motions = []
    for k in range(6):
        q, q_dot, q_ddot = (np.outer(x, AMPLITUDES[k] * np.eye(6)[k]) for x in shapes)
        motions.append((t, q + paper.neutral_pose, q_dot, q_ddot))
    return motions


# %%
# The reference noise: 0.5 % of the static leg force. On the paper's 6 x 20 s of sines the
# Bt diagonal cannot be known better than this, whatever the estimator (the table of
# ``docs/accuracy-bounds.md`` gives nearly the same numbers for the plant's records).
sigma = sid.reference_noise(paper).force_noise
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
lengths = [6.0, 10.0, 20.0, 40.0]
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
