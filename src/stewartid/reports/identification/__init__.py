"""The identification report of ``stewartid identify --report``."""
