"""Plant simulator after Zhang (2020), Fig. 3: excitation, leg-length PID, hydraulic actuators,
compiled plant dynamics and sensors; :func:`~stewartid.simulation.simulate_experiments` runs the
paper's six experiments.
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
