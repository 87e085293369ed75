"""``faultgen monitor``: a fleet's measured logs in, alarms and the worn axis out (faultgen.monitor)."""

from __future__ import annotations

import functools
import os
import sys
from pathlib import Path
from typing import Annotated

import typer

from faultgen.cli.base import Command
from faultgen.cli.main import app
from faultgen.cli.options import (
    Backend, Jobs, LogFormat, MonitorScheduler, Progress, TorqueConstants, log_adapter, warn_jobs,
)

#: What a monitor's output folder holds in its cache (OUT/.cache): simulated cycles, calibrations,
#: the twins' filtered program logs (faultgen.monitor.twin).

#: The fewest logs the monitor learns a unit from, and the most logs --train and --persistence may
#: name: faultgen.monitor.scoring's MIN_TRAIN and MAX_LOGS (which a settings file read back is
#: checked against), repeated so that the command line's options load without the monitor.
MIN_TRAIN, MAX_LOGS = 10, 100_000


def _output_folder(value: Path) -> Path:
    """``--out``: a folder, or a path where one can be made; an existing file is refused before
    any log is read (typer callback)."""
    if value is not None and (value.exists() or value.is_symlink()) and not value.is_dir():
        raise typer.BadParameter(f"{value} exists and is not a folder; OUT is the monitor's output folder "
                                 "(give a new or an earlier run's folder)")
    return value


