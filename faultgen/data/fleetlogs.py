"""A fleet's measured logs as a faultgen dataset (``faultgen logs import``).

A folder of logs (:mod:`faultgen.data.logfolder`: ``LOGS/<unit>/<stamp>.csv|.csv.gz|.h5`` and an
optional ``LOGS/events.csv``) becomes a dataset like a simulated fleet's (``faultgen fleet``):
one run per unit, one record per log in stamp order, so that ``validate``, ``info``, ``plot`` and
every analysis command read it as they read a fleet.

The record of a log is computed by the code that makes a simulated fleet's daily records: each
cycle of the log (its ``cycle`` column; without one the log is one cycle) goes through
:func:`faultgen.simulation.sensors.cycle_features` (the motor torque is the log's arm-side torque
divided by the gear ratio; the histograms' design ranges are the robot's joint range, the velocity
limit of its folder's ``tasks.toml`` and its peak motor torque, as for its simulated tasks), and
the log's cycles are reduced to one record by :func:`faultgen.simulation.sensors.daily_features`,
as a simulated day's cycles are.

What an imported run holds beside the features (docs/dataset.md, "An imported fleet"):
``label`` (per log and axis: 1 worn, 0 healthy, -1 unknown, from the events), ``stamp``,
``stamp_key``, ``log_cycles``, ``log_duration`` and, when every log of the unit has them,
``joint_temperature`` (mean over the log) and ``payload_mass`` (its largest value);
:data:`faultgen.data.schema.MEASURED_ARRAYS`. No truth is measured: ``friction_multiplier`` holds
the labels as every analysis reads a wear (:data:`WORN_MARK` on worn logs, 1 elsewhere) and the
simulated truths ``mean_friction_torque`` and ``tracking_error`` are absent.

The dataset keeps a manifest (``/import``: each imported file's name relative to the folder,
``<unit>/<file>``, and its SHA-256; the folder's name only, never its path): importing again
into the same output imports only the logs that are new, keeps the records of the others (also
of files no longer in the folder), and refuses a log whose content changed since it was imported
(naming it), unless ``reimport_changed``. A log is keyed by its unit and stamp, not its file name:
``u1/2026-03-01.csv`` gzipped to ``u1/2026-03-01.csv.gz`` is the log imported before (its inflated
content the one imported: kept; another: changed), never a second record of that day; two files of
one stamp in a unit folder are refused by name (:func:`faultgen.data.logfolder.scan`). Every write is atomic
(:func:`faultgen.data.atomic.hdf5_writer`): a failure or a kill leaves the previous dataset as it
was, and no file that looks complete.
"""

from __future__ import annotations

import functools
import hashlib
import json
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import h5py
import numpy as np
from tqdm.auto import tqdm

from faultgen import __version__
from faultgen.data import logfolder, schema, writer
from faultgen.logs import columns, formats, measured
from faultgen.logs.columns import CSV_SUFFIXES, HDF5_SUFFIXES
from faultgen.data.atomic import check_apart, check_writable, hdf5_writer
from faultgen.data.opening import attr, open_file
from faultgen.model import robots
from faultgen.operation import programs
from faultgen.simulation import sensors

#: ``friction_multiplier`` of a log labelled worn: a mark, not a measured wear (100 % to an analysis
#: that reads it as a wear; healthy and unknown logs hold 1).
WORN_MARK = 2.0
#: The ``task`` and ``friction_model`` labels of an imported run, and its ``source`` attribute.
MEASURED = schema.MEASURED
#: Suffixes of the logs the measured-format reader takes (:func:`faultgen.logs.measured.read`).
SUFFIXES = CSV_SUFFIXES + HDF5_SUFFIXES
#: Why a log listed in the folder was not imported when it vanished before it was read (skipped, named).
VANISHED = "removed from the folder while it was imported"
#: The group of the manifest in an imported dataset.
MANIFEST = "import"

