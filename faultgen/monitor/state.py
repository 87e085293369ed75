"""What ``faultgen monitor`` keeps in ``OUT`` between runs, in formats that cannot run code.

An output folder may come from someone else (docs/reliability.md, "Threat model: output folders"),
so nothing in it is unpickled or imported, nothing it names is opened outside ``OUT`` and ``LOGS``,
and every file is checked against the settings and inputs it belongs to before it is used:

- ``OUT/.state/<unit>.json``: a unit's record (:class:`faultgen.monitor.history.UnitHistory`, its
  JSON written and checked there) under the digest of the run's settings (:func:`settings_digest`),
  its size bounded by :data:`STATE_MAX_BYTES`.
- ``OUT/.cache/cycles/<digest>.json`` (:func:`write_cycle`, :func:`read_cycle`): one simulated
  cycle's features beside the key that determined them (model and program SHA-256, friction model,
  temperature, payload, worn axis); a file whose key is not the one asked for, or whose features
  are not finite numbers of the expected length, is refused.
- ``OUT/.cache/calibrated/<digest>/`` and ``<digest>.json`` (:func:`write_calibration`,
  :func:`read_calibration`): a unit's calibration, under the digest of what it was made from, and
  a record of the calibrated model's SHA-256; the model itself is loaded as any robot description
  (:func:`faultgen.model.robots.load`: no file outside its folder, no plugin).

Every refusal is a :class:`StateError` (a :class:`faultgen.inputs.InputError`) naming the file and what did not match, and
saying what to do (score into a new ``OUT``, or delete the named file).
"""

from __future__ import annotations

import hashlib
import json
from dataclasses import asdict
from pathlib import Path

import numpy as np

from faultgen import inputs
from faultgen.data import atomic
from faultgen.data.confined import Confined
from faultgen.monitor.scoring import Settings

CYCLE_FORMAT = "faultgen-twin-cycle/1"
CALIBRATION_FORMAT = "faultgen-monitor-calibration/1"
#: Size bound of one unit's state file, written (:func:`faultgen.monitor.history.write_unit` refuses a larger one) and read back
#: (checked before it is parsed): about 0.85 kB per scored log with its load record, so some 20 000 logs (a log an hour for
#: two years). ``json`` takes up to 27 times the file's size to parse (a file of empty lists): 0.44 GB.
STATE_MAX_BYTES = 16 * 2**20
#: The entries of ``OUT/.cache`` (module docstring; ``programs``: the twins' replayed motion, which earlier versions wrote;
#: ``friction-tests``: the tests' readings, :mod:`faultgen.monitor.friction_tests`).
CACHE = ("cycles", "calibrated", "programs", "friction-tests")
#: Size bound of one cached cycle (a few hundred bytes).
CYCLE_MAX_BYTES = 2**20


class StateError(inputs.InputError):
    """A state or cache file in OUT refused (module docstring): it stops the run as a whole, before
    any output is written, where a unit's own trouble (a log, a twin) only degrades that unit."""


def sha256_file(path: str | Path) -> str:
    """SHA-256 of a file's bytes (a robot model, a log), hex, through :func:`faultgen.inputs.sha256_of`:
    a regular file of at most :data:`faultgen.logs.columns.LOG_MAX_BYTES`, its size checked before
    the read (a sparse file of terabytes apparent was hashed whole). InputError naming the file otherwise."""
    from faultgen.logs.columns import LOG_MAX_BYTES

    return inputs.sha256_of(path, "file", LOG_MAX_BYTES)


#: Longest unit name kept as it is in a file name of OUT (``<unit>.png``, ``.state/<unit>.json``),
#: UTF-8 bytes: with its suffix and an atomic write's temporary name (``.<name>.<pid>@<host>.XXXXXXXX.part``,
#: up to 87 bytes more) it stays within the 255 bytes a file name may have.
UNIT_FILE_MAX_BYTES = 128


