"""
An excitation design within the machine's limits
================================================

``stewartid design`` chooses records that identify every Mt and Bt entry to the accuracy it
needs, within the platform's ``[limits]`` (stroke, leg speed and acceleration, actuator
force, gimbal angle). Its building blocks are fast: here the paper's set of sines is
compared with a designed set of the same length, two amplitude levels per record (intervals
of two speeds, which separate viscous from Coulomb friction) at the largest amplitudes the
limits allow. The commanded limit use of each, and the standard error of every Bt entry
predicted for Method B with one Coulomb level (the estimator a design is made for) from the
information of its equations, are computed on the motion itself through the rigid-body model,
without simulating the plant (the full design plays every candidate on the plant and checks
the prediction by a Monte Carlo of noisy fits).
"""

import matplotlib.pyplot as plt
import numpy as np

import stewartid as sid
from stewartid.design.candidates import paper_design, scheduled_design
from stewartid.design.optimise import commanded_use, largest_amplitudes
from stewartid.design.weak_information import information_prediction

paper = sid.load_platform("paper")
noise = sid.reference_noise(paper)
amplitudes = largest_amplitudes(paper, 0.5, max_use=0.7)
designs = {"paper's sines": paper_design(duration_s=20.0),
           "two levels, largest amplitudes": scheduled_design(amplitudes, 0.5, [20.0] * 6,
                                                              levels=(1.0, 0.5))}
print("largest amplitudes (m, rad):", np.round(amplitudes, 4))

# %%
# Peak use of each limit over the records, and the predicted standard error of the Bt
# diagonal with the reference sensor noise.
fig, axes = plt.subplots(1, 2, figsize=(10, 3.6))
for k, (label, design) in enumerate(designs.items()):
    peaks = {}
    for record in design.records:
        for name, value in commanded_use(paper, record).peak.items():
            peaks[name] = max(peaks.get(name, 0.0), value)
    prediction = information_prediction(paper, design, noise, source="model")
    relative = 100 * prediction.std_B.diagonal() / np.abs(prediction.nominal_B.diagonal())
    print(f"{label}: {design.duration:.0f} s, Bt diagonal standard error "
          + ", ".join(f"{v:.2f}" for v in relative) + " %")
    axes[0].bar(np.arange(len(peaks)) + (k - 0.5) * 0.4, list(peaks.values()), 0.4, label=label)
    axes[0].set_xticks(range(len(peaks)), list(peaks), rotation=20, fontsize=8)
    axes[1].bar(np.arange(6) + (k - 0.5) * 0.4, relative, 0.4, label=label)
axes[0].axhline(1.0, color="k", lw=0.8)
axes[0].set_ylabel("peak use of the limit")
axes[1].set_xticks(range(6), ["x", "y", "z", "rx", "ry", "rz"])
axes[1].set_ylabel("Bt diagonal std error (% of nominal)")
axes[1].legend(fontsize=8)
fig.tight_layout()
plt.show()
