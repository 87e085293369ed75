"""The benchmark's files: ``train.h5`` and ``test.h5`` (what a method may read) and ``test_labels.csv``.

Both HDF5 files hold *units* (``/units/<id>``: one robot doing its program), each with attributes
``robot``, ``task`` and ``sample`` (what a record is: "cycle") and one array per observable
quantity of :data:`OBSERVABLES` it has, in the units of faultgen's dataset schema (docs/dataset.md):
what a robot's controller could log. Never the simulated truth (friction, wear, fault parameter).
A train unit also carries its labels: ``fault_level`` (per record, %: the worn axis's friction wear,
or the share of a fault's final change), and attributes ``worn_axis`` (1..N, 0 none) and ``fault``
("none", "friction_wear", or the effect of another fault). A test unit carries none of them; its
labels are in ``test_labels.csv`` (one row per unit and record: unit, cycle, fault_level_pct,
worn_axis, fault), which scoring reads and a method is never given. Test unit ids are in a seeded
random order (``test-000``, ...), so that neither the id nor the order tells the fault.
"""

from __future__ import annotations

import csv
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from faultgen import axes as axis_numbers
from faultgen import inputs
from faultgen.data import atomic, cells
from faultgen.logs.columns import MAX_CYCLE, PAYLOAD_COLUMN, TEMPERATURE_PREFIX, VALUE_BOUNDS

#: The friction tests' readings (the prognostics track's version 2, docs/bench/prognostics.md): name ->
#: (unit, layout); on the record of the test's day, 0 on the others (``friction_test`` 1 marks the
#: records with a test): each axis's dry level with its 95 % interval and viscous coefficient, arm
#: side, at the test's logged joint temperature (``faultgen friction-test``'s friction_fit.csv).
TEST_ARRAYS = {
    "friction_test": ("1", "cycle"), "friction_test_coulomb": ("N m", "cycle, axis"),
    "friction_test_coulomb_low": ("N m", "cycle, axis"), "friction_test_coulomb_high": ("N m", "cycle, axis"),
    "friction_test_viscous": ("N m s/rad", "cycle, axis"), "friction_test_temperature": ("degC", "cycle, axis"),
}
#: The duty of the day a unit logs (the prognostics track's version 3): name -> (unit, layout).
DUTY_ARRAYS = {"speed_override": ("1", "cycle"), "operating_hours": ("h", "cycle")}
#: name -> unit of every per-record array a method may read (faultgen's dataset schema): the
#: per-axis features ("record, axis"), the histograms ("record, axis, bin") and, for a run with
#: operating conditions, what a plant logs beside them.
OBSERVABLES = {
    "cycles": "1", "mean_abs_torque": "N m", "rms_torque": "N m", "average_speed": "rad/s",
    "average_load_torque": "N m", "angle_hist": "1", "speed_hist": "1", "torque_hist": "1",
    "day": "d", "hour": "h", "ambient_temperature": "degC", "joint_temperature": "degC", "payload_mass": "kg",
    "task_index": "1",
    **{name: unit for name, (unit, _) in {**TEST_ARRAYS, **DUTY_ARRAYS}.items()},
}
#: The per-axis scalar features a detector sees by default (columns of :meth:`Unit.features`).
FEATURES = ("mean_abs_torque", "rms_torque", "average_speed", "average_load_torque")
FORMAT = "faultgen-bench/1"
LABEL_COLUMNS = ("unit", "cycle", "fault_level_pct", "worn_axis", "fault")
#: The arrays every unit holds: its records' cycle numbers and the per-axis feature that sets the axes.
REQUIRED = ("cycles", "mean_abs_torque")
#: The text attributes of every unit and what each says.
UNIT_TEXT = {"robot": "the robot's name", "task": "the task's name", "sample": "what a record is: cycle, day or log"}
#: Most records one unit may hold (a record a cycle: a cycle a minute for 19 years).
MAX_RECORDS = 10**7
#: Most units one benchmark file may hold (the tracks have tens to hundreds).
MAX_UNITS = 100_000
#: Longest text attribute (robot, task, sample, fault) read, characters.
MAX_TEXT_BYTES = 4096
#: Most bytes a benchmark file's arrays may declare, all units together, counted as float64 (8 bytes an
#: element, as the features are scored) from the declared shapes before any array is read: 2^26
#: elements, some 9.5 million records of cycles and mean_abs_torque on six axes, 140 000 with every
#: observable. A thesis track's file is a few MB.
MAX_BYTES = 512 * 2**20
#: Size bound of ``test_labels.csv``, bytes (a row is under 80 bytes; a full track's file a few MB).
LABELS_MAX_BYTES = 256 * 2**20
#: The largest fault level a run writes, % (``faultgen run --wear-pct`` takes 0..500).
MAX_FAULT_LEVEL = 500.0
_TAU, _QD = VALUE_BOUNDS["tau"][:2], VALUE_BOUNDS["qd"][:2]
#: array -> (low, high) of the values a run or an import writes (the joint logs' bounds,
#: :data:`faultgen.logs.columns.VALUE_BOUNDS`; the histograms are shares of a record's
#: samples): every value read is finite and within them, so that no metric overflows or turns NaN.
VALUE_RANGES = {
    "cycles": (0, MAX_CYCLE), "mean_abs_torque": _TAU, "rms_torque": _TAU, "average_load_torque": _TAU,
    "average_speed": _QD, "angle_hist": (0.0, 1.0), "speed_hist": (0.0, 1.0), "torque_hist": (0.0, 1.0),
    "day": (0.0, MAX_CYCLE), "hour": (0.0, 24.0), "ambient_temperature": VALUE_BOUNDS[TEMPERATURE_PREFIX][:2],
    "joint_temperature": VALUE_BOUNDS[TEMPERATURE_PREFIX][:2], "payload_mass": VALUE_BOUNDS[PAYLOAD_COLUMN][:2],
    "task_index": (0, MAX_CYCLE), "fault_level": (0.0, MAX_FAULT_LEVEL),
    "friction_test": (0, 1), **dict.fromkeys(("friction_test_coulomb", "friction_test_coulomb_low",
                                              "friction_test_coulomb_high"), _TAU),
    "friction_test_viscous": (-1e9, 1e9), "friction_test_temperature": VALUE_BOUNDS[TEMPERATURE_PREFIX][:2],
    "speed_override": (0.0, 2.0), "operating_hours": (0.0, 24.0),
}