def unit_file(unit: str, suffix: str) -> str:
    """The file name of ``unit``'s chart or state in OUT: ``<unit><suffix>``, or for a name longer
    than :data:`UNIT_FILE_MAX_BYTES` bytes its first 100 bytes (whole characters), ``-`` and 16 hex
    digits of the SHA-256 of the whole name (units.csv and the state itself keep the whole name)."""
    raw = unit.encode("utf-8")
    if len(raw) <= UNIT_FILE_MAX_BYTES:
        return unit + suffix
    return f"{raw[:100].decode('utf-8', 'ignore')}-{hashlib.sha256(raw).hexdigest()[:16]}{suffix}"


def key_name(key: dict) -> str:
    """The file name of a cache entry made from ``key`` (a JSON-able dict): the first 24 hex digits
    of the SHA-256 of its canonical JSON."""
    return hashlib.sha256(json.dumps(key, sort_keys=True).encode()).hexdigest()[:24]


def settings_digest(settings: Settings, model: str, twin_temperature: bool, robot_sha256: str,
                    log_format: str = "measured", scale_prior: tuple[float, float] | None = None) -> dict:
    """What a state belongs to, as a JSON-able dict: the monitor's settings, the model source
    ("nominal", "per-unit" or the SHA-256 of a given calibrated model), whether the twin predicts
    the temperature's effect, the SHA-256 of the robot's MJCF, the logs' format (with its
    options) and, where given, the scale factor's prior (mean, sd; :mod:`faultgen.monitor.scale_prior`)."""
    return {**asdict(settings), "model": model, "twin_temperature": bool(twin_temperature), "robot": robot_sha256,
            "format": log_format, **prior_settings(scale_prior)}


#: The keys of a fleet's scale prior (``--scale-prior``: mean, sd) in the digest and settings.json.
SCALE_PRIOR_KEYS = ("scale_prior_mean", "scale_prior_sd")


def prior_settings(scale_prior: tuple[float, float] | None) -> dict:
    """The digest's and settings.json's entries of a scale prior (mean, sd): :data:`SCALE_PRIOR_KEYS`;
    none without one (the default prior)."""
    return {} if scale_prior is None else dict(zip(SCALE_PRIOR_KEYS, map(float, scale_prior), strict=True))


def floats(values) -> list[float]:
    """``values`` (any shape) flattened to Python floats, as the state files write them (JSON)."""
    return [float(v) for v in np.ravel(values)]


def out_folder(out: str | Path) -> Confined:
    """``OUT`` as the monitor reads and writes it (:class:`faultgen.data.confined.Confined`): a path
    that leads, through a link, outside it is refused as a :class:`StateError` naming it (an output
    folder never makes faultgen read or write outside itself)."""
    return Confined(out, "monitor output folder", StateError)


def checked_out(out: str | Path) -> Confined:
    """:func:`out_folder` after checking, before a run reads or writes anything there, that OUT's
    ``.state``, ``.cache`` and each :data:`CACHE` entry, where they exist, lead inside OUT, and that an
    existing OUT takes new files (a read-only OUT refused before the work, not after it). A killed
    run's stage in OUT is removed first (:func:`faultgen.data.atomic.remove_stale`), giving back a
    ``.state`` it had moved aside and not replaced, so that the state read is the last one written.

    Raises
    ------
    StateError
        One of them is a link leading outside OUT (named).
    OSError
        OUT is on a read-only file system, takes no new file or is full (:func:`faultgen.data.atomic.check_writable`).
    """
    if Path(out).is_dir():
        atomic.remove_stale(out)
        atomic.check_writable(Path(out) / ".state")
    confined = out_folder(out)
    for entry in (".state", ".cache", *(f".cache/{name}" for name in CACHE)):
        confined.path(Path(out) / entry)
    return confined


def inside(path: Path, root: Path) -> Path:
    """``path`` after checking that it leads inside ``root`` (:func:`out_folder`)."""
    return out_folder(root).path(path)


