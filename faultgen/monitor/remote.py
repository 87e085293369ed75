"""``faultgen monitor --scheduler``: units scored on a Dask cluster whose workers share no file
system with this process, as sweeps and fleets are (:mod:`faultgen.runs.cluster`).

A task is one group of units (:func:`faultgen.monitor.parallel.groups_of`) with everything its
scoring reads (:class:`Shipment`): the bytes of the unit's new logs, of its first log and of the log
its twin replays, the twin's cached simulated cycles of the models it may use (the nominal model's,
a given model's, the unit's cached calibration's) and the unit's cached calibration. The worker
lays them out in a temporary folder of its own as ``LOGS`` and ``OUT/.cache`` are laid out here,
scores the group there with the same code as a local job (:func:`faultgen.monitor.feed.score_group`),
and hands back the units (their monitors and state), their charts (PNG bytes) and rows of
``rul.csv``, and every cache file it made (cycles, a calibration, the twin's filtered program log),
with this process's paths in place of its folder's in every message. This process writes the cache
files into ``OUT/.cache`` (atomically, each cycle once) and the outputs as for a local run, so they
are those of ``--jobs 1``, bit for bit.

The robot is sent as the cluster code sends a sweep's: its name when it is a known robot, else
its absolute path (the workers must have it there), and a worker whose model file differs from
this process's (SHA-256) is refused, as is a worker without a given ``--calibrated`` model.
Cycles a worker simulates are shared with the other workers only through this process's cache in
a later task: two units of one model and program may simulate the same part's cycle side by side
(the same numbers: the outputs do not change, only the time).
"""

from __future__ import annotations

import itertools
import json
import shutil
import tempfile
from collections import deque
from collections.abc import Iterator
from dataclasses import dataclass, replace
from pathlib import Path

from faultgen import inputs
from faultgen.data.confined import Confined
from faultgen.logs import columns
from faultgen.model import robots
from faultgen.monitor import history
from faultgen.monitor import state as stored
from faultgen.monitor.feed import Context, idle_outputs, score_group
from faultgen.monitor.history import UnitHistory
from faultgen.monitor.unit import calibration_key

#: Size bound of one file of a cached calibration's folder (its model, report and the robot's
#: assets: meshes of an added robot are a few MB).
CALIBRATION_FILE_MAX_BYTES = 256 * 2**20
#: Tasks sent ahead per worker thread (the rest wait in this process, their logs not yet read).
IN_FLIGHT = 2


@dataclass(frozen=True)
class Shipment:
    """What a worker needs to score one group, as bytes: ``logs`` (``<unit>/<file>`` -> bytes, the
    fleet folder's layout) and ``cache`` (path relative to ``OUT/.cache`` -> bytes)."""

    logs: dict[str, bytes]
    cache: dict[str, bytes]


@dataclass(frozen=True)
class Returned:
    """What a worker hands back for one group: ``scored`` as :func:`score_group` returns it, the
    cache files it made (path relative to ``OUT/.cache`` -> bytes), its address and the SHA-256 of
    the robot model it loaded."""

    scored: list
    cache: dict[str, bytes]
    worker: str
    robot_sha256: str


def robot_for_workers(robot: str | Path) -> str:
    """``robot`` as a worker finds it: a known robot's name as it is, else this process's absolute path."""
    if str(robot) in robots.available():
        return str(robot)
    return str(Path(robot).absolute())


def score_remote(context: Context, robot: str, group: list, shipment: Shipment) -> Returned:
    """Worker task: lay ``shipment`` out in a temporary folder, score ``group`` there
    (:func:`faultgen.monitor.feed.score_group`) and return what it made (:class:`Returned`).
    ``context`` is this process's; its paths are replaced by the temporary folder's, and back in
    every message of what is returned or raised."""
    from distributed import get_worker

    address = get_worker().address
    root = Path(tempfile.mkdtemp(prefix="faultgen-monitor-"))
    try:
        logs, out = root / "logs", root / "out"
        for files, base in ((shipment.logs, logs), (shipment.cache, out / ".cache")):
            laid = Confined(base, "worker's folder")  # a name leading out of it (``..``) is refused
            for name, data in files.items():
                laid.write_bytes(base / name, data)
        try:
            nominal = robots.load(robot)
        except (OSError, ValueError) as err:
            raise FileNotFoundError(f"worker {address} cannot load the robot {robot} ({err}): install the same "
                                    "faultgen and robot models on every worker, or put an added robot's folder at "
                                    "the same path there") from None
        if context.calibrated is not None and not Path(context.calibrated).is_file():
            raise FileNotFoundError(f"worker {address} has no {context.calibrated} (the --calibrated model as the "
                                    "client sees it): put it at the same path on every worker")
        paths = {}  # this worker's path -> the client's, longest first when put back
        units = {}
        for unit, unit_logs in context.units.items():
            shipped = [log for log in unit_logs if log.name in shipment.logs]
            units[unit] = [replace(log, path=logs / log.name) for log in shipped]
            paths.update({str(logs / log.name): str(log.path) for log in shipped})
        paths[str(out)] = str(context.out)
        here = replace(context, robot=nominal.path, out=out, units=units)
        local = [(name, unit, [replace(log, path=logs / log.name) for log in unit_logs])
                 for name, unit, unit_logs in group]
        shipped_cache = set(shipment.cache)
        try:
            scored = score_group(here, local, here.new_source(nominal))  # the robot resolved above, once
        except ValueError as err:  # a refusal of the run (a state or cache file), in the client's paths
            try:
                again = type(err)(_put_back(str(err), paths))
            except TypeError:  # an error that is not made from its message alone: as it was
                raise err from None
            raise again from None
        made = {}
        for path in sorted((out / ".cache").rglob("*")):
            name = path.relative_to(out / ".cache").as_posix()
            if path.is_file() and (name not in shipped_cache or name.startswith("programs/")):
                made[name] = path.read_bytes()
        return Returned([(name, _unit_put_back(unit, paths), outputs) for name, unit, outputs in scored], made,
                        address, stored.sha256_file(nominal.path))
    finally:
        shutil.rmtree(root, ignore_errors=True)