@dataclass
class Unit:
    """One unit of a benchmark file.

    Attributes
    ----------
    id, robot, task, sample : str
    arrays : dict of str to ndarray
        The observables it has (:data:`OBSERVABLES`), first axis the records.
    fault_level : ndarray of shape (n_records,) or None
        % (train units only; None in a test file).
    worn_axis : int or None
        1..N, 0 without a fault; None in a test file.
    fault : str or None
        "none", "friction_wear" or an effect id; None in a test file.
    """

    id: str
    robot: str
    task: str
    sample: str
    arrays: dict[str, np.ndarray]
    fault_level: np.ndarray | None = None
    worn_axis: int | None = None
    fault: str | None = None

    @property
    def n_axes(self) -> int:
        return self.arrays["mean_abs_torque"].shape[1]

    def features(self, names: tuple[str, ...] = FEATURES) -> np.ndarray:
        """Per record, the per-axis features ``names`` side by side: ndarray of shape
        (n_records, len(names) * N), feature-major (all axes of the first feature, then the next)."""
        return np.concatenate([self.arrays[name] for name in names if name in self.arrays], axis=1)


def write(path: Path, units: list[Unit], attrs: dict) -> None:
    """Write ``units`` to the benchmark file ``path`` (atomically), with file attributes ``attrs``."""
    with atomic.hdf5_writer(path) as f:
        f.attrs["format"] = FORMAT
        for key, value in attrs.items():
            f.attrs[key] = value
        group = f.create_group("units")
        for unit in units:
            g = group.create_group(unit.id)
            g.attrs.update(robot=unit.robot, task=unit.task, sample=unit.sample)
            for name, values in unit.arrays.items():
                g.create_dataset(name, data=values)
                g[name].attrs["units"] = OBSERVABLES[name]
            if unit.fault_level is not None:
                g.create_dataset("fault_level", data=unit.fault_level)
                g["fault_level"].attrs["units"] = "%"
                g.attrs.update(worn_axis=int(unit.worn_axis), fault=str(unit.fault))


def folder_file(path: str | Path, what: str, max_bytes: int | None = None) -> Path:
    """``path`` after checking that it is a regular file (:func:`faultgen.inputs.regular_file`, of at
    most ``max_bytes`` bytes) inside its benchmark folder (``path``'s parent): a symbolic link whose
    target leaves the folder is refused, naming the link only (nothing of the target is read or shown).

    Raises
    ------
    faultgen.inputs.InputError
        Naming ``path`` and ``what``: missing (with the command that writes it), outside the folder,
        not a regular file, or above the bound.
    """
    path = Path(path)
    folder = path.parent if str(path.parent) else Path(".")
    if not path.exists() and not path.is_symlink():
        raise inputs.InputError(f"{path} does not exist (the {what}); `faultgen bench make TRACK -o {folder}` writes it")
    if not inputs.inside(path, folder):
        raise inputs.InputError(f"{path}: a symbolic link to a file outside the benchmark folder {folder}; the {what} "
                                "must be a regular file inside the folder (nothing of the target was read)")
    return inputs.regular_file(path, what, max_bytes)