#: A reader of one log: ``(path, robot) -> MeasuredData`` (:func:`faultgen.logs.measured.read`, or an
#: adapter's, :mod:`faultgen.logs.formats`).
Reader = Callable[[Path, robots.Robot], measured.MeasuredData]
#: The measured format's reader (:data:`faultgen.logs.formats.MEASURED`), without the accelerations
#: the import's features do not use.
MEASURED_READER = functools.partial(formats.MEASURED.read, accelerations=False)


@dataclass
class ImportSummary:
    """What an import did.

    Attributes
    ----------
    out : Path
    robot : str
    units : int
        Runs in the dataset.
    imported : list of str
        Logs read now (``<unit>/<file>``), re-imported changed ones included.
    kept : int
        Records kept from the previous import (their files unchanged, or gone from the folder).
    gone : list of str
        Of them, the logs whose files are no longer in the folder.
    reimported : list of str
        Logs whose content changed since their import, imported again (``reimport_changed``).
    skipped : list of (str, str)
        Bad files passed over (``skip_bad``): name and reason.
    labels : dict
        Logs with a worn axis, logs all healthy, the others (unknown), over the whole dataset.
    torque : dict
        Logs read now per torque source, where the log format says which torque it read
        (:func:`faultgen.logs.formats.torque_source`: measured current x torque constant, or the
        commanded moment, which cannot show wear).
    friction_tests : int
        Friction tests found in the units' ``friction-test`` folders
        (:func:`faultgen.data.logfolder.scan_tests`): not imported (they are no daily logs; ``faultgen
        monitor`` reads them), said in the summary.
    written : bool
        False when nothing was new (the dataset was left as it was).
    """

    out: Path
    robot: str
    units: int = 0
    imported: list[str] = field(default_factory=list)
    kept: int = 0
    gone: list[str] = field(default_factory=list)
    reimported: list[str] = field(default_factory=list)
    skipped: list[tuple[str, str]] = field(default_factory=list)
    labels: dict = field(default_factory=dict)
    written: bool = True
    torque: dict = field(default_factory=dict)
    friction_tests: int = 0

    def __str__(self) -> str:
        records = len(self.imported) + self.kept
        lines = [f"{self.out}: {self.units} unit(s), {records} log record(s) of {self.robot}"
                 + ("" if self.written else " (nothing new: left as it was)"),
                 f"  imported now:  {len(self.imported)}"
                 + (f" ({len(self.reimported)} changed since their import, imported again)" if self.reimported else ""),
                 f"  kept:          {self.kept} imported before" + (f", {len(self.gone)} of them no longer in the folder"
                                                                    if self.gone else "")]
        if self.labels:
            lines.append(f"  labels:        {self.labels.get('worn', 0)} worn, {self.labels.get('healthy', 0)} healthy, "
                         f"{self.labels.get('unknown', 0)} unknown (events.csv; logs without an event are unknown)")
        for source, count in sorted(self.torque.items()):
            lines.append(f"  torque:        {source} ({count} log(s) read now)")
        if self.friction_tests:
            lines.append(f"  friction tests: {self.friction_tests} found (LOGS/<unit>/{logfolder.TESTS}/): not imported; "
                         "`faultgen monitor` reads them")
        if self.skipped:
            lines.append(f"  skipped:       {len(self.skipped)} bad file(s):")
            lines += [f"    {name}: {reason}" for name, reason in self.skipped]
        return "\n".join(lines)


def sha256(path: Path, max_bytes: int | None = None) -> str:
    """SHA-256 of a file's content, hex, read in blocks: a regular file of at most ``max_bytes``
    bytes (default :data:`faultgen.logs.columns.LOG_MAX_BYTES`), checked on its size before any read
    (:func:`faultgen.inputs.sha256_of`: a sparse file's apparent size is never read).

    Raises
    ------
    faultgen.inputs.InputError
        Naming the file: missing, not a regular file, or above the bound."""
    from faultgen import inputs

    return inputs.sha256_of(path, "log", columns.LOG_MAX_BYTES if max_bytes is None else max_bytes)


