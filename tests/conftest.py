"""Test-session set-up.

Each pytest-xdist worker (``-n auto`` in pyproject.toml) keeps numpy's BLAS to one thread: two
workers on two cores, each with a BLAS pool as wide as the machine, contend for the cores
(2026-11-22, three calibration test files on two workers: 118 s with two BLAS threads each,
101 s with one; 161 s in one process).
"""

import os

import numpy  # noqa: F401  (load the BLAS library before limiting it)
from threadpoolctl import threadpool_limits

if os.environ.get("PYTEST_XDIST_WORKER"):
    threadpool_limits(1)