def _short(value, most: int = 60) -> str:
    """``repr(value)`` cut to ``most`` characters (a name or cell of a file inside the folder, in an error)."""
    text = repr(value)
    return text if len(text) <= most else text[:most] + "...(cut)"


def _attr(obj, name: str, where: str, expected: str, kinds: str, required: bool = True):
    """The scalar attribute ``name`` of ``obj``, checked from its declared type and shape before it
    is read: text (``kinds`` "SOU") is returned as str, a whole number ("iu") as int. None when it is
    absent and not ``required``.

    Raises
    ------
    faultgen.inputs.InputError
        ``where`` (the file and the unit) and the attribute: missing, not a scalar or of another type.
    """
    import h5py

    if name not in obj.attrs:
        if not required:
            return None
        raise inputs.InputError(f"{where}: no attribute {name!r}; {expected} is expected")
    attr_id = h5py.h5a.open(obj.id, name.encode())
    dtype = attr_id.dtype
    if attr_id.shape != () or dtype.kind not in kinds or (dtype.kind in "SU" and dtype.itemsize > MAX_TEXT_BYTES) or (
            dtype.kind == "O" and h5py.check_string_dtype(dtype) is None):  # O: text of any length, or a reference
        raise inputs.InputError(f"{where}: attribute {name!r} is of type {attr_id.dtype} and shape {attr_id.shape}; "
                                f"{expected} is expected")
    value = obj.attrs[name]
    if kinds == "iu":
        return int(value)
    text = value.decode("utf-8", "replace") if isinstance(value, bytes) else str(value)
    if len(text) > MAX_TEXT_BYTES:
        raise inputs.InputError(f"{where}: attribute {name!r} is {len(text)} characters long; {expected} of at most "
                                f"{MAX_TEXT_BYTES} is expected")
    return text


def _unit_arrays(path: Path, uid: str, g, labelled: bool) -> tuple[dict, int]:
    """The datasets of the unit group ``g`` (not read yet), each checked from its declared shape and
    type: ``cycles`` (the records, at most :data:`MAX_RECORDS`), ``mean_abs_torque`` (records x
    axes), every other observable by its axes in faultgen's dataset schema, ``fault_level``
    (records) when ``labelled``; and the number of axes."""
    from faultgen.data.schema import BINS, SHAPES

    where = f"{path}: unit {_short(uid)}"
    for name in REQUIRED:
        if name not in g:
            raise inputs.InputError(f"{where}: no array {name!r}; every unit holds "
                                    f"{' and '.join(REQUIRED)} (records{' x axes' if name != 'cycles' else ''})")
    cycles = inputs.bounded_dataset(g, "cycles", path, (None,), kinds="iu")
    n = cycles.shape[0]
    if not 1 <= n <= MAX_RECORDS:
        raise inputs.InputError(f"{where}: cycles declares {n} records; 1..{MAX_RECORDS} are expected")
    torque = inputs.bounded_dataset(g, "mean_abs_torque", path, (n, None))
    n_axes = torque.shape[1]
    if not axis_numbers.MIN_AXES <= n_axes <= axis_numbers.MAX_AXES:
        raise inputs.InputError(f"{where}: mean_abs_torque has {n_axes} axes; "
                                f"{axis_numbers.MIN_AXES}..{axis_numbers.MAX_AXES} are expected")
    sizes = {"cycle": n, "axis": n_axes, **BINS}
    arrays = {}
    for name in OBSERVABLES:
        if name in g:
            extra = {**TEST_ARRAYS, **DUTY_ARRAYS}
            layout = extra[name][1] if name in extra else SHAPES[name]
            shape = tuple(sizes[axis.strip()] for axis in layout.split(","))
            arrays[name] = inputs.bounded_dataset(g, name, path, shape, kinds="iu" if name == "cycles" else "fiub")
    if labelled:
        arrays["fault_level"] = inputs.bounded_dataset(g, "fault_level", path, (n,), kinds="fiu")
    return arrays, n_axes


