"""Sim-vs-measured calibration: find where the model and a robot's torque log disagree, name the
missing physical effect, add it to the model, and show the gap shrink.

The workflow (:func:`calibrate`, ``faultgen calibrate``):

1. read and check the measured file (:func:`faultgen.logs.measured.read`; velocities and
   accelerations from a Savitzky-Golay filter when the file has none), and refuse a log the robot
   cannot explain (:mod:`faultgen.calibrate.plausibility`) before writing anything;
2. predict the torque with the nominal model (:func:`predict`: the inverse dynamics plus what the
   flexible gearboxes change, :mod:`faultgen.calibrate.gearbox`) and split the record in time into a fitting part and a held-out part
   (:class:`faultgen.calibrate.search.Split`); every gap is reported on the held-out part;
3. fit every effect of the library (:mod:`faultgen.effects`) to the residual and pick
   the one that explains it best by its held-out information criterion; when the log cannot tell
   two effects apart, fit the simpler and say so, with both candidates' evidence and the motion
   that would separate them (:mod:`faultgen.calibrate.search`, :meth:`Calibration.ambiguous`);
4. add it to the model (an MJCF spec compiled in memory, :mod:`faultgen.calibrate.trial`),
   recompute the residual with the augmented model, search every axis still above its noise floor
   again for the effects already named (:func:`faultgen.calibrate.improve.complete`), and repeat
   until no effect is significant; with two or more effects, fit each again with the others in
   place (backfitting, :func:`faultgen.calibrate.improve.backfit`);
5. write the augmented model (once: no trial touches the disk), ``report.json`` (design document
   contract) and a figure.

The modules by job: :mod:`~faultgen.calibrate.loop` (the workflow), :mod:`~faultgen.calibrate.improve`
(the passes after the forward search), :mod:`~faultgen.calibrate.trial` (models held in memory),
:mod:`~faultgen.calibrate.result` (steps, the report, ``parameters.json``),
:mod:`~faultgen.calibrate.search` (model selection). This module reads the log and runs the loop
into a folder that appears whole.

docs/calibration.md explains the method and lists its accuracy on hidden-effect data.
"""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import numpy as np

from faultgen import axes
from faultgen.calibrate import search, user_effects
from faultgen.calibrate.effects import EFFECTS, Effect, get
from faultgen.calibrate.residual_tests import LEVEL as RESIDUAL_TEST_LEVEL
from faultgen.calibrate.loop import MAX_STEPS
from faultgen.calibrate.loop import run as _calibrate
from faultgen.calibrate.plausibility import ImplausibleLogError
from faultgen.calibrate.prediction import predict
from faultgen.calibrate.result import Calibration, Step, parameters
from faultgen.data import atomic
from faultgen.logs import formats, longlog
from faultgen.logs import measured as measured_io
from faultgen.logs.blocks import block_mean
from faultgen.model import robots

__all__ = ["EFFECTS", "RESIDUAL_TEST_LEVEL", "Calibration", "Effect", "ImplausibleLogError", "Step", "calibrate", "get",
           "parameters", "predict"]


#: Most rows the search works on. A longer log is averaged down to this many (:func:`decimate`):
#: the search's regressors take about 28 kB per row (a 10^6-row log asked for 25.7 GiB), so
#: 25 000 rows keep ``faultgen calibrate`` within 3 GB (60 000 took 5.7 GB; docs/calibration.md, "Long logs").
MAX_ROWS = 25_000


def calibrate(robot: str | Path | robots.Robot, measured: str | Path | measured_io.MeasuredData, out: str | Path,
              max_steps: int = MAX_STEPS, progress: bool = False, use_sysid: bool = True,
              log_format: formats.LogFormat = formats.MEASURED, friction_every_axis: bool = False, figure: bool = True,
              delay: str | float | None = None, effects: list[str] | None = None,
              tests: bool = True) -> Calibration:
    """:func:`faultgen.calibrate.loop.run` into a hidden folder beside ``out``, renamed to ``out`` once every output
    is written (:func:`faultgen.data.atomic.atomic_folder`): a failed, refused or interrupted run
    leaves nothing at ``out`` (an existing ``out`` untouched) and nothing that blocks a rerun. A
    log longer than :data:`MAX_ROWS` rows is first averaged down to that many (:func:`decimate`),
    so memory stays bounded whatever the log's length. A log on which no joint moves is refused
    (:class:`ImplausibleLogError`, naming the joints and how little they move). ``use_sysid``: a
    Stribeck hump's parameters refined by ``mujoco.sysid`` when it is installed (:func:`faultgen.calibrate.loop.run`).
    ``robot``: the nominal model, a :class:`~faultgen.model.robot.Robot` or a name, robot folder or MJCF
    file resolved here, once (:func:`faultgen.model.robots.load`; UnknownRobotError, ModelError).
    ``log_format``: the log's format (a :class:`faultgen.logs.formats.LogFormat`, ``--format NAME``;
    default the measured one): read through it, whole or, longer
    than :data:`MAX_ROWS`, in blocks (:func:`faultgen.logs.longlog.read`).
    ``friction_every_axis``: the dry (Coulomb) and viscous friction levels of every moving axis fitted
    after the search, always (:func:`faultgen.calibrate.loop.own_friction`; ``--fit-friction-all``).
    ``figure``: draw ``calibration.png`` (False: the other outputs only, as ``faultgen monitor`` caches them).
    ``tests``: run the residual tests and explain the unexplained axes (False: the report's
    ``unexplained`` and ``residual_tests`` are null, as ``faultgen monitor`` caches them;
    :func:`faultgen.calibrate.loop.run`).
    ``delay``: the channel delay's correction (None: reported only; "auto": the estimate; a number
    of seconds; :func:`faultgen.calibrate.loop.check_delay`).
    ``effects``: a user's own effect classes, ``module:Class`` or ``path/file.py:Class`` each
    (``--effects``; :mod:`faultgen.calibrate.user_effects`), fitted beside the library's for this
    calibration (UserEffectError, a ValueError, naming the module and class when one is not usable).
    The result holds the calibrated robot as written to ``out`` (:attr:`Calibration.model`)."""
    with user_effects.loaded(effects):  # the library as it was afterwards
        return _calibrate_with(robot, measured, out, max_steps, progress, use_sysid, log_format,
                               friction_every_axis, figure, delay, tests)


