"""Reference data: the published results of Zhang (2020) as package data
(:mod:`~stewartid.reference.published`)."""