def content_sha256(path: Path) -> str | None:
    """SHA-256 of a log's content: its bytes, inflated when it is gzip-compressed (with the bomb
    check of :func:`faultgen.inputs.open_bytes`), so a log gzipped after its import has the digest
    it was imported under; None for a file that cannot be read so, or is above
    :data:`faultgen.logs.columns.LOG_MAX_BYTES` on disk (checked on its size before any read)."""
    from faultgen import inputs

    digest = hashlib.sha256()
    try:
        with inputs.open_bytes(path, "log", columns.LOG_MAX_BYTES) as fh:
            for block in iter(lambda: fh.read(1 << 20), b""):
                digest.update(block)
    except (OSError, ValueError, EOFError):
        return None
    return digest.hexdigest()


def read_once(read: Reader, path: Path, robot: robots.Robot) -> tuple[measured.MeasuredData, str]:
    """``read(path, robot)`` on the bytes of ``path`` read once, and their SHA-256, so that the
    digest is that of exactly the content parsed, even when the log is replaced meanwhile (read
    twice, a log replaced between the hash and the parse was stored under the old content's
    digest). A refusal names ``path``.

    The size bound (:data:`faultgen.logs.columns.LOG_MAX_BYTES`) is checked on the file's size
    before anything is read, and nothing is ever written to measure a file: a log of at most
    :data:`faultgen.logs.columns.WHOLE_MAX_BYTES` is held in memory (:func:`faultgen.inputs.hold`),
    parsed from those bytes by a reader that takes them (:attr:`faultgen.logs.formats.LogFormat.
    reads_held`; a plug-in reader of paths gets a private copy of them); a larger one is parsed
    from its path and hashed after, refused when the file changed meanwhile (its inode, size or
    modification time). (It was copied whole into TMPDIR before any bound: a sparse log of 1 GiB
    apparent, 0 bytes on disk, wrote 1 GiB there before its refusal.)

    Raises
    ------
    ValueError
        The reader's refusal (:class:`faultgen.logs.measured.MeasuredDataError`, an adapter's), or
        :class:`faultgen.inputs.InputError` for a path that is not a regular file, a file above the
        bound, or one that changed while it was read.
    """
    from faultgen import inputs

    path = Path(path)
    size = inputs.size_of(inputs.regular_file(path, "log", columns.LOG_MAX_BYTES))
    if size <= columns.WHOLE_MAX_BYTES:
        try:
            held = inputs.hold(path, "log", columns.WHOLE_MAX_BYTES)
        except inputs.InputError:
            if not path.is_file():
                raise
        else:  # held: parsed from the bytes hashed
            return _parse_held(read, held, robot), held.sha256
    before = _identity(path)
    data = read(path, robot)
    digest = sha256(path)
    if _identity(path) != before:
        raise inputs.InputError(f"{path}: changed while it was read (its size or modification time); import it "
                                "again once it is written")
    return data, digest


def _identity(path: Path) -> tuple[int, int, int, int]:
    info = path.stat()
    return info.st_dev, info.st_ino, info.st_size, info.st_mtime_ns


def _reads_held(read: Reader) -> bool:
    """Whether ``read`` is a log format's reader (a bound :meth:`faultgen.logs.formats.LogFormat.read`,
    or a ``functools.partial`` of one) that takes a file's bytes held (:attr:`reads_held`)."""
    func = read.func if isinstance(read, functools.partial) else read
    return bool(getattr(getattr(func, "__self__", None), "reads_held", False))


