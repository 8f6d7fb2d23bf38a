"""
An electric hexapod: currents, reflected mass and screw friction
================================================================

Six servo motors on ball screws carry a 400 kg platform (``src/stewartid/data/electric.toml``).
There is no force sensor: the drives log motor currents, and the leg force is the current times
the force constant. Each leg also carries the rotor and screw as a reflected mass along its axis
(30 kg) and the screw's friction along it (200 N s/m, 80 N), both part of the nominal Mt and Bt.
The electric plant plays one 2 Hz sine per degree of freedom, logged at 2 kHz with whole encoder
counts (1 um) and 0.5 % current noise (what ``stewartid simulate --noise`` does); least squares
and the physical model identify them.
"""

from importlib import resources

import matplotlib.pyplot as plt
import numpy as np

import stewartid as sid

with resources.as_file(resources.files("stewartid") / "data/electric.toml") as path:
    platform = sid.load_platform(path)
motor = platform.actuator
print(f"force constant {motor.force_constant:g} N/A, reflected mass {motor.reflected_mass:g} kg, "
      f"screw friction {motor.viscous:g} N s/m and {motor.coulomb:g} N per leg")

# %%
# Six experiments of 2.5 s each (a 0.5 s fade-in, then four periods), every current with 0.5 % of
# its RMS as noise. The records keep the true motor currents beside the logged forces.
run = sid.simulate_experiments(platform, frequency_hz=2.0, duration_s=2.5, fade_in=0.5,
                               noise=sid.SensorNoise(), current_noise=0.005, seed=0)
heave = run.states[2]
print(f"heave: largest current {np.abs(heave.currents).max():.2f} A of {motor.peak_current:g} A, "
      f"largest leg speed {np.abs(heave.length_rates).max():.3f} m/s")

# %%
# Least squares fits the legs' Coulomb friction for an electric platform (one level in N);
# the nominal matrices hold the reflected mass (J^T m_r J in Mt) and the screw's viscous
# friction (J^T c J in Bt). The physical model identifies the three leg parameters directly.
M0, B0 = sid.nominal_matrices(platform)
fitted = sid.create_identifier("ls").fit(run.datasets, platform)
physical = sid.PhysicalIdentifier().fit(run.datasets, platform)
names = ["x", "y", "z", "rx", "ry", "rz"]
print(f"{'':4s} {'Mt nominal':>11s} {'identified':>11s} {'Bt nominal':>11s} {'identified':>11s}")
for k, name in enumerate(names):
    print(f"{name:4s} {M0[k, k]:11.1f} {fitted.M_[k, k]:11.1f} {B0[k, k]:11.1f} "
          f"{fitted.B_[k, k]:11.1f}")
print(f"legs' Coulomb friction (least squares): {fitted.leg_coulomb_:.1f} N "
      f"(true {motor.coulomb:g})")
for name, true in (("reflected_mass", motor.reflected_mass), ("viscous[actuator]", motor.viscous),
                   ("coulomb[actuator]", motor.coulomb)):
    value, error = physical.parameters_[name], physical.parameter_std_errors_[name]
    print(f"physical model: {name} = {value:.2f} +- {error:.2f} (true {true:g})")

# %%
# Where a leg's current goes during the heave experiment: leg 1's force (current times force
# constant, less its mean, the platform's weight) beside the two parts the motor alone adds,
# the reflected mass's inertial force m_r l_ddot and the screw's friction
# c l_dot + Fc sign(l_dot). On this light platform the screw's friction is a large share.
t = heave.t
rate = heave.length_rates[:, 0]
reflected = motor.reflected_mass * np.gradient(rate, t)
friction = motor.viscous * rate + motor.coulomb * np.sign(rate)
force = motor.force_constant * heave.currents[:, 0]
fig, ax = plt.subplots(figsize=(8, 3.5))
ax.plot(t, force - force.mean(), lw=1.0, label="leg force less its mean (k_t i)")
ax.plot(t, friction, lw=1.0, label="screw friction")
ax.plot(t, reflected, lw=1.0, label="reflected mass m_r l_ddot")
ax.set_xlabel("t (s)")
ax.set_ylabel("N")
ax.set_title("Heave at 2 Hz, leg 1")
ax.legend(loc="upper left", fontsize=8)
fig.tight_layout()
plt.show()
