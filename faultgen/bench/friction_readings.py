"""The friction tests of a fleet's unit as benchmark arrays (the prognostics track's version 2,
docs/bench/prognostics.md): each test log read as ``faultgen friction-test`` reads one
(:func:`faultgen.calibrate.friction_report.read`: constant-speed segments found, direction
differencing, each axis's friction curve fitted with 95 % intervals; docs/friction-test.md), and its
reading put on the record of the test's day (:data:`faultgen.bench.files.TEST_ARRAYS`), so that a
prognoser shown a unit's records up to a day sees the tests up to that day and no later one. The
tests' truth (``truth_tests.csv``) is never read here.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

#: A reading's columns (friction_fit.csv's, arm side) -> the benchmark array holding them.
COLUMNS = {"coulomb_Nm": "friction_test_coulomb", "coulomb_Nm_low": "friction_test_coulomb_low",
           "coulomb_Nm_high": "friction_test_coulomb_high", "viscous_Nms_rad": "friction_test_viscous",
           "temperature_degC": "friction_test_temperature"}


def arrays(tests: Path, stamps: list[str], robot) -> dict[str, np.ndarray]:
    """The readings of the tests ``tests/<stamp>.csv`` of one unit whose records are the logs ``stamps``
    (in record order), ``robot`` a :class:`faultgen.model.robot.Robot`: ``friction_test`` (n,) int8, 1
    on a test's day, and each of :data:`COLUMNS`' arrays (n, N), float64, the axis's reading on that
    day, 0 elsewhere (and on an axis the test did not read).

    Raises
    ------
    ValueError
        A test whose stamp is none of ``stamps`` (naming it), or one that cannot be read (as
        :func:`faultgen.calibrate.friction_test.friction_points`).
    """
    from faultgen.calibrate import friction_report
    from faultgen.logs import measured

    n, n_axes = len(stamps), robot.n_axes
    out = {"friction_test": np.zeros(n, dtype=np.int8),
           **{name: np.zeros((n, n_axes)) for name in COLUMNS.values()}}
    row_of = {stamp: k for k, stamp in enumerate(stamps)}
    for path in sorted(Path(tests).glob("*.csv")):
        if path.stem not in row_of:
            raise ValueError(f"{path}: a friction test on {path.stem}, a day with no log of its unit")
        k = row_of[path.stem]
        fits = friction_report.read(measured.read(path, robot, accelerations=False), robot).fits
        out["friction_test"][k] = 1
        for _, fit in fits.iterrows():
            for column, name in COLUMNS.items():
                out[name][k, int(fit["axis"]) - 1] = float(fit[column])
    return out