def _parse_held(read: Reader, held, robot: robots.Robot) -> measured.MeasuredData:
    """``read`` on the bytes ``held``: handed over as they are to a reader that takes them, else
    written to a private temporary folder (at most :data:`faultgen.logs.columns.WHOLE_MAX_BYTES`,
    the held bytes) and read from there, a refusal naming the log, never the copy."""
    if _reads_held(read):
        return read(held, robot)
    import tempfile

    with tempfile.TemporaryDirectory(prefix="faultgen-log-") as folder:
        copy = Path(folder) / held.name  # the same name: readers go by its suffix
        copy.write_bytes(held.data)
        try:
            return read(copy, robot)
        except ValueError as err:  # name the log, not its copy
            err.args = tuple(a.replace(str(copy), str(held.path)) if isinstance(a, str) else a
                             for a in err.args) or err.args
            raise


def log_record(data: measured.MeasuredData, robot: robots.Robot, speed_limit: np.ndarray) -> dict[str, np.ndarray]:
    """The record of one log: its cycles' :func:`~faultgen.simulation.sensors.cycle_features`,
    reduced to one by :func:`~faultgen.simulation.sensors.daily_features` (module docstring).

    Parameters
    ----------
    data : MeasuredData
        The log, checked (:func:`faultgen.logs.measured.read`).
    robot : Robot
        Its robot: gear ratio (arm-side torque -> motor torque), joint range, peak motor torque.
    speed_limit : ndarray of shape (N,)
        The speed histogram's design maximum, rad/s (:func:`faultgen.operation.programs.robot_limits`).

    Returns
    -------
    dict of ndarray
        The fleet's per-record features, each of shape (1, N) or (1, N, 12), and ``log_cycles``
        (1,), ``log_duration`` (1,) s, ``joint_temperature`` (1, N) degC and ``payload_mass`` (1,)
        kg when the log has them.
    """
    tau_m = data.tau / robot.gear_ratio  # arm-side torque referred to the motor side
    slices = [slice(None)] if data.cycle is None else measured.cycle_slices(data.cycle)
    per_cycle = [sensors.cycle_features(data.q[None, s], data.qd[None, s], tau_m[None, s], robot.joint_range,
                                        speed_limit, robot.motor_torque_limit) for s in slices]
    joined = {name: np.concatenate([f[name] for f in per_cycle]) for name in per_cycle[0]}
    record = sensors.daily_features(joined, len(per_cycle))
    record["log_cycles"] = np.array([len(slices)])
    record["log_duration"] = np.array([data.duration])
    if data.joint_temperature is not None:
        record["joint_temperature"] = data.joint_temperature.mean(axis=0)[None]
    if data.payload_mass is not None:
        record["payload_mass"] = np.array([data.payload_mass.max()])
    return record


def _feature_specs() -> dict[str, tuple[str, str, str]]:
    """The per-record arrays of a simulated fleet's run that an imported run holds too."""
    names = ("friction_multiplier", "mean_abs_torque", "rms_torque", "angle_hist", "speed_hist", "torque_hist")
    return {**{name: schema.ARRAYS[name] for name in names}, **schema.DUTY_ARRAYS}


