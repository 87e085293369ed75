"""A friction test's records read back as logs: a run labelled a friction test
(:data:`faultgen.data.schema.RECORD_ATTRIBUTE`; in a fleet, a robot's tests,
``faultgen fleet --friction-test-every``) holds one recorded cycle per test with its 250 Hz signals;
:func:`log` makes one of them the measured log that ``faultgen friction-test`` reads
(:func:`faultgen.calibrate.friction_report.read`), :func:`write` writes it as a CSV file.

The log: ``t`` (s), ``q`` the encoder's arm angle ``q_a`` (rad), ``tau`` the motor torque through the
gear ratio, ``tau_m G`` (N m, arm side, as a controller logs it), and the cycle's joint temperature
(deg C, when the run has the thermal condition) on every sample.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from faultgen.data import atomic, cells
from faultgen.logs import measured
from faultgen.data.reader import Run
from faultgen.logs.columns import temperature_columns


def _columns(run: Run, index: int) -> dict[str, np.ndarray]:
    if not run.friction_test:
        raise ValueError(f"run {run.id!r} is not a friction test (no record = 'friction_test' label)")
    cycles = run.recorded
    if not isinstance(index, int) or not 0 <= index < len(cycles):
        raise ValueError(f"test {index!r} of run {run.id!r}: expected 0..{len(cycles) - 1} ({len(cycles)} tests)")
    gear = np.asarray(run.drivetrain.gear_ratio, dtype=float)
    t = np.asarray(run.array("t"), dtype=float)
    q, tau = run.signal("q_a")[index].astype(float), run.signal("tau_m")[index].astype(float) * gear
    names = temperature_columns(q.shape[1])
    columns = {"t": t, **{f"q{k + 1}": q[:, k] for k in range(q.shape[1])},
               **{f"tau{k + 1}": tau[:, k] for k in range(q.shape[1])}}
    if run.has("joint_temperature"):
        temperature = np.asarray(run.array("joint_temperature"), dtype=float)[index]
        columns.update({name: np.full(len(t), temperature[k]) for k, name in enumerate(names)})
    return columns


def log(run: Run, index: int, robot) -> measured.MeasuredData:
    """Test ``index`` (0-based, in :attr:`Run.recorded` order) of the friction-test ``run`` as a
    measured log of ``robot`` (module docstring), checked as a file would be.

    Raises
    ------
    ValueError
        For a run that is not a friction test or an index out of range (named), or a log that does
        not check (:class:`faultgen.logs.measured.MeasuredDataError`).
    """
    return measured.from_columns(_columns(run, index), robot, f"{run.id} test {index + 1}", accelerations=False)


def write(run: Run, index: int, path: str | Path) -> Path:
    """Test ``index`` of ``run`` written as a measured-format CSV (``t, q1..qN, tau1..tauN[,
    temperature1..N]``) at ``path``, atomically (a killed write leaves no partial file), the file
    ``faultgen friction-test`` reads; raises as :func:`log`."""
    import pandas as pd

    path = Path(path)
    atomic.write_text(path, cells.escaped(pd.DataFrame(_columns(run, index))).to_csv(index=False))
    return path
