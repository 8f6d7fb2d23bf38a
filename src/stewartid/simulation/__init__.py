"""Plant simulator: hydraulic hexapod under leg-length PID control, sensors, data sets.

The five blocks of the paper's Simulink model (Zhang 2020, Fig. 3): signal generator
(:mod:`.excitation`), inverse motion and PID (:mod:`.controller`), hydraulic actuators
(:mod:`.hydraulics`), plant dynamics (:mod:`.plant`, compiled closed loop) and forward
solution (:mod:`.sensors`). :func:`simulate_experiments` runs the paper's six experiments.
A real rig's sensor imperfections (channel delays, filtered noise, mains hum, drift:
:mod:`.imperfections`) are part of :class:`SensorNoise`; :func:`degrade` applies them to any
data set.
"""

from stewartid.simulation.excitation import (
    DEFAULT_AMPLITUDES,
    Excitation,
    Sine,
    multisine_excitation,
    paper_experiments,
    sine_excitation,
)
from stewartid.simulation.experiments import (
    ExperimentRecord,
    SimulationResult,
    simulate_experiment,
    simulate_experiments,
    write_experiments,
)
from stewartid.simulation.sensors import SensorNoise, degrade

__all__ = [
    "DEFAULT_AMPLITUDES",
    "Excitation",
    "ExperimentRecord",
    "SensorNoise",
    "SimulationResult",
    "Sine",
    "degrade",
    "multisine_excitation",
    "paper_experiments",
    "simulate_experiment",
    "simulate_experiments",
    "sine_excitation",
    "write_experiments",
]