class _Previous:
    """The dataset a previous import wrote at ``out`` (or none): its manifest and its runs' records."""

    def __init__(self, out: Path, robot: robots.Robot):
        self.files: dict[str, str] = {}
        self.events_sha256 = ""
        self.runs: dict[str, dict] = {}
        self.by_stamp: dict[tuple[str, float], str] = {}
        self.path = out
        if not out.exists():
            return
        with open_file(out) as f:
            if MANIFEST not in f:
                raise ValueError(f"{out} exists and is not an imported fleet (no /{MANIFEST} manifest); choose another "
                                 "-o, or remove it")
            manifest = f[MANIFEST]
            name = attr(manifest.attrs.get("robot"))
            if name != robot.name or attr(manifest.attrs.get("model_sha256")) != writer.model_hash(robot.path):
                raise ValueError(f"{out} holds logs of robot {name!r} (model {str(manifest.attrs.get('model_sha256'))[:12]}); "
                                 f"this import is for {robot.name!r} (model {writer.model_hash(robot.path)[:12]}): "
                                 "give its robot, or another -o")
            self.files = dict(zip((n.decode() for n in manifest["file"][()]),
                                  (h.decode() for h in manifest["sha256"][()]), strict=True))
            self.events_sha256 = attr(manifest.attrs.get("events_sha256", ""))
            self.runs = {unit: {"names": [n.decode() for n in group["log_file"][()]],
                                "keys": [float(k) for k in group["stamp_key"][()]],
                                "log_period": float(group.attrs["log_period"])} for unit, group in f["runs"].items()}
        # each record's file by its unit and stamp: a log is the same log under another name
        # (2026-03-01.csv gzipped to 2026-03-01.csv.gz)
        self.by_stamp = {(unit, key): name for unit, run in self.runs.items()
                         for name, key in zip(run["names"], run["keys"], strict=True)}

    def plan(self, units: dict, summary: ImportSummary, reimport_changed: bool) -> dict[str, list[tuple]]:
        """What each unit's records will be, in stamp order: ``(key, name, log or None, sha256, name
        imported under or None)``, kept from this import (``log`` None) or read now; a log is keyed by its
        unit and stamp, so a file renamed (gzipped) is the record imported before. Logs vanished since
        the folder was listed and files re-imported go into ``summary``; a unit whose files all left
        the folder keeps its records.

        Raises
        ------
        ValueError
            For a file changed since it was imported, without ``reimport_changed``.
        """
        plan: dict[str, list[tuple[float, str, logfolder.LogFile | None, str, str | None]]] = {}
        for unit, logs in units.items():
            entries = []
            for log in logs:
                try:  # bounded: its size first (a file above the bound is refused unread, by read_once)
                    digest = sha256(log.path)
                except (OSError, ValueError) as err:
                    if not (log.path.exists() or log.path.is_symlink()):  # removed since the folder was listed
                        summary.skipped.append((log.name, f"{VANISHED} ({getattr(err, 'strerror', None) or 'no such file'})"))
                        continue
                    digest, unread = "", str(err).removeprefix(f"{log.path}: ")  # not a regular file, too large
                was = self.name_of(log)
                before = self.files.get(was) if was is not None else None
                if before is None or before == digest or (was != log.name and content_sha256(log.path) == before):
                    entries.append((log.key, log.name, None if before else log, digest, was))
                    continue
                if not reimport_changed:
                    then = "" if was == log.name else f" as {was}"
                    now = f"{digest[:12]}... now" if digest else f"now {unread}"
                    raise ValueError(f"{log.path} changed since it was imported{then} into {self.path} "
                                     f"(SHA-256 {before[:12]}... then, {now}); put the imported "
                                     "content back, or give --reimport-changed to import it again")
                summary.reimported.append(log.name)
                entries.append((log.key, log.name, log, digest, was))
            plan[unit] = entries
        present = {name for entries in plan.values() for entry in entries for name in (entry[1], entry[4]) if name}
        for unit, run in self.runs.items():  # records whose files left the folder: kept
            gone = [name for name in run["names"] if name not in present]
            summary.gone += gone
            if gone:
                plan.setdefault(unit, [])
        return plan

    def name_of(self, log: logfolder.LogFile) -> str | None:
        """The file name under which ``log``'s unit and stamp were imported, or None."""
        return log.name if log.name in self.files else self.by_stamp.get((log.unit, log.key))

    def records(self, unit: str) -> dict[str, np.ndarray]:
        """Every array of a unit's previous run (features only: small), by name."""
        with open_file(self.path) as f:
            group = f["runs"][unit]
            return {name: group[name][()] for name in group}