def _put_back(text: str, paths: dict[str, str]) -> str:
    for ours in sorted(paths, key=len, reverse=True):
        text = text.replace(ours, paths[ours])
    return text


def _unit_put_back(unit: UnitHistory, paths: dict[str, str]) -> UnitHistory:
    """``unit`` with this worker's paths replaced by the client's in its notes and skipped logs' reasons."""
    unit.notes = [history.Note(_put_back(note, paths), note.kind, note.log, note.column) for note in unit.notes]
    unit.skipped = [replace(s, reason=_put_back(s.reason, paths)) for s in unit.skipped]
    return unit


class Cache:
    """This process's ``OUT/.cache`` as the tasks read it: each cycle file's model (its key's
    ``model``, a SHA-256), read once, so a task gets only the cycles of the models it may use."""

    def __init__(self, out: Path, nominal_sha256: str, calibrated: Path | None):
        self.root = out / ".cache"
        self.out = stored.checked_out(out)  # every read and write below stays inside OUT
        self.base = {nominal_sha256} | ({stored.sha256_file(calibrated)} if calibrated is not None else set())
        self.nominal_sha256 = nominal_sha256
        self.by_model: dict[str, dict[str, bytes]] = {}
        folder = self.root / "cycles"
        if folder.is_dir():
            for path in sorted(folder.glob("*.json")):  # each bounded as the local reader bounds it
                self._add(f"cycles/{path.name}", self.out.read_bytes(path, "cached twin cycle", stored.CYCLE_MAX_BYTES))

    def _add(self, name: str, data: bytes) -> None:
        try:
            model = json.loads(data)["key"]["model"]
        except (ValueError, KeyError, TypeError):
            model = ""  # not a cycle: the worker's own check refuses it, if it is read
        self.by_model.setdefault(model, {})[name] = data

    def for_unit(self, unit: UnitHistory, nominal_sha256: str, first_sha256: str, log_format: str) -> dict[str, bytes]:
        """The cache files a unit's scoring may read: the cycles of the nominal model, of a given
        model and of its cached calibration (with that calibration's folder and record; ``log_format``
        the run's :attr:`faultgen.logs.formats.LogFormat.key`)."""
        files: dict[str, bytes] = {}
        models = set(self.base)
        if unit.model in ("calibrated", "friction"):
            key = calibration_key(nominal_sha256, first_sha256, unit.model, log_format)
            digest = stored.key_name(key)
            record, folder = self.root / "calibrated" / f"{digest}.json", self.root / "calibrated" / digest
            if record.is_file() and folder.is_dir():
                files[f"calibrated/{digest}.json"] = self.out.read_bytes(record, "cached calibration record",
                                                                         stored.CYCLE_MAX_BYTES)
                for path in sorted(self.out.path(folder).rglob("*")):
                    if path.is_file():
                        files[path.relative_to(self.root).as_posix()] = self.out.read_bytes(
                            path, "file of a cached calibration", CALIBRATION_FILE_MAX_BYTES)
                        if path.name.endswith("_twin.xml"):
                            models.add(stored.sha256_file(path))
        for model in sorted(models):
            files.update(self.by_model.get(model, {}))
        return files

    def write(self, made: dict[str, bytes]) -> None:
        """Write a task's new cache files here, atomically: a cycle or a calibration file once (the
        same key gives the same bytes), the program logs again (as a local twin does), and a
        calibration's record last, after its folder."""
        records = [name for name in made if name.startswith("calibrated/") and name.count("/") == 1]
        for name in sorted(set(made) - set(records)) + sorted(records):
            if name.split("/")[0] not in stored.CACHE:
                raise ValueError(f"a worker sent back {name!r}, which is not a monitor cache file")
            if Path(name).is_absolute() or ".." in Path(name).parts:
                raise ValueError(f"a worker sent back {name!r}, which is not a path inside the monitor's cache")
            path = self.out.path(self.root / name)
            if path.exists() and not name.startswith("programs/"):
                continue
            self.out.write_bytes(path, made[name])
            if name.startswith("cycles/"):
                self._add(name, made[name])


