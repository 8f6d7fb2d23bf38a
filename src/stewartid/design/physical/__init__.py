"""Excitation design for the physical model: all-DOF multisines chosen by the predicted
standard errors of its parameters, played on the plant and checked.
"""