def _calibrate_with(robot, measured, out, max_steps, progress, use_sysid, log_format, friction_every_axis, figure,
                    delay, tests) -> Calibration:
    nominal = robot if isinstance(robot, robots.Robot) else robots.load(robot)  # a boundary: once
    if isinstance(measured, measured_io.MeasuredData):
        data, moves = measured, longlog.motion(measured.qd, search.REST_SPEED)
    else:
        if progress:
            print(f"reading {measured}", flush=True)
        # a log longer than MAX_ROWS is averaged down while it is read: memory flat in its length
        data, moves = longlog.read(measured, nominal, MAX_ROWS, search.REST_SPEED, log_format)
        if progress and moves.rows > len(data):
            print(data.notes[-1], flush=True)
    _check_motion(data.source, moves)
    if len(data) > MAX_ROWS:
        data = decimate(data, MAX_ROWS)
        if progress:
            print(data.notes[-1], flush=True)
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    with atomic.atomic_folder(out) as staging:
        result = _calibrate(nominal, data, staging, max_steps=max_steps, progress=progress, use_sysid=use_sysid,
                             friction_every_axis=friction_every_axis, figure=figure, delay=delay, tests=tests)
        result = replace(result, model_out=out / result.model_out.relative_to(staging))
        atomic.write_text(staging / "report.json", json.dumps(result.report(), indent=2) + "\n")
    return replace(result, model=robots.moved(result.model, result.model_out))  # the folder renamed into place


def decimate(data: measured_io.MeasuredData, rows: int) -> measured_io.MeasuredData:
    """A long log reduced to at most ``rows`` rows: every column averaged over blocks of ``k`` =
    ceil(n / rows) consecutive samples (one filter for the angles, speeds, accelerations and
    torques alike, so a relation linear in them holds between the averages as between the
    samples), one row per block. The velocities and accelerations were estimated at the full rate
    before. Cost: sign changes of the speed (Coulomb friction) and ripple faster than k samples
    (cogging) are smoothed over a block; the torque noise averages down by sqrt(k), but the fit has
    k times fewer rows, so parameter standard errors are about those of the whole log.
    """
    n = len(data)
    k = -(-n // rows)
    if k <= 1:
        return data
    m = n // k

    def blocks(a: np.ndarray) -> np.ndarray:
        return block_mean(a, k, m)

    note = longlog.decimation_note(n, k, m, MAX_ROWS)
    return measured_io.MeasuredData(t=blocks(data.t), q=blocks(data.q), qd=blocks(data.qd), qdd=blocks(data.qdd),
                                    tau=blocks(data.tau), source=data.source,
                                    velocity_estimated=data.velocity_estimated, robot=data.robot,
                                    notes=(*data.notes, note))


#: Fewest samples at which a joint must move (|qd| >= REST_SPEED) for the log to calibrate anything.
MIN_MOVING = 100


def _check_motion(source: Path, moves: longlog.Motion) -> None:
    """Refuse a log on which no joint moves: nothing can be identified (raises ImplausibleLogError
    naming each joint's largest speed). ``moves``: the log's speeds at its full rate."""
    moving, peak = moves.moving, moves.peak
    if np.all(moving < MIN_MOVING):
        joints = ", ".join(f"{a} (largest |qd| {v:.2g} rad/s)" for a, v in zip(axes.numbers(range(len(moving))), peak))
        raise ImplausibleLogError(
            f"{source}: no joint moves: joints {joints} stay below {search.REST_SPEED:g} rad/s in all but "
            f"{int(np.max(moving))} of {moves.rows} samples (at least {MIN_MOVING} needed); give a log in which the "
            "robot moves (an excitation or a task program)")
