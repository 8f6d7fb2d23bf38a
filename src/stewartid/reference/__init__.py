"""Reference data: the published results of Zhang (2020)."""