def load_json(path: Path, what: str, max_bytes: int) -> dict:
    """The JSON object of the file ``path`` (a ``what``: named in the error), read up to ``max_bytes``.

    Raises
    ------
    StateError
        The file cannot be read, is larger than ``max_bytes``, is not JSON or not a JSON object.
    """
    try:
        text = inputs.read_text(path, what, max_bytes)
    except inputs.InputError as err:
        raise StateError(str(err)) from None
    try:
        document = json.loads(text)
    except (ValueError, RecursionError) as err:
        raise StateError(f"{path}: not a {what} ({type(err).__name__}: {str(err)[:80]})") from None
    if not isinstance(document, dict):
        raise StateError(f"{path}: not a {what} (expected a JSON object)")
    return document


def checked_vector(value, path: Path, name: str, length: int, finite: bool = True) -> np.ndarray:
    """``value`` read from the file ``path`` as an array of shape (``length``,), its field ``name``
    named in the error.

    Raises
    ------
    StateError
        ``value`` is not a list of ``length`` numbers, or (``finite``) holds NaN or an infinity.
    """
    if not (isinstance(value, list) and len(value) == length
            and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value)):
        raise StateError(f"{path}: {name} is not a list of {length} numbers")
    array = np.asarray(value, dtype=float)
    if finite and not np.all(np.isfinite(array)):
        raise StateError(f"{path}: {name} holds a value that is not a finite number")
    return array


def write_cycle(path: Path, root: Path, key: dict, features: np.ndarray) -> None:
    """Cache one simulated cycle's ``features`` beside the ``key`` that determined them, at ``path``
    inside ``root`` (:func:`out_folder`: a link leading out is refused, nothing written)."""
    out_folder(root).write_text(path, json.dumps({"format": CYCLE_FORMAT, "key": key, "features": floats(features)}))


def read_cycle(path: Path, root: Path, key: dict, n_features: int) -> np.ndarray:
    """The cached features of the cycle ``key``, checked (module docstring).

    Raises
    ------
    StateError
        The file is a link leading outside ``root``, is not a cached cycle of ``key`` or its features are not ``n_features`` finite numbers.
    """
    d = load_json(inside(path, root), "cached twin cycle", CYCLE_MAX_BYTES)
    if d.get("format") != CYCLE_FORMAT or d.get("key") != key:
        raise StateError(f"{path}: not the cached twin cycle of {key} (another model, program or condition); "
                                "delete it (the twin simulates it again)")
    return checked_vector(d.get("features"), path, "features", n_features)


def write_calibration(path: Path, root: Path, key: dict, model: Path) -> None:
    """Record that the calibration in ``model``'s folder was made from ``key`` (the nominal model's
    and the log's SHA-256 and the search's length), with ``model``'s own SHA-256, at ``path``
    inside ``root`` (:func:`out_folder`)."""
    folder = out_folder(root)
    folder.write_text(path, json.dumps({"format": CALIBRATION_FORMAT, "key": key,
                                        "model": sha256_file(folder.path(model))}))


def read_calibration(path: Path, root: Path, key: dict, model: Path) -> None:
    """Check a cached calibration's record against ``key`` and the model file it names.

    Raises
    ------
    StateError
        The record or the model is a link out of ``root``, the record belongs to another key, or
        the model file is missing or is not the one the record was written for.
    """
    d = load_json(inside(path, root), "cached calibration record", CYCLE_MAX_BYTES)
    fix = f"; delete {path} and {path.with_suffix('')} (the unit is calibrated again)"
    if d.get("format") != CALIBRATION_FORMAT or d.get("key") != key:
        raise StateError(f"{path}: not the calibration of this robot and log{fix}")
    if not Path(model).is_file() or sha256_file(inside(model, root)) != d.get("model"):
        raise StateError(f"{model}: not the calibrated model its record {path.name} was written for{fix}")