def _check_range(values: np.ndarray, name: str, where: str) -> None:
    """Refuse the first value of the array ``name`` that is not finite or lies outside its
    :data:`VALUE_RANGES`, naming ``where`` (the file and unit), the array, the record and the range.

    Raises
    ------
    faultgen.inputs.InputError
    """
    low, high = VALUE_RANGES[name]
    bad = ~np.isfinite(values) | (values < low) | (values > high) if values.dtype.kind == "f" else (
        (values < low) | (values > high))
    if bad.any():
        index = np.unravel_index(int(np.argmax(bad)), values.shape)
        unit = OBSERVABLES.get(name, "%")
        raise inputs.InputError(f"{where}: {name} holds {values[index].item()!r} at record {index[0] + 1}; finite "
                                f"values within {low:g}..{high:g}{'' if unit == '1' else ' ' + unit} are expected "
                                "(what a run writes)")


def read_with_attrs(path: str | Path, attrs: tuple[str, ...] = ()) -> tuple[list[Unit], dict]:
    """The units of a benchmark file (as :func:`read`) and its file attributes ``attrs`` (each
    required: text, or a whole number for ``version``).

    The file is opened by :func:`faultgen.inputs.open_hdf5` (a file outside its folder, an external
    or escaping soft link, a virtual dataset or external storage refused) and every unit's
    attributes and arrays are checked from their declared types and shapes (:func:`_unit_arrays`,
    at most :data:`MAX_UNITS` units and :data:`MAX_BYTES` in all, as float64) before any array is read.

    Raises
    ------
    faultgen.inputs.InputError
        A ``ValueError`` naming the file, the unit and what is missing or wrong and what was expected.
    """
    import h5py

    path = folder_file(path, "benchmark file")
    with inputs.open_hdf5(path, "benchmark file of `faultgen bench make`") as f:
        fmt = _attr(f, "format", str(path), f"the text {FORMAT!r}", "SOU", required=False)
        if fmt != FORMAT:
            raise inputs.InputError(f"{path} is not a benchmark file (format {_short(fmt)}, expected {FORMAT!r})")
        made = {name: _attr(f, name, str(path), "a whole number" if name == "version" else "a text",
                            "iu" if name == "version" else "SOU") for name in attrs}
        group = f.get("units")
        if not isinstance(group, h5py.Group):
            found = "none" if group is None else f"a {type(group).__name__.lower()}"
            raise inputs.InputError(f"{path}: no /units group (found {found}); a benchmark file holds its units "
                                    "under /units")
        if len(group) > MAX_UNITS:
            raise inputs.InputError(f"{path}: {len(group)} units; at most {MAX_UNITS} are read")
        checked, total = [], 0
        for uid in group:  # every unit checked from its metadata before any array is read
            g = group.get(uid)
            where = f"{path}: unit {_short(uid)}"
            if not isinstance(g, h5py.Group):
                raise inputs.InputError(f"{where} is a {type(g).__name__.lower()}; each unit is a group")
            labelled = "fault_level" in g
            arrays, n_axes = _unit_arrays(path, uid, g, labelled)
            total += 8 * sum(ds.size for ds in arrays.values())
            if total > MAX_BYTES:
                raise inputs.InputError(f"{path}: its units declare more than {MAX_BYTES} bytes of arrays (as float64) "
                                        f"in all, at unit {_short(uid)}; a benchmark file is read up to that (MAX_BYTES)")
            info = {name: _attr(g, name, where, f"a text ({meaning})", "SOU") for name, meaning in UNIT_TEXT.items()}
            if labelled:
                info["worn_axis"] = _attr(g, "worn_axis", where, f"a whole axis number 0..{n_axes}", "iu")
                if not 0 <= info["worn_axis"] <= n_axes:
                    raise inputs.InputError(f"{where}: attribute 'worn_axis' is {info['worn_axis']}; a whole axis "
                                            f"number 0..{n_axes} (0: none) is expected")
                info["fault"] = _attr(g, "fault", where, "a text (none, friction_wear or an effect id)", "SOU")
            checked.append((uid, arrays, info))
        units = []
        for uid, arrays, info in checked:
            values = {name: ds[()] for name, ds in arrays.items()}
            for name, array in values.items():
                _check_range(array, name, f"{path}: unit {_short(uid)}")
            fault_level = values.pop("fault_level", None)
            units.append(Unit(id=uid, arrays=values, fault_level=fault_level, **info))
    return units, made


def read(path: str | Path) -> list[Unit]:
    """The units of a benchmark file, in file order (labels only in a train file).

    Raises
    ------
    faultgen.inputs.InputError
        A ``ValueError``: if ``path`` does not exist, leaves its folder or is not a benchmark file,
        or a unit lacks an attribute or array or declares a wrong type or shape (naming the file,
        the unit and what was expected); see :func:`read_with_attrs`.
    """
    return read_with_attrs(path)[0]