def import_logs(logs_dir: Path, out: Path, *, robot, skip_bad: bool = False, progress: bool = True,
                reimport_changed: bool = False, reader: Reader = MEASURED_READER, suffixes: tuple[str, ...] = SUFFIXES,
                command: str = "") -> ImportSummary:
    """Import a fleet's folder of logs into a faultgen dataset (module docstring), atomically.

    Parameters
    ----------
    logs_dir : Path
        ``LOGS/<unit>/<stamp>.<csv|csv.gz|h5>`` and optionally ``LOGS/events.csv``
        (:mod:`faultgen.data.logfolder`).
    out : Path
        The dataset. If it exists it must be an earlier import of the same robot: the new logs are
        added to it (module docstring).
    robot : str, Path or Robot
        The robot of every unit (a name, a robot folder, or a loaded robot).
    skip_bad : bool
        Pass over bad files (not a log, a stamp that does not parse, a log the reader refuses),
        listing them in the summary; without it the first one is refused. A log removed from the
        folder while it is imported is passed over and listed either way (:data:`VANISHED`).
    progress : bool
        A progress bar over the logs read.
    reimport_changed : bool
        Import again a file whose content changed since it was imported; without it, refused.
    reader : callable, optional
        ``(path, robot) -> MeasuredData`` of one log; default the measured format's
        (:data:`MEASURED_READER`; another format's: its :meth:`~faultgen.logs.formats.LogFormat.read`
        without accelerations).
    suffixes : tuple of str
        The file endings of logs (lower case), the reader's.
    command : str
        The command line, stored as provenance.

    Returns
    -------
    ImportSummary

    Raises
    ------
    ValueError
        For a bad folder layout or events file (:mod:`faultgen.data.logfolder`), a bad log without
        ``skip_bad`` (its file and row named: :class:`faultgen.logs.measured.MeasuredDataError`), a
        file changed since its import without ``reimport_changed``, an ``out`` that is not an import
        of this robot, or no log to import at all. Nothing is written.
    OSError
        If ``out`` cannot be written (nothing is left at ``out`` but what was there).
    """
    logs_dir, out = Path(logs_dir), Path(out)
    check_apart(out, logs_dir)  # a dataset inside LOGS would be read back as a file of the folder
    robot = robot if isinstance(robot, robots.Robot) else robots.load(robot)
    read = reader
    speed_limit = programs.robot_limits(robot)[0]
    units, not_logs = logfolder.scan(logs_dir, suffixes)
    if not_logs and not skip_bad:
        name, reason = not_logs[0]
        raise ValueError(f"{logs_dir / name}: {reason} (--skip-bad passes over bad files and lists them)")
    events, events_sha = _events(logs_dir, units, robot)
    previous = _Previous(out, robot)
    summary = ImportSummary(out=out, robot=robot.name, skipped=list(not_logs))
    summary.friction_tests = sum(map(len, logfolder.scan_tests(logs_dir, units, suffixes)[0].values()))
    plan = previous.plan(units, summary, reimport_changed)
    new = [entry for entries in plan.values() for entry in entries if entry[2] is not None]
    if previous.files and not new and events_sha == previous.events_sha256:
        summary.written, summary.kept, summary.units = False, len(previous.files), len(previous.runs)
        return summary  # nothing new: the dataset stays as it is
    check_writable(out)
    with hdf5_writer(out) as f, tqdm(total=len(new), desc="import", unit="log", disable=not progress) as bar:
        writer.write_root(f, 0, command, "")
        f.attrs["complete"] = False
        runs = f.create_group("runs")
        rows = functools.partial(_rows, read=read, robot=robot, speed_limit=speed_limit, skip_bad=skip_bad,
                                 summary=summary, bar=bar)
        manifest = _write_units(runs, plan, previous, rows, robot, events, command, summary)
        if not len(runs):
            raise ValueError(f"{logs_dir}: no log could be imported ({len(summary.skipped)} bad file(s): "
                             f"{summary.skipped[0][0] if summary.skipped else 'none'}...)")
        f.attrs["n_runs"] = len(runs)
        _write_manifest(f, manifest, robot, logs_dir, events_sha)
        f.attrs["complete"] = True
        summary.units = len(runs)
    return summary


def _events(logs_dir: Path, units: dict, robot: robots.Robot) -> tuple[list, str]:
    """(the events of ``LOGS/events.csv``, its SHA-256), or ([], "") without one."""
    events_path = logs_dir / "events.csv"
    events = logfolder.read_events(events_path, units, robot.n_axes, logs_dir) if events_path.is_file() else []
    return events, sha256(events_path, logfolder.EVENTS_MAX_BYTES) if events_path.is_file() else ""


