"""Logged or simulated experiments: the :class:`~stewartid.datasets.dataset.Dataset` type, the
file formats (:mod:`~stewartid.datasets.dataset`, a controller's own log through a column
mapping in :mod:`~stewartid.datasets.log_format`) and the physical checks that catch data
inconsistent with the platform description (:mod:`~stewartid.datasets.plausibility`).
"""
