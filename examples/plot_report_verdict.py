"""
The verdict: which method to trust
==================================

``stewartid identify --method all --report DIR`` fits every registered method to the same
experiments, validates each on data it was not fitted on (every record cut into time
segments, each predicted by the method refitted without it) and says which method to trust
and why. In Python the same comparison is :func:`stewartid.compare_methods`, which writes no
file; :func:`stewartid.write_report` renders it as the report. Here the plant has 30 N·m of
Coulomb friction per joint axis and the reference sensor noise, and two methods are compared
on 4 s records (the Fourier method needs longer ones): Method B (wavelet) and the time-domain
least squares, which models Coulomb friction. The verdict's sentences are computed from the
numbers of the run.
"""

import matplotlib.pyplot as plt
import numpy as np

import stewartid as sid

paper = sid.load_platform("paper")
run = sid.simulate_experiments(paper, coulomb=30.0, duration_s=4.0,
                               noise=sid.reference_noise(paper), seed=1)
print("registered:", ", ".join(spec.name for spec in sid.registered_methods()))
comparison = sid.compare_methods(run.datasets, paper, methods=("wavelet", "ls"), folds=2)
print(f"trusted: {comparison.trusted} (ranking: {', '.join(comparison.ranking)})")
for reason in comparison.reasons:
    print("-", reason)

# %%
# The trusted Mt and Bt diagonals with their standard errors, beside the nominal values of
# the linearised model (kg and kg m², N s/m and N m s/rad). ``comparison.M``, ``comparison.B``
# and ``comparison.std_errors`` are the trusted method's; every method's fitted estimator is
# in ``comparison.estimators``, and ``sid.write_report(comparison, DIR)`` writes the report.
nominal = {"M": comparison.nominal_M, "B": comparison.nominal_B}
trusted = {"M": comparison.M, "B": comparison.B}
dofs = ["x", "y", "z", "rx", "ry", "rz"]
print("   " + "  ".join(f" {key + 't':>9s} {'std err':>8s} {'nominal':>9s}" for key in "MB"))
for k, dof in enumerate(dofs):
    print(f"{dof:3s}" + "  ".join(f" {trusted[key][k, k]:9.0f} {comparison.std_errors[key][k, k]:8.0f}"
                                  f" {nominal[key][k, k]:9.0f}" for key in "MB"))

# %%
# Held-out variance accounted for, per degree of freedom and method (100 % is a perfect
# prediction of data the method was not fitted on).
validated = [fit for fit in comparison.runs if fit.name in comparison.validation]
fig, ax = plt.subplots(figsize=(8, 3.5))
width = 0.8 / len(validated)
for k, fit in enumerate(validated):
    ax.bar(np.arange(6) + (k - (len(validated) - 1) / 2) * width,
           comparison.validation[fit.name].vaf_percent, width, label=fit.display_name,
           color=fit.color)
ax.set_xticks(range(6), dofs)
ax.set_ylim(min(90.0, min(np.min(comparison.validation[fit.name].vaf_percent)
                          for fit in validated) - 1), 100.5)
ax.set_ylabel("held-out VAF (%)")
ax.set_title(f"trusted: {comparison.trusted}")
ax.legend(loc="lower left", fontsize=8)
fig.tight_layout()
plt.show()