def execute(context: Context, groups: list, scheduler: str, robot: str | Path, idle: list = ()) -> Iterator[list]:
    """Score ``groups`` on the Dask cluster of ``scheduler`` (module docstring), then make the
    charts and remaining life of the ``idle`` monitors (units with no new log,
    :func:`faultgen.monitor.feed.idle_outputs`, which reads no file); yield each result as
    :func:`score_group` returns it, in order, a group's once its cache files are written.
    ``robot`` is the robot as the user named it (:func:`robot_for_workers`). At most
    :data:`IN_FLIGHT` tasks per worker thread are sent ahead, so this process holds the bytes of
    only so many groups' logs at a time.

    Raises
    ------
    faultgen.runs.errors.SweepRefused
        No Dask scheduler answers at ``scheduler`` (:func:`faultgen.runs.cluster.probe`; nothing ran).
    faultgen.runs.errors.SweepError
        The scheduler was lost, or a worker loaded another robot model than this process's.
    ValueError
        A unit's scoring refused the run (a state or cache file), as a local run would.
    """
    from concurrent.futures import CancelledError

    from distributed import Client

    from faultgen.runs import cluster
    from faultgen.runs.errors import SweepError, SweepRefused

    cluster.probe(scheduler)
    try:
        client = Client(scheduler, timeout="10s", set_as_default=False)
    except Exception as err:  # noqa: BLE001 (a scheduler gone since the probe, TLS without certificates, ...)
        raise SweepRefused(f"cannot reach the Dask scheduler at {scheduler}: {' '.join(str(err).split())}") from None
    sent_robot = robot_for_workers(robot)
    ours = stored.sha256_file(context.robot)
    if context.calibrated is not None:
        context = replace(context, calibrated=Path(context.calibrated).absolute())
    cache = Cache(context.out, ours, context.calibrated)
    with client:
        threads = sum(w.get("nthreads", 1) for w in client.scheduler_info()["workers"].values())
        window = max(IN_FLIGHT * threads, 2)
        futures: deque = deque()
        tasks = itertools.chain(
            ((score_remote, (_context_of(context, group), sent_robot, group), group) for group in groups),
            ((idle_outputs, (monitor, context.failure_wear), None) for monitor in idle))
        while True:
            for function, args, group in tasks:
                if group is not None:  # its logs and cache read only now: so many groups' bytes at a time
                    args = (*args, _shipment(context, cache, group, ours))
                futures.append(client.submit(function, *args, pure=False))
                if len(futures) >= window:
                    break
            if not futures:
                return
            future = futures.popleft()
            try:
                returned = future.result()
            except CancelledError as err:
                raise SweepError(f"lost the Dask scheduler at {scheduler} ({err or 'cancelled'}); nothing of this run "
                                 "is written: run the same command again") from None
            finally:
                future.release()
            if not isinstance(returned, Returned):  # an idle unit's outputs
                yield returned
                continue
            if returned.robot_sha256 != ours:
                raise SweepError(f"worker {returned.worker} loaded another {context.robot.name} (MJCF SHA-256 "
                                 f"{returned.robot_sha256[:12]}, here {ours[:12]}): install the same faultgen and "
                                 "robot models on every worker")
            cache.write(returned.cache)
            yield returned.scored


def _context_of(context: Context, group: list) -> Context:
    """``context`` with only the units and maintenance events ``group`` reads (a task carries no
    other unit's list of logs)."""
    names = {name for name, _, _ in group} | {unit.program[0] for _, unit, _ in group if unit.program is not None}
    return replace(context, units={u: logs for u, logs in context.units.items() if u in names},
                   maintenance={u: e for u, e in context.maintenance.items() if u in names})


def _shipment(context: Context, cache: Cache, group: list, nominal_sha256: str) -> Shipment:
    files: dict[str, bytes] = {}
    for _, unit, _ in group:
        files.update(cache.for_unit(unit, nominal_sha256, unit.first[1], context.log_format.key))
    return Shipment(_logs_of(context, group), files)


def _logs_of(context: Context, group: list) -> dict[str, bytes]:
    """The logs a group's scoring reads, ``<unit>/<file>`` -> bytes: each unit's new logs, its
    first log (its calibration's) and the log its twin replays (maybe another unit's)."""
    wanted = []
    for name, unit, unit_logs in group:
        wanted += unit_logs
        mine = context.units.get(name, [])
        wanted += [log for log in mine if log.stamp == unit.first[0]]
        if unit.program is not None:
            wanted += [log for log in context.units.get(unit.program[0], []) if log.stamp == unit.program[1]]
    # through faultgen.inputs: the size bound first (a sparse log was read whole here: a MemoryError)
    return {log.name: inputs.read_bytes(log.path, "joint log", columns.LOG_MAX_BYTES) for log in wanted}