@app.command("monitor", cls=Command)
def monitor_command(
    logs: Annotated[Path, typer.Argument(help="Fleet folder: LOGS/<unit>/<stamp>.csv (or .csv.gz, .h5).")],
    robot: Annotated[str, typer.Option(help="Robot the logs were recorded on: name, robot folder or MJCF file.")],
    out: Annotated[Path, typer.Option("--out", "-o", callback=_output_folder, help="Output folder: report.html, "
                                      "units.csv, alarms.csv, scores.csv, <unit>.png. An earlier run's folder is "
                                      "continued: only new logs are scored. Another folder that holds files is "
                                      "refused unless --overwrite.")],
    calibrated: Annotated[Path | None, typer.Option(
        help="A `faultgen calibrate` output folder whose model every unit's twin uses (default: each unit's "
             "model calibrated on its first log).")] = None,
    calibrate: Annotated[bool, typer.Option(
        help="Calibrate each unit's model on its first log; --no-calibrate: the nominal model.")] = True,
    protocol: Annotated[str, typer.Option(
        help="twin: residuals against the unit's twin, isolation by wear signatures; own: the features "
             "themselves, isolation by each axis's reconstruction-based contribution to Q (no model).")] = "twin",
    train: Annotated[int, typer.Option(help="Logs of each unit's normal operation the monitor learns from.",
                                       min=MIN_TRAIN, max=MAX_LOGS)] = 28,
    alpha: Annotated[float, typer.Option(help="Significance level of the T2 and Q limits, below 0.5.",
                                         min=1e-9, max=0.499)] = 0.01,
    persistence: Annotated[int, typer.Option(help="Consecutive logs over a limit that make an alarm.",
                                             min=1, max=MAX_LOGS)] = 5,
    wear_limit: Annotated[float, typer.Option(
        help="With the twin: the wear (% increase of an axis's dry friction, in % of the unit's own: its "
             "calibrated or nominal model's) the lower one-sided 90 % bound of the wear filtered up to a log must "
             "reach for the log to alarm. OUT/wear.csv gives it with its 90 % interval and each log's own estimate. "
             "Default 8: the lower edge of the 8-15 % window a first alarm should fall in; the bound lies below the "
             "true wear, so alarms come at or above the limit (docs/analysis.md, \"Issue 90: 8 % the default\").",
        min=0.001, max=1000.0)] = 8.0,
    failure_wear: Annotated[float, typer.Option(
        help="With the twin: the wear estimate (% of the axis's own dry friction) that ends an axis's life; OUT/rul.csv gives "
             "each axis's remaining life until it, with a 5-95 % interval.", min=1.0, max=500.0)] = 40.0,
    hours_per_day: Annotated[float, typer.Option(
        help="Operating hours per calendar day between a unit's logs (a log records minutes of its work): "
             "OUT/life.csv's rated-life consumption between logs.", min=0.1, max=24.0)] = 16.0,
    scale_prior: Annotated[Path | None, typer.Option(
        help="The output folder of another monitor run on the same robot whose friction tests saw some "
             "units' wear: the factor that puts the twin's wear on the tests' scale is learned there (a "
             "normal prediction over its units' factors) and is this run's prior in place of 1 +- 0.3, so that an "
             "alarm before a test sees the wear can come nearer the limit; not OUT itself (docs/analysis.md, "
             "\"Issue 90: a fleet's scale prior\").")] = None,
    log_format: LogFormat = "measured",
    torque_constants: TorqueConstants = None,
    jobs: Jobs = 1,
    scheduler: MonitorScheduler = None,
    stepper: Backend = None,
    twin_temperature: Annotated[bool, typer.Option(
        help="Let the twin's temperature law predict the seasonal change too (default: the unit's learned "
             "slope alone).")] = False,
    overwrite: Annotated[bool, typer.Option(
        "--overwrite", help="Write into a folder that holds files but is not an earlier monitor run's output, "
        "replacing its files of the outputs' names; without it such a folder is refused.")] = False,
    progress: Progress = True,
) -> None:
    """Monitor your own robots: learn each unit's normal operation from its first logs against its
    twin, score every later log, and name the worn axis.

    For each unit (a folder of LOGS, logs in stamp order; columns t, q1..qN rad, tau1..tauN N m at
    the arm side, optional temperature1..N deg C and payload kg): (a) its model is calibrated on its
    first log (`faultgen calibrate`, cached in OUT/.cache), or --calibrated's is used; (b) the model
    replays the unit's first log, healthy at every payload the logs declare and with each axis in
    turn worn (40 %, thesis eq. 6.6's schedule at its end); (c) on the first --train logs the monitor
    learns the residual's offset, temperature slope and noise and fits a PCA monitor (T2 and Q,
    thesis eq. 2.3-2.6); (d) every later log is scored, its residual standardised by the
    regression's prediction interval (wider the further its temperature and payload lie outside
    those the learning logs saw), and each axis's wear estimated along its wear signature (weighted
    least squares, with a standard error) and filtered over the logs (a local linear trend). With
    the twin a log alarms when the lower 90 % bound of the largest filtered wear reaches
    --wear-limit %; without it (--protocol own) when T2
    or Q is over its limit. A unit alarms from the first of --persistence consecutive alarming
    logs, or at once on one log far past (the twin: the bound past the limit by its own width;
    own: T2 or Q past its limit at alpha^persistence); its source axis is the one with the largest wear estimate (own: the largest
    reconstruction-based contribution to Q, Alcala and Qin 2009).

    No unit stops the fleet: a unit whose twin cannot be built falls back (its calibrated model,
    then its own friction on the nominal model, then the nominal model, then --protocol own), and
    a log that cannot be read or replayed is skipped; OUT/units.csv gives every unit's status
    (monitored, learning, degraded, not monitored), protocol, model and the reason. A unit whose
    first log `faultgen calibrate` would refuse (torque logged motor-side, another robot's log) is
    not monitored, with that message, never against a fallback model; a file in a unit folder that
    is not a log is passed over and named; a bad row of events.csv stops its unit only, the row
    named. Exit status: 0 when every unit is monitored or
    still learning, 3 when some unit is degraded or not monitored (every output still written),
    2 when the run is refused before any work (bad option, robot, folder or OUT). OUT must lie apart
    from LOGS (neither inside it nor holding it); a run that fails leaves no OUT it made.

    Logs in another layout: --format ur-rtde (Universal Robots' RTDE recorder; joint temperatures
    kept; the torque is the measured actual current times --torque-constants, or else the commanded
    target moment, which cannot show wear: units.csv's torque_source says which, and a unit whose
    torque does not vary from log to log is not monitored) or --format voraus, as `faultgen logs
    import` reads them. A unit whose twin fell back to the nominal model has its wear in the nominal
    model's scale: units.csv's and wear.csv's wear_scale say "nominal model".

    A repair or gearbox_change in LOGS/events.csv closes the unit's open alarm (alarms.csv keeps it,
    with closed and closed_by) and the unit learns its offset again from the next logs; a log whose
    motion left the twin's program (a program change nobody logged: its cycles match neither the
    program's cycle nor a whole number of them, at any sample rate; its cycle column, else the
    program's period, tells them) rebuilds the twin on it and the unit learns again, said in units.csv.

    Units in parallel: --jobs N local processes (at most one per unit; a warning above the CPU
    cores), or --scheduler tcp://HOST:PORT, a Dask cluster whose
    workers share no folder with this machine (the units' logs and cached twins are sent, their
    results come back and are written here); either way the outputs are those of --jobs 1, bit for
    bit.

    Writes OUT/units.csv, OUT/alarms.csv (unit, first_alarm, known: the log the alarm became known on,
    source_axis, statistic, limit, evidence, closed, closed_by),
    OUT/scores.csv (per unit and log: Q, T2, their limits, the axis ranking and scores),
    OUT/wear.csv (per unit, log and axis, with the twin: the wear estimate, % of the axis's own dry
    friction, with its 90 % interval that carries the twin's model uncertainty; with friction tests
    the factor onto their scale, scale_factor, which another run's --scale-prior learns from),
    OUT/rul.csv (per unit and axis, with the twin: the remaining life until the wear estimate reaches
    --failure-wear, in days or logs, with a 5-95 % interval and the trend model, or "no end of life
    within the horizon"), OUT/life.csv (per unit and axis: the % of its gearbox's rated life the
    load consumed since the last gearbox_change, from each log's arm-side torque and speed with
    the makers' rated-life formula and the robot's gearbox ratings, `faultgen robots ROBOT`; the
    duty in % per day and the days left to 100 %), OUT/<unit>.png (control chart, alarm, axis scores) and OUT/report.html
    (the fleet report: a page for a browser, offline, with every unit's status, alarm, evidence and
    chart; its settings in OUT/settings.json; `faultgen report OUT` writes it again), all together;
    a rerun after new logs arrived scores only those. Method and its check on an independent fleet:
    docs/analysis.md.

    The twin is the default: `faultgen monitor LOGS --robot ROBOT -o OUT`, with LOGS the folder of
    your robots' logs (`faultgen logs import --help`) and ROBOT the model they come from (its
    calibration refuses logs the model cannot have made). Without a model, each unit against its
    own first logs only:

    \b
      faultgen monitor LOGS --robot irb6700 -o monitor-own --protocol own
    """
    from faultgen.monitor import console, loop
    from faultgen.monitor.run import resolve_run
    from faultgen.monitor.scoring import Settings
    from faultgen.runs.context import ExecutionContext

    settings = Settings(protocol=protocol, train=train, alpha=alpha, persistence=persistence, wear_limit=wear_limit)
    check_monitor_out(out, logs, overwrite)
    if scheduler is None:  # at most one worker per unit is started (faultgen.monitor.parallel.map_groups)
        warn_jobs(jobs, "the units", "400-600 MB")
    made = missing_folders(out / ".cache")  # what the run creates first: OUT/.cache, OUT and folders above it when new
    try:
        # the run resolved once, the robot loaded there (--torque-constants checked against its axes)
        run = resolve_run(robot, logs, out, calibrated=calibrated, calibrate=calibrate, settings=settings,
                          twin_temperature=twin_temperature, progress=progress,
                          log_format=functools.partial(log_adapter, log_format, torque_constants),
                          context=ExecutionContext(jobs, scheduler, stepper), failure_wear=failure_wear,
                          hours_per_day=hours_per_day, scale_prior=scale_prior)
        if run.scale_prior is not None:
            typer.echo(run.scale_prior.note())
        outcome = loop.monitor(run)
    except loop.MonitorInterrupted as stopped:  # Ctrl-C, SIGTERM: OUT/.cache keeps the twins made so far
        typer.echo(str(stopped), err=True)
        # ended here, at once: nothing is left to write, and the interpreter's own end (collecting the
        # objects of MuJoCo, SciPy, matplotlib) takes 2-2.5 s more on 2 loaded cores
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(stopped.exit_code)
    except Exception:  # a refusal or a failure: nothing this run made is left (OUT, OUT/.cache, empty folders above)
        remove_made(made, out)
        raise
    lines, short = console.summary(outcome, settings, out)
    for line in lines:
        typer.echo(line)
    if short:
        typer.echo(short, err=True)
        raise typer.Exit(loop.EXIT_SOME_UNITS_NOT_MONITORED)