def _write_units(runs: h5py.Group, plan: dict, previous: _Previous, rows, robot: robots.Robot, events,
                 command: str, summary: ImportSummary) -> dict[str, str]:
    """Write each unit of ``plan`` that has records into ``runs`` (``rows(unit, entries, old)``: its
    records, :func:`_rows`), labelled by its ``events``; return each record's file -> its SHA-256."""
    by_unit: dict[str, list] = {}
    for event in events:
        by_unit.setdefault(event.unit, []).append(event)
    manifest: dict[str, str] = {}
    for unit in sorted(plan):
        old = previous.records(unit) if unit in previous.runs else None
        unit_rows = rows(unit, plan[unit], old)
        if not unit_rows:
            continue
        period = previous.runs.get(unit, {}).get("log_period", sensors.LOG_PERIOD)
        _write_unit(runs, unit, unit_rows, robot, by_unit.get(unit, []), command, summary, period)
        manifest.update({row["log_file"]: row["sha256"] for row in unit_rows})
    return manifest


def _write_manifest(f: h5py.File, manifest: dict[str, str], robot: robots.Robot, logs_dir: Path,
                    events_sha: str) -> None:
    """The import's manifest group: every record's file and its SHA-256, the robot and its model's
    SHA-256, the logs folder's name, the events file's SHA-256 and faultgen's version."""
    group = f.create_group(MANIFEST)
    names = sorted(manifest)
    group.create_dataset("file", data=np.array(names, dtype=object), dtype=h5py.string_dtype())
    group.create_dataset("sha256", data=np.array([manifest[n] for n in names], dtype=object),
                         dtype=h5py.string_dtype())
    group.attrs.update({"robot": robot.name, "model_sha256": writer.model_hash(robot.path),
                        "logs": logs_dir.resolve().name, "events_sha256": events_sha,
                        "faultgen_version": __version__})


def _rows(unit, entries, old, read, robot, speed_limit, skip_bad, summary, bar) -> list[dict]:
    """A unit's records in stamp order: kept ones from ``old`` (the previous run's arrays; a record
    kept under its file's new name when the file was renamed), new ones read (one log at a time;
    one re-imported replaces its old record); bad logs refused, or with ``skip_bad`` listed and
    passed over."""
    position = {} if old is None else {name.decode(): i for i, name in enumerate(old["log_file"])}
    rows = []
    kept_names = set()
    for key, name, log, digest, was in sorted(entries, key=lambda e: e[0]):
        if was is not None:
            kept_names.add(was)  # never kept again as a record of a file gone from the folder
        if log is None:
            i = position[was if was is not None else name]
            rows.append({**{k: v[i:i + 1] for k, v in old.items() if _per_record(k, v, old)},
                         "log_file": name, "sha256": digest, "stamp": old["stamp"][i].decode(), "key": key})
            summary.kept += 1
            continue
        try:
            data, digest = read_once(read, log.path, robot)
        except ValueError as err:  # MeasuredDataError and an adapter's refusals: the file and row named
            gone = not (log.path.exists() or log.path.is_symlink())
            if not (skip_bad or gone):
                raise
            summary.skipped.append((name, VANISHED if gone else str(err).removeprefix(f"{log.path}: ")))
            bar.update()
            continue
        rows.append({**log_record(data, robot, speed_limit), "log_file": name, "sha256": digest, "stamp": log.stamp,
                     "key": key, "period": data.sample_period})
        summary.imported.append(name)
        source = formats.torque_source(data.notes)
        if source:
            summary.torque[source] = summary.torque.get(source, 0) + 1
        bar.update()
    if old is not None:  # records of files no longer in the folder: kept, in stamp order
        for name, i in position.items():
            if name not in kept_names and name not in {r["log_file"] for r in rows}:
                rows.append({**{k: v[i:i + 1] for k, v in old.items() if _per_record(k, v, old)}, "log_file": name,
                             "sha256": "", "stamp": old["stamp"][i].decode(), "key": float(old["stamp_key"][i])})
                summary.kept += 1
        rows.sort(key=lambda r: r["key"])
    return rows


