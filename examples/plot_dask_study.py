"""
A small study on a local Dask cluster
=====================================

``stewartid study`` runs a Monte Carlo study or parameter sweep on dask.distributed: every
(grid point, noise seed) simulates the six experiments and identifies them with every
method, one row per method in ``results.parquet``; finished rows survive an interruption
(``docs/studies.md``). Here two Coulomb friction levels times two noise seeds, on short
records, with threads in this process as the cluster (the ``[dask]`` extra); on a real
cluster the same call takes the cluster's client.
"""

import tempfile

import matplotlib.pyplot as plt
from distributed import Client, LocalCluster

from stewartid.studies import parse_study, run_study

spec = parse_study({
    "study": {"platform": "paper", "methods": ["wavelet", "ls"], "duration": 4.0,
              "seeds": 2, "title": "Coulomb friction, two seeds"},
    "grid": {"coulomb": [0.0, 30.0], "noise_scale": [1.0]},
})
with LocalCluster(n_workers=1, threads_per_worker=2, processes=False,
                  dashboard_address=None) as cluster, Client(cluster) as client:
    run = run_study(spec, tempfile.mkdtemp(), client=client, report=False)
print(f"{run.computed} tasks in {run.runtime_s:.1f} s, {len(run.rows)} rows")
print(run.rows[["coulomb", "seed", "method", "max_error_B_percent"]].to_string(index=False))

# %%
# The largest Bt error of each method against the Coulomb friction, every seed a point.
fig, ax = plt.subplots(figsize=(6, 3.5))
for method, rows in run.rows.groupby("method"):
    ax.plot(rows["coulomb"], rows["max_error_B_percent"], "o", label=method, alpha=0.8)
    ax.plot(*zip(*rows.groupby("coulomb")["max_error_B_percent"].mean().items(), strict=True),
            "-", color=ax.lines[-1].get_color())
ax.set_xlabel("Coulomb friction per joint axis (N m)")
ax.set_ylabel("largest Bt error (%)")
ax.legend()
fig.tight_layout()
plt.show()
