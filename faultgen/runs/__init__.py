"""Grids of runs: sweeps and their presets, executed in parallel into one dataset (``sweep``).
Above ``data``."""
