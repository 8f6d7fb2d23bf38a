"""The rigid-body ("physical") model identified from the logs: masses, first moments,
inertias, friction per joint type and sensor offsets, from which Mt and Bt follow at any pose.
"""