def _per_record(name: str, value: np.ndarray, old: dict) -> bool:
    """Whether an array of a previous run has one row per record (what a kept record carries over)."""
    return name not in ("t", "q_ref", "cycles", "label", "stamp", "stamp_key", "log_file", "friction_multiplier") \
        and np.ndim(value) >= 1 and len(value) == len(old["cycles"])


def _write_unit(runs: h5py.Group, unit: str, rows: list[dict], robot: robots.Robot, events, command: str,
                summary: ImportSummary, period: float) -> None:
    """One unit's run group: its records, its labels, its attributes."""
    n, n_axes = len(rows), robot.n_axes
    keys = np.array([row["key"] for row in rows])
    label = logfolder.labels(keys, events, n_axes)
    summary.labels["worn"] = summary.labels.get("worn", 0) + int(np.any(label == logfolder.WORN, axis=1).sum())
    summary.labels["healthy"] = summary.labels.get("healthy", 0) + int(np.all(label == logfolder.HEALTHY, axis=1).sum())
    summary.labels["unknown"] = n + summary.labels.get("unknown", 0) - int(np.any(label == logfolder.WORN, axis=1).sum()) \
        - int(np.all(label == logfolder.HEALTHY, axis=1).sum())
    group = runs.create_group(unit)
    arrays = {"t": np.zeros(0), "q_ref": np.zeros((0, n_axes)), "cycles": np.arange(1, n + 1),
              "friction_multiplier": np.where(label == logfolder.WORN, WORN_MARK, 1.0), "label": label,
              "stamp": np.array([row["stamp"] for row in rows], dtype=object), "stamp_key": keys,
              "log_file": np.array([row["log_file"] for row in rows], dtype=object)}
    names = [*(k for k in _feature_specs() if k != "friction_multiplier"), "log_cycles", "log_duration"]
    names += [k for k in ("joint_temperature", "payload_mass") if all(k in row for row in rows)]
    arrays.update({name: np.concatenate([row[name] for row in rows]) for name in names})
    specs = {**{k: schema.ARRAYS[k] for k in ("t", "q_ref", "cycles")}, **_feature_specs(), **schema.MEASURED_ARRAYS}
    for name, value in arrays.items():
        units, axes, description = specs[name]
        if value.dtype == object:
            ds = group.create_dataset(name, data=value, dtype=h5py.string_dtype())
        else:
            ds = group.create_dataset(name, data=value, compression="gzip", compression_opts=4, shuffle=True)
        ds.attrs.update({"units": units, "axes": axes, "description": description})
    periods = [row["period"] for row in rows if "period" in row]
    worn = sorted({k + 1 for k in np.flatnonzero(np.any(label == logfolder.WORN, axis=0))})
    config = {"import": {"unit": unit, "stamps": rows and logfolder.parse_stamp(rows[0]["stamp"], unit)[1]}}
    group.attrs.update({
        "robot": robot.name, "task": MEASURED, "friction_model": MEASURED, "cycles": n,
        "seed": int(hashlib.sha256(unit.encode()).hexdigest()[:7], 16), "worn_axes": np.array(worn, dtype=int),
        "wear": json.dumps({}), "noise": json.dumps({}), "faultgen_version": __version__,
        "model_sha256": writer.model_hash(robot.path), "n_axes": n_axes,
        "drivetrain": json.dumps(writer.drivetrain(robot)), "limits": json.dumps(writer.limits(robot)),
        "log_period": float(np.median(periods)) if periods else period,
        "config": json.dumps(config, sort_keys=True), "command": command, "signals": False, "sample": "log",
        "source": MEASURED, "unit": unit})