def is_monitor_output(folder: Path) -> bool:
    """Whether ``folder`` is an earlier monitor run's output: it holds the monitors' state
    (``.state``), or the cache a run killed before its first outputs leaves (``.cache`` holding
    nothing but :data:`faultgen.monitor.state.CACHE`)."""
    from faultgen.monitor import state as stored

    state, cache = folder / ".state", folder / ".cache"
    if state.is_dir() and not state.is_symlink():
        return True
    if not cache.is_dir() or cache.is_symlink():
        return False
    return all(entry.name in stored.CACHE for entry in cache.iterdir())


def check_monitor_out(out: Path, logs: Path, overwrite: bool) -> None:
    """Refuse, before any work, an OUT that is LOGS, lies inside it or holds it
    (:func:`faultgen.data.atomic.check_apart`), is a file, or is a folder holding files that is
    not an earlier monitor run's output (:func:`is_monitor_output`: continued) unless ``overwrite``;
    a folder holding only a ``lost+found`` folder (an ext4 mount point) counts as empty.

    Raises
    ------
    ValueError
        Naming OUT (and LOGS) and what to do.
    """
    from faultgen.data import atomic

    atomic.check_apart(out, logs)
    if (out.exists() or out.is_symlink()) and not out.is_dir():
        raise ValueError(f"{out} is a file; --out expects a folder to write the results into")
    # an ext4 mount's lost+found (made by mkfs, not by a user) leaves a mount point empty
    held = out.is_dir() and any(e.name != "lost+found" or not e.is_dir() or e.is_symlink() for e in out.iterdir())
    if held and not is_monitor_output(out) and not overwrite:
        raise ValueError(f"{out} holds files and is not an earlier monitor run's output (no {out / '.state'}); pass "
                         "--overwrite to write into it (replacing its files of the outputs' names) or choose another "
                         "--out")


def missing_folders(path: Path) -> list[Path]:
    """``path`` and the folders above it that do not exist now, innermost first (absolute): those a
    run that creates ``path`` with its parents makes; empty when ``path`` exists."""
    path = path.absolute()
    missing = []
    while not (path.exists() or path.is_symlink()) and path.parent != path:
        missing.append(path)
        path = path.parent
    return missing


def remove_made(made: list[Path], out: Path) -> None:
    """Remove what a failed run made (:func:`missing_folders` before the run): OUT with all it holds
    when the run made it, else the OUT/.cache it made; then each new folder above OUT, innermost
    first, only while it is empty. A folder above OUT may hold another run's output by now (two
    runs into new folders under one new parent): it is kept, and so is everything in it. Nothing
    that existed before the run is touched."""
    import shutil

    out = out.absolute()
    for folder in made:
        if folder == out or out in folder.parents:  # the run's own: OUT/.cache, OUT
            if folder.is_dir() and not folder.is_symlink():
                shutil.rmtree(folder, ignore_errors=True)
            continue
        try:
            folder.rmdir()  # fails on a folder that holds anything
        except OSError:
            return
