"""A ``faultgen monitor`` run resolved once (:class:`MonitorRun`, :func:`resolve_run`): the robot and
its gearbox ratings, the given calibrated model, the log format, the settings and what the saved
state is keyed by, checked and loaded in one function from what the command (or a library caller)
names; :func:`faultgen.monitor.loop.monitor` and the stages below it take the record, never a name.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from faultgen.data import atomic
from faultgen.logs import formats
from faultgen.model import robots
from faultgen.model.robot import Robot
from faultgen.monitor import life, prognosis
from faultgen.monitor import logs as fleet_logs
from faultgen.monitor import state as stored
from faultgen.monitor.scale_prior import ScalePrior
from faultgen.monitor.scale_prior import learn as learn_prior
from faultgen.monitor.scoring import Settings
from faultgen.runs.context import LOCAL, ExecutionContext
from faultgen.simulation import backends


@dataclass(frozen=True)
class MonitorRun:
    """A monitor run as :func:`resolve_run` resolved it (frozen; it stays in the process that
    resolved it: its workers get :meth:`faultgen.monitor.feed.Context.of` it)."""

    #: The robot the logs were recorded on, loaded once (:func:`faultgen.model.robots.load`).
    robot: Robot
    #: The robot as the caller named it (name, folder or MJCF): the page's name, the Dask workers' robot.
    named: str | Path
    #: ``LOGS/<unit>/<stamp>.csv``.
    logs: Path
    #: Output folder; an earlier run's output there is continued (its settings must match).
    out: Path
    settings: Settings
    #: The logs' layout (:class:`faultgen.logs.formats.LogFormat`: measured, ``ur-rtde``, ``voraus``).
    log_format: formats.LogFormat
    #: The gearboxes' ratings of :attr:`robot` (:func:`faultgen.monitor.life.ratings_of`).
    ratings: tuple
    #: The ``--calibrated`` model file used as every unit's model (under protocol ``twin``), else None.
    calibrated: Path | None = None
    #: That model, loaded once (None without one).
    given: Robot | None = None
    #: Without a given model: calibrate each unit's model on its first log (True) or use the nominal one.
    calibrate: bool = True
    #: What the twins' model is, as the state and the page say: "nominal", "per-unit" or the given model's SHA-256.
    model_source: str = "nominal"
    #: What a saved state belongs to (:func:`faultgen.monitor.state.settings_digest`).
    digest: dict | None = None
    #: The twin also predicts the temperature's effect (the model's own temperature law).
    twin_temperature: bool = False
    #: Where and on what the units are scored (jobs, a Dask scheduler, the stepper of the twins' cycles).
    context: ExecutionContext = LOCAL
    #: The wear, % of an axis's own dry friction, that ends its life (rul.csv).
    failure_wear: float = prognosis.FAILURE_WEAR
    #: Operating hours per calendar day between logs, in (0, 24] (life.csv).
    hours_per_day: float = life.HOURS_PER_DAY
    progress: bool = True
    #: The friction tests' scale factor's prior learned from another run (``--scale-prior``), or None.
    scale_prior: ScalePrior | None = None

    @property
    def stepper(self) -> backends.Stepper:
        """What steps the twins' cycles: the run's execution context's."""
        return self.context.stepper

    @property
    def n_features(self) -> int:
        """The length of a log's feature vector: :data:`faultgen.monitor.logs.FEATURES` per axis."""
        return len(fleet_logs.FEATURES) * self.robot.n_axes

    @property
    def own_model(self) -> bool:
        """Whether each unit's twin was asked for a model of its own (given or calibrated)."""
        return self.calibrated is not None or self.calibrate

    def new_source(self) -> fleet_logs.Source:
        """The run's log source, holding its robots as resolved here (:class:`faultgen.monitor.logs.Source`)."""
        return fleet_logs.Source(self.robot, self.log_format, self.given)


