"""Logged or simulated experiments: the :class:`Dataset` type, the interchange format and a
controller's own logs through a column mapping (:class:`LogFormat`), and the physical checks
that catch data inconsistent with the platform description."""

from stewartid.datasets._experiments import read_experiments
from stewartid.datasets.dataset import Dataset, read_dataset, read_datasets
from stewartid.datasets.log_format import LogFormat, load_log_format

__all__ = ["Dataset", "LogFormat", "load_log_format", "read_dataset", "read_datasets",
           "read_experiments"]
