"""
The report and its verdict: which method to trust
=================================================

``stewartid identify --method all --report DIR`` fits every registered method to the same
experiments, validates each on data it was not fitted on (every record cut into time
segments, each predicted by the method refitted without it) and says which method to trust
and why. The same in Python is
:func:`~stewartid.reports.identification.report.write_identification_report`. Here the
plant has 30 N·m of Coulomb friction per joint axis and the reference sensor noise, and two
methods are compared on 4 s records (the Fourier method needs longer ones): Method B
(wavelet) and the time-domain least squares, which models Coulomb friction. The verdict's
sentences are computed from the numbers of the run.
"""

import tempfile

import matplotlib.pyplot as plt
import numpy as np

from stewartid import compare_methods, load_platform, write_report
from stewartid.identification.registry import registered_methods
from stewartid.reports.identification.verdict_text import verdict_lines
from stewartid.simulation import simulate_experiments
from stewartid.simulation.sensors import reference_noise

paper = load_platform("paper")
run = simulate_experiments(paper, coulomb=30.0, duration_s=4.0, noise=reference_noise(paper),
                           seed=1)
print("registered:", ", ".join(spec.name for spec in registered_methods()))
comparison = compare_methods(run.datasets, paper, methods=("wavelet", "ls"), folds=2)
report = write_report(comparison, tempfile.mkdtemp())
print(f"trusted: {report.trusted}")
print("\n".join(verdict_lines(report.verdict, report.runs)))

# %%
# Held-out variance accounted for, per degree of freedom and method (100 % is a perfect
# prediction of data the method was not fitted on).
dofs = ["x", "y", "z", "rx", "ry", "rz"]
fig, ax = plt.subplots(figsize=(8, 3.5))
width = 0.8 / len(report.runs)
for k, method in enumerate(report.runs):
    if method.validation is None:
        continue
    ax.bar(np.arange(6) + (k - (len(report.runs) - 1) / 2) * width,
           method.validation.vaf_percent, width, label=method.display_name, color=method.color)
ax.set_xticks(range(6), dofs)
ax.set_ylim(min(90.0, min(np.min(m.validation.vaf_percent) for m in report.runs
                          if m.validation is not None) - 1), 100.5)
ax.set_ylabel("held-out VAF (%)")
ax.set_title(f"trusted: {report.trusted}")
ax.legend(loc="lower left", fontsize=8)
fig.tight_layout()
plt.show()