def resolve_run(robot: str | Path | Robot, logs: str | Path, out: str | Path, *, calibrated: str | Path | None = None,
                calibrate: bool = True, settings: Settings = Settings(), twin_temperature: bool = False,
                progress: bool = True,
                log_format: formats.LogFormat | Callable[[Robot], formats.LogFormat] = formats.MEASURED,
                context: ExecutionContext = LOCAL, failure_wear: float = prognosis.FAILURE_WEAR,
                hours_per_day: float = life.HOURS_PER_DAY,
                scale_prior: str | Path | ScalePrior | None = None) -> MonitorRun:
    """The run of :func:`faultgen.monitor.loop.monitor` resolved, before any work (each argument is
    the :class:`MonitorRun` field of its name; ``robot`` a name, folder or MJCF loaded here once, or
    a Robot the caller resolved; ``log_format`` a format, or what makes it from the robot, as the
    command line's ``--torque-constants`` are checked against its axes; ``scale_prior`` a ScalePrior or
    the output folder of another run to learn it from, :func:`faultgen.monitor.scale_prior.learn`).

    Raises
    ------
    ValueError
        ``context`` not an ExecutionContext or with ``jobs`` > 1 and a ``scheduler``; ``out`` that
        is, lies in or holds ``logs`` (:func:`faultgen.data.atomic.check_apart`); ``failure_wear``
        or ``hours_per_day`` out of range; a ``scale_prior`` folder that is ``out`` or that it cannot be
        learned from; the robot, a bad gearbox rating in its ``drivetrain.toml``
        (:mod:`faultgen.model.rating`), the log format; a ``calibrated`` model that does not load.
    faultgen.runs.errors.SweepRefused
        The ``scheduler`` is malformed or no Dask scheduler answers there.
    """
    _check_context(context)
    atomic.check_apart(out, logs)
    prognosis.check_failure_wear(failure_wear)
    nominal = robot if isinstance(robot, Robot) else robots.load(robot)
    ratings = life.ratings_of(nominal)  # a bad rating refused before any work
    life.check_hours(hours_per_day)
    log_format = log_format if isinstance(log_format, formats.LogFormat) else log_format(nominal)
    given_path = given_model(calibrated) if settings.protocol == "twin" and calibrated is not None else None
    model_source = "nominal" if settings.protocol != "twin" else (
        stored.sha256_file(given_path) if given_path is not None else "per-unit" if calibrate else "nominal")
    if scale_prior is not None and not isinstance(scale_prior, ScalePrior):
        if Path(scale_prior).resolve() == Path(out).resolve():
            raise ValueError(f"--scale-prior {scale_prior}: the run's own output folder; expected another "
                             "run's (a unit would be its own prior, and the prior would move with every run)")
        scale_prior = learn_prior(scale_prior)
    digest = stored.settings_digest(settings, model_source, twin_temperature, stored.sha256_file(nominal.path),
                                    log_format.key, scale_prior.pair if scale_prior is not None else None)
    given = None
    if given_path is not None:
        try:
            given = robots.load(given_path)
        except ValueError as err:  # the run's error, never the nominal model instead
            raise ValueError(f"--calibrated {calibrated}: the model does not load ({err})") from None
    return MonitorRun(nominal, robot.path if isinstance(robot, Robot) else robot, Path(logs), Path(out), settings,
                      log_format, ratings, given_path, given, calibrate, model_source, digest, twin_temperature,
                      context, failure_wear, hours_per_day, progress, scale_prior)


def _check_context(context: ExecutionContext) -> None:
    """A monitor's execution context: an ExecutionContext, local jobs or a Dask scheduler (which must
    answer there, before any work), not both."""
    if not isinstance(context, ExecutionContext):
        raise ValueError(f"context {context!r}: expected an ExecutionContext(jobs, scheduler, stepper) "
                         "(faultgen.runs.context)")
    if context.scheduler is not None and context.jobs > 1:
        raise ValueError(f"--jobs {context.jobs} with --scheduler {context.scheduler}: the cluster's workers score "
                         "the units in parallel; drop --jobs (or --scheduler to score them in local processes)")
    if context.scheduler is not None:
        from faultgen.runs import cluster

        cluster.probe(context.scheduler)


def given_model(calibrated: str | Path) -> Path:
    """The model file of a ``faultgen calibrate`` output folder (or the file itself)."""
    path = Path(calibrated)
    if path.is_dir():
        found = sorted((path / "model").glob("*_calibrated.xml")) or sorted(path.glob("*_calibrated.xml"))
        if not found:
            raise ValueError(f"{path}: no model/<robot>_calibrated.xml; give a `faultgen calibrate` output "
                             "folder or its model file")
        path = found[0]
    return path