def write_labels(path: Path, units: list[Unit]) -> None:
    """``test_labels.csv``: one row per unit and record (:data:`LABEL_COLUMNS`), atomically."""
    rows = [cells.line(LABEL_COLUMNS)]
    for unit in units:
        for cycle, level in zip(unit.arrays["cycles"], unit.fault_level):
            rows.append(cells.line([unit.id, int(cycle), float(level), int(unit.worn_axis), str(unit.fault)]))
    atomic.write_text(path, "\n".join(rows) + "\n")


def attach_labels(units: list[Unit], path: str | Path) -> list[Unit]:
    """``units`` of a test file with their labels from ``test_labels.csv`` (scoring only).

    The file must be a regular file inside the benchmark folder (:func:`folder_file`: a symbolic
    link leaving it is refused without reading the target) of at most :data:`LABELS_MAX_BYTES`
    bytes, and hold no more rows than the units have records; an error names the file and the row,
    and shows at most a short cut of the cell at fault (of this file only).

    Raises
    ------
    faultgen.inputs.InputError
        A ``ValueError``: if the file is missing or refused, its header or a row is wrong, a unit has
        no rows, or its cycles differ from the unit's (naming them).
    """
    path = folder_file(path, "test labels", LABELS_MAX_BYTES)
    records = sum(len(unit.arrays["cycles"]) for unit in units)
    rows: dict[str, list] = {}
    line = 1
    try:
        with inputs.open_text(path, "test labels", LABELS_MAX_BYTES) as fh:
            reader = csv.reader(fh)
            header = next(reader, None)
            if tuple(header or ()) != LABEL_COLUMNS:
                raise inputs.InputError(f"{path}, row 1: columns {_short(header, 120)}; expected "
                                        f"{', '.join(LABEL_COLUMNS)}")
            for line, fields in enumerate(reader, start=2):
                if line - 1 > records:
                    raise inputs.InputError(f"{path}, row {line}: more label rows than the {records} records of "
                                            "the test file's units")
                if len(fields) != len(LABEL_COLUMNS):
                    raise inputs.InputError(f"{path}, row {line}: {len(fields)} fields; {len(LABEL_COLUMNS)} are "
                                            f"expected ({', '.join(LABEL_COLUMNS)})")
                unit, cycle, level, axis, fault = fields
                parsed = []
                for column, text, kind in (("cycle", cycle, int), ("fault_level_pct", level, float),
                                           ("worn_axis", axis, int)):
                    try:
                        value = kind(text)
                    except ValueError:
                        value = None
                    if value is None or (kind is float and not (np.isfinite(value) and 0 <= value <= MAX_FAULT_LEVEL)) \
                            or (kind is int and not 0 <= value <= MAX_CYCLE):
                        raise inputs.InputError(
                            f"{path}, row {line}: {column} {_short(text)}; expected "
                            + (f"a finite number within 0..{MAX_FAULT_LEVEL:g} (%)" if kind is float
                               else f"a whole number within 0..{MAX_CYCLE}"))
                    parsed.append(value)
                rows.setdefault(unit, []).append((*parsed, fault))
    except csv.Error as err:
        raise inputs.InputError(f"{path}, row {line + 1}: not a CSV row ({err})") from None
    except UnicodeDecodeError as err:
        raise inputs.InputError(f"{path}, after row {line}: not UTF-8 text ({err.reason}); the test labels are a "
                                "UTF-8 CSV file") from None
    out = []
    for unit in units:
        got = rows.get(unit.id)
        if not got or [c for c, *_ in got] != [int(c) for c in unit.arrays["cycles"]]:
            raise inputs.InputError(f"{path}: the labels of unit {unit.id} do not match its records in the test file")
        if len({(axis, fault) for _, _, axis, fault in got}) != 1:
            raise inputs.InputError(f"{path}: the rows of unit {unit.id} disagree on worn_axis or fault; one worn "
                                    "axis and fault per unit is expected")
        if got[0][2] > unit.n_axes:
            raise inputs.InputError(f"{path}: unit {unit.id} has worn_axis {got[0][2]}; its robot has "
                                    f"{unit.n_axes} axes (0: none)")
        out.append(Unit(id=unit.id, robot=unit.robot, task=unit.task, sample=unit.sample, arrays=unit.arrays,
                        fault_level=np.array([level for _, level, *_ in got]), worn_axis=got[0][2], fault=got[0][3]))
    return out
