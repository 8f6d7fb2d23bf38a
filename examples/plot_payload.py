"""
A payload's mass, centre of mass and inertia from the logs
==========================================================

A 2 t cabin is bolted onto the paper's platform, its centre of mass off the reference point
and its axes not the platform's. The platform file describes the bare platform; the physical
model in payload mode (``stewartid identify --model physical --payload``) takes all of it as
known and identifies the payload alone from the logged pose and leg forces: its mass, first
moment and inertia about the reference point (ten parameters, linear in the forces), with the
joint friction and the force-sensor offsets as nuisance parameters. Six short records move
every degree of freedom at once, each at its own frequency, with the reference sensor noise.
"""

import matplotlib.pyplot as plt
import numpy as np

import stewartid as sid
from stewartid.simulation import DEFAULT_AMPLITUDES, Sine, multisine_excitation, simulate_experiment

bare = sid.load_platform("paper")
cabin = {"mass": 2000.0, "com": [-0.20, 0.30, -0.50],
         "inertia": [1800.0, 2200.0, 2600.0, -120.0, 80.0, 160.0]}
loaded = bare.replace(**{f"payload__{key}": value for key, value in cabin.items()})
#: Ixx, Iyy, Izz, Ixy, Ixz, Iyz: entries (row, column) of the 3 x 3 inertia matrix.
ENTRIES = ([0, 1, 2, 0, 0, 1], [0, 1, 2, 1, 2, 2])


def parallel_axis(mass, c):
    """What moving the inertia from the centre of mass ``c`` to the reference point adds,
    m (c.c 1 - c c^T), as Ixx, Iyy, Izz, Ixy, Ixz, Iyz (the parallel-axis theorem)."""
    return (mass * (c @ c * np.eye(3) - np.outer(c, c)))[ENTRIES]


def about_reference(mass, com, inertia):
    """The ten parameters (m, first moment m c, inertia about the reference point) of the
    ``[payload]`` keys."""
    c = np.asarray(com)
    return np.concatenate([[mass], mass * c, np.asarray(inertia) + parallel_axis(mass, c)])


def keys(body):
    """The ``[payload]`` keys of the ten parameters, flat: mass, com (3), inertia about the
    centre of mass (6)."""
    m, c = body[0], body[1:4] / body[0]
    return np.concatenate([[m], c, body[4:] - parallel_axis(m, c)])


# %%
# The plant carries the payload. Record k moves degree of freedom d at frequency
# ``hz[(d + k) % 6]``, so that every record excites translation and rotation together and
# the six records differ; 2 s fade in, then 4 s of full motion.
hz = (0.3, 0.45, 0.6, 0.75, 0.9, 1.05)
noise = sid.reference_noise(loaded)
datasets = []
for k in range(6):
    sines = [Sine(d, 0.7 * DEFAULT_AMPLITUDES[d], hz[(d + k) % 6], 0.5 * d + k)
             for d in range(6)]
    excitation = multisine_excitation(loaded, sines, name=f"exp{k + 1}")
    datasets.append(simulate_experiment(loaded, excitation, 6.0, noise=noise,
                                        rng=np.random.default_rng(k))[0])
print(f"6 records of {datasets[0].t[-1]:.1f} s, force noise {noise.force_noise:.0f} N per leg")

# %%
# Payload mode is fitted on the *bare* description. Its ten parameters are the moving body's
# mass, first moment and inertia about the reference point less the platform's own; the
# ``[payload]`` keys (mass, centre of mass, inertia about it) follow from them, their standard
# errors by the delta method (a central difference of the map, which is smooth for m > 0).
fitted = sid.create_identifier("physical", payload=True).fit(datasets, bare)
names = [name for name in fitted.parameters_ if name.startswith("payload.")]
truth = about_reference(**cabin)
found = np.array([fitted.parameters_[name] for name in names])
error = np.array([fitted.parameter_std_errors_[name] for name in names])
print("fixed (not excited):", list(fitted.fixed_) or "none")
print(f"{'parameter':14s} {'true':>10s} {'identified':>11s} {'std error':>10s}")
for name, t, v, s in zip(names, truth, found, error, strict=True):
    print(f"{name:14s} {t:10.2f} {v:11.2f} {s:10.2f}")

covariance = fitted.covariance_[:10, :10]  # the payload's parameters come first
steps = 1e-6 * np.maximum(np.abs(found), 1.0)
jacobian = np.stack([(keys(found + h * e) - keys(found - h * e)) / (2 * h)
                     for h, e in zip(steps, np.eye(10), strict=True)], axis=1)
key_std = np.sqrt(np.diag(jacobian @ covariance @ jacobian.T))
key_true = np.array([cabin["mass"], *cabin["com"], *cabin["inertia"]])
key_found = keys(found)
labels = ["mass (kg)", "com x (m)", "com y (m)", "com z (m)", "Ixx", "Iyy", "Izz", "Ixy", "Ixz",
          "Iyz"]
print(f"\n{'[payload]':14s} {'true':>10s} {'identified':>11s} {'std error':>10s}")
for label, t, v, s in zip(labels, key_true, key_found, key_std, strict=True):
    digits = 4 if "com" in label else 1
    print(f"{label:14s} {t:10.{digits}f} {v:11.{digits}f} {s:10.{digits}f}")

# %%
# Identified over true for every ``[payload]`` key, with two standard errors (1 is exact;
# the inertias in kg m^2 about the payload's centre of mass). The products of inertia are
# known about as well in kg m^2 as the moments, but they are twenty times smaller.
fig, ax = plt.subplots(figsize=(8, 3.5))
ax.errorbar(np.arange(10), key_found / key_true, yerr=2 * key_std / np.abs(key_true), fmt="o")
ax.axhline(1.0, color="0.5", lw=0.8)
ax.set_xticks(range(10), ["mass", "com x", "com y", "com z", "Ixx", "Iyy", "Izz", "Ixy", "Ixz",
                          "Iyz"])
ax.set_ylabel("identified / true")
ax.set_title("The payload from six 6 s records, on the bare platform file")
fig.tight_layout()
plt.show()
