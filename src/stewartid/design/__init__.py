"""Excitation design: limits, candidate trajectories, predicted accuracy, optimisation,
export of command files and the design report (``stewartid design``)."""
