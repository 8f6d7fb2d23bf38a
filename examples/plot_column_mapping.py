"""
Bring a controller's log through a column mapping
=================================================

A motion controller rarely writes the interchange format (``t, x..rz, l1..l6, f1..f6`` in s,
m, rad and N). This one logs, with semicolons and decimal commas, the time in milliseconds,
the leg lengths in millimetres and the actuator forces in kilonewtons, under its own column
names, and no pose at all. A column mapping (``docs/logs.md``; ``--columns`` on the command
line) says where each interchange column comes from and in which unit; the pose is then
computed from the leg lengths by forward kinematics, and the data are checked against the
platform description before anything is identified.
"""

import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import stewartid as sid

paper = sid.load_platform("paper")
truth = sid.simulate_experiments(paper, coulomb=5.0, duration_s=3.0).datasets[2]  # heave

# %%
# The controller's file, as it would come off the machine.
folder = Path(tempfile.mkdtemp())
log = folder / "heave.csv"
header = (["Time [ms]"] + [f"Leg{k} [mm]" for k in range(1, 7)]
          + [f"Load{k} [kN]" for k in range(1, 7)])
table = np.column_stack([truth.t * 1e3, truth.lengths * 1e3, truth.forces * 1e-3])
lines = [";".join(header)] + [";".join(f"{value:.6f}".replace(".", ",") for value in row)
                              for row in table]
log.write_text("\n".join(lines) + "\n")
print("\n".join(lines[:3]))

# %%
# The mapping, inline as ``--columns`` takes it (a TOML file says the same). The delimiter
# and the decimal comma are detected.
mapping = "t=Time [ms]:ms, l1..l6=Leg{k} [mm]:mm, f1..f6=Load{k} [kN]:kN"
(read,) = sid.read_experiments(log, paper, columns=mapping)
print(f"largest pose difference to the simulated truth: "
      f"{np.abs(read.pose - truth.pose)[:, :3].max() * 1e6:.2f} um, "
      f"{np.abs(read.pose - truth.pose)[:, 3:].max() * 1e6:.2f} urad")

# %%
# The heave the controller never logged, recovered from its leg lengths, and a leg force.
fig, axes = plt.subplots(2, 1, figsize=(8, 4.5), sharex=True)
axes[0].plot(truth.t, truth.pose[:, 2] * 1e3, lw=3, color="0.8", label="simulated")
axes[0].plot(read.t, read.pose[:, 2] * 1e3, lw=1, label="from the log (forward kinematics)")
axes[0].set_ylabel("z (mm)")
axes[0].legend(loc="upper right")
axes[1].plot(read.t, read.forces[:, 0] * 1e-3)
axes[1].set_ylabel("f1 (kN)")
axes[1].set_xlabel("t (s)")
fig.tight_layout()
plt.show()
