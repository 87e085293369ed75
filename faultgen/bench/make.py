"""``faultgen bench make``: a track's train and test files, checked against its frozen manifest.

The parts of a track version (:mod:`faultgen.bench.tracks`) are swept (:func:`faultgen.run_sweep`)
with the train seeds and with the test seeds into a hidden folder beside the output, turned into
the benchmark files (:mod:`faultgen.bench.files`), and hashed: the manifest is the SHA-256 of every
array (its dtype, shape and bytes) and of every unit's attributes, and of ``test_labels.csv``. If
the track version has a frozen manifest (``faultgen/bench/manifests/<track>-<version>-<size>.json``,
shipped in the package), the new one must equal it; if not, nothing is written and the error names
the track and the first differing array. The output folder appears complete or not at all
(:func:`faultgen.data.atomic.atomic_folder`); the sweeps' runs are kept beside it
(``.<out>.<track>-<version>-<size>.sweeps``) until it is written, so that a make stopped by Ctrl-C
or a kill resumes from the runs it finished when run again, and are removed after a difference
from the frozen manifest too. A version's third-party robots (``[[versions.robots]]``) are added into
that folder first, and a part of kind ``logs`` is a fleet written there by the independent simulator
(:mod:`faultgen.bench.independent`) and imported as ``faultgen logs import`` does, its labels from the
simulator's truth; a part of kind ``records`` is a record-level fleet
(:mod:`faultgen.bench.prognostics_v3`), whose test split is also written in each other variant as
``test-<variant>.h5`` (hashed into the manifest beside ``test.h5``). A version with a numeric ``profile`` is made in it (:mod:`faultgen.bench.profile`),
and every manifest records the environment that made it (machine, BLAS kernels, NumPy's dispatch,
package versions), which a failed check compares with its own.
"""

from __future__ import annotations

import hashlib
import json
import shutil
from importlib import resources
from pathlib import Path

import numpy as np

import faultgen
from faultgen.bench import files, profile, prognostics_v3, tracks
from faultgen.data import atomic
from faultgen.runs.context import ExecutionContext

OUTPUTS = ("train.h5", "test.h5", "test_labels.csv", "manifest.json")
#: The most bytes an attribute of a unit may declare before :func:`hashes` reads it.
ATTRS_MAX_BYTES = 64 * 2**10


def manifest_path(track: str, version: int, size: str) -> Path:
    """Where the frozen manifest of a track version and size lives (in the package)."""
    return Path(str(resources.files("faultgen.bench") / "manifests")) / f"{track}-{version}-{size}.json"


def _array_hash(values: np.ndarray) -> str:
    values = np.ascontiguousarray(values)
    digest = hashlib.sha256(f"{values.dtype.str}{values.shape}".encode())
    digest.update(values.tobytes())
    return digest.hexdigest()


def hashes(folder: Path) -> dict[str, str]:
    """SHA-256 of every array and unit attribute set of ``train.h5`` and ``test.h5`` in ``folder``, and of
    ``test_labels.csv``: ``{"train.h5:/units/train-000/cycles": hex, ...}`` in a stable order."""
    import h5py

    from faultgen import inputs

    out = {}
    # a version with test variants (prognostics v3) has test-<variant>.h5 beside test.h5
    for name in ("train.h5", "test.h5", *sorted(p.name for p in folder.glob("test-*.h5"))):
        path = files.folder_file(folder / name, "benchmark file")
        with inputs.open_hdf5(path, "benchmark file of `faultgen bench make`") as f:  # nothing read from another file
            for uid in f["units"]:
                g = f["units"][uid]
                for key in g.attrs:  # declared sizes first: a unit's attributes are a few short texts and numbers
                    if h5py.h5a.open(g.id, key.encode()).get_storage_size() > ATTRS_MAX_BYTES:
                        raise inputs.InputError(f"{path}: unit {uid[:60]!r} attribute {key[:60]!r} declares more than "
                                                f"{ATTRS_MAX_BYTES} bytes; a unit's attributes are short")
                attrs = json.dumps({k: np.asarray(v).tolist() for k, v in sorted(g.attrs.items())}, sort_keys=True)
                out[f"{name}:/units/{uid}@attrs"] = hashlib.sha256(attrs.encode()).hexdigest()
                for array in sorted(g):
                    out[f"{name}:/units/{uid}/{array}"] = _array_hash(
                        inputs.bounded_dataset(g, array, path)[()])
    labels = files.folder_file(folder / "test_labels.csv", "test labels", files.LABELS_MAX_BYTES)
    out["test_labels.csv"] = hashlib.sha256(inputs.read_bytes(labels, "test labels", files.LABELS_MAX_BYTES)).hexdigest()
    return out


def _described(key: str, folder: Path, new: dict[str, str], frozen: dict[str, str]) -> str:
    """A manifest key as a file of ``folder`` and an array in it, and how it differs: "FOLDER/test.h5:
    array /units/test-003/cycles differs from", "... is missing against" or "... is not in"."""
    name, _, array = key.partition(":")
    where = f"{folder / name}" + (f": array {array}" if array else "")
    how = "is missing against" if key not in new else "is not in" if key not in frozen else "differs from"
    return f"{where} {how}"


def compare(folder: str | Path, made: dict, allow_modified: bool = False) -> dict:
    """Check a benchmark folder to be scored against its track version's frozen manifest (shipped in
    the package, never the folder's own ``manifest.json``): the SHA-256 of every array and unit
    attribute set of ``train.h5`` and ``test.h5`` and of ``test_labels.csv`` (:func:`hashes`).

    ``made``: the test file's attributes track, version and size (as
    :func:`faultgen.bench.files.read_with_attrs` read them, after the files were checked).

    Returns
    -------
    dict
        ``{"comparable": True}`` when every digest equals the frozen one; with ``allow_modified``,
        ``{"comparable": False, "modified": [up to 20 "FILE: array A differs from ..." lines],
        "modified_count": n}`` otherwise (no frozen manifest counts as one difference).

    Raises
    ------
    faultgen.inputs.InputError
        Without ``allow_modified``, when the track version and size have no frozen manifest or a
        digest differs: one line naming the file, the first differing array and how many differ.
    """
    from faultgen import inputs

    folder = Path(folder)
    track, version, size = made.get("track"), made.get("version"), made.get("size")
    known = track in tracks.names() and size in tracks.SIZES and isinstance(version, int)
    frozen_path = manifest_path(track, version, size) if known else None
    what = f"track {track!s:.60} version {version} ({size!s:.20})"
    if frozen_path is None or not frozen_path.is_file():
        lines = [f"{folder / 'test.h5'}: {what} has no frozen manifest in this faultgen"]
    else:
        frozen = json.loads(frozen_path.read_text())["arrays"]
        new = hashes(folder)
        lines = [f"{_described(k, folder, new, frozen)} the frozen manifest of {what}" for k in _differing(new, frozen)]
        if len(lines) > 1:
            lines[0] += f" ({len(lines)} of {len(frozen)} arrays differ)"
    if not lines:
        return {"comparable": True}
    if not allow_modified:
        raise inputs.InputError(f"{lines[0]}; its score would not be comparable with the track's (give "
                                "--allow-modified to score it anyway, marked not comparable)")
    return {"comparable": False, "modified": lines[:20], "modified_count": len(lines)}


def _differing(new: dict[str, str], frozen: dict[str, str]) -> list[str]:
    """The arrays (in the frozen manifest's order, then the new one's) whose hash differs or that are
    missing on one side."""
    keys = list(frozen) + [k for k in new if k not in frozen]
    return [k for k in keys if new.get(k) != frozen.get(k)]


def first_difference(new: dict[str, str], frozen: dict[str, str]) -> tuple[str, int] | None:
    """The first array (in the frozen manifest's order, then the new one's) whose hash differs or that
    is missing on one side, and how many differ; None if the two are equal."""
    differing = _differing(new, frozen)
    return (differing[0], len(differing)) if differing else None


def _unit(run) -> files.Unit:
    """A run of a sweep as a labelled benchmark unit (its id is given later)."""
    arrays = {name: run.array(name) for name in files.OBSERVABLES if run.has(name)}
    fault = "none" if not run.failing else "friction_wear" if run.fault is None else str(run.fault["effect"])
    unit = files.Unit(id="", robot=run.robot, task=run.task, sample=run.sample, arrays=arrays)
    unit.fault_level = np.asarray(run.fault_level, dtype=float)
    unit.worn_axis = int(run.worn_axes[0]) if run.worn_axes else 0
    unit.fault = fault
    return unit


def add_robots(version: tracks.Version, folder: Path) -> dict[str, Path]:
    """Add the version's third-party robots (``[[versions.robots]]``) under ``folder``, as ``faultgen
    robots add NAME --from FILE --package PKG=DIR`` does (with its generated tasks), with the version's
    sizing rule (``sizing``: rule 1 for the versions that name none); a robot already there is kept
    (adding is atomic; :func:`make` starts a sweeps folder afresh whose robots another rule sized).
    Returns name -> robot folder."""
    import warnings

    from faultgen.model import importers
    from faultgen.model.folder import add
    from faultgen.operation import taskgen

    out = {}
    for robot in version.robots:
        target = folder / robot["name"]
        if not target.is_dir():
            source = tracks.source_path(robot["from"])
            packages = {name: tracks.source_path(spec) for name, spec in dict(robot.get("packages", {})).items()}
            with warnings.catch_warnings():  # the meshes a robot leaves out (the command prints them)
                warnings.simplefilter("ignore", importers.GeometryDropped)
                add(robot["name"], source, target, tasks=taskgen.generate, packages=packages, rule=version.sizing)
        out[robot["name"]] = target
    return out


def _other_sizing(version: tracks.Version, folder: Path) -> list[str]:
    """The version's robots in ``folder`` (a sweeps folder's, left by an earlier make) that do not
    record the version's sizing rule: sized by another rule, or by a faultgen before the rules were
    recorded."""
    from faultgen.model.folder import sizing_rule

    return [robot["name"] for robot in version.robots
            if (folder / robot["name"]).is_dir() and sizing_rule(folder / robot["name"]) != version.sizing]


def _fleet_units(version: tracks.Version, split: str, size: str, sweeps: Path, added: dict[str, Path],
                 progress: bool) -> list[files.Unit]:
    """The units of the version's ``logs`` parts for ``split``: each fleet written by the independent
    simulator into ``sweeps`` (resuming), imported as ``faultgen logs import`` does (only new logs),
    and labelled from its truth.csv (wear %, worn axis); a fleet with friction tests gets their
    readings on its records (:mod:`faultgen.bench.friction_readings`; truth_tests.csv is never read)."""
    from faultgen.bench import friction_readings, independent
    from faultgen.data import fleetlogs
    from faultgen.model import robots

    units = []
    for part, fleet in version.fleets(split, size):
        folder = added[fleet["robot"]]
        spec = independent.FleetSpec(**{k: tuple(v) if isinstance(v, list) else v for k, v in fleet["spec"].items()})
        logs, truth_path = independent.write_fleet(sweeps / f"{split}-{part}", spec, folder)
        # the robot folder in the sweeps folder (added now or by an earlier make), read once per fleet with tests
        model = robots.load(folder) if spec.friction_test_every else None
        dataset = sweeps / f"{split}-{part}.h5"
        fleetlogs.import_logs(logs, dataset, robot=str(folder), progress=progress)
        truth = independent.read_truth(truth_path)
        with faultgen.open(dataset) as data:
            for run in data:
                unit = _unit(run)
                known = truth[run.id]  # an imported run's id is its unit's folder name
                if [s.decode() if isinstance(s, bytes) else str(s) for s in run.array("stamp")] != known["stamps"]:
                    raise ValueError(f"{dataset}: the logs of unit {run.id} differ from the stamps of its truth")
                unit.task = fleet["task"]  # the program every log of the fleet ran (the import says "measured")
                unit.fault_level = known["wear"].astype(float)
                unit.worn_axis = known["axis"]
                unit.fault = "friction_wear" if known["axis"] else "none"
                if spec.friction_test_every:  # the tests' readings on their days' records, never their truth
                    unit.arrays.update(friction_readings.arrays(logs / run.id / independent.TEST_FOLDER,
                                                                known["stamps"], model))
                units.append(unit)
    return units


def _split_units(version: tracks.Version, split: str, size: str, sweeps: Path, jobs: int, progress: bool,
                 command: str, added: dict[str, Path]) -> list[files.Unit]:
    """Sweep every part of ``version`` for ``split`` into ``sweeps`` (resuming finished runs) and read
    the runs as labelled units, in the parts' order and each sweep's run order; then the units of its
    ``logs`` parts (:func:`_fleet_units`). ``added``: the third-party robots' folders, by name."""
    runs = []
    for part, fields in version.grids(split, size):
        fields = dict(fields)
        preset = fields.pop("preset", None)
        if "robots" in fields:
            fields["robots"] = [str(added.get(r, r)) for r in fields["robots"]]
        grid = faultgen.Grid.from_preset(preset, **fields) if preset else faultgen.Grid(**fields)
        out = sweeps / f"{split}-{part}.h5"
        if not out.is_file():  # a sweep's file appears only when it is complete: one made before a stop is kept
            out = faultgen.run_sweep(grid, out, ExecutionContext(jobs), progress=progress, command=command)
        runs.append(out)
    units = []
    for path in runs:
        with faultgen.open(path) as data:
            units += [_unit(run) for run in data]
    return units + _fleet_units(version, split, size, sweeps, added, progress) + _record_units(
        version, split, size, (prognostics_v3.DEFAULT_VARIANT,))[prognostics_v3.DEFAULT_VARIANT]


def _record_units(version: tracks.Version, split: str, size: str, names: tuple[str, ...]) -> dict[str, list[files.Unit]]:
    """The units of the version's ``records`` parts for ``split`` (:mod:`faultgen.bench.prognostics_v3`)
    in each variant of ``names``: variant -> units (empty lists for a version without such parts)."""
    out: dict[str, list[files.Unit]] = {name: [] for name in names}
    for _, spec in version.records(split, size):
        for name, units in prognostics_v3.split_units(spec, names).items():
            out[name] += units
    return out


def _why(track: tracks.Track, recipe: tracks.Version, numeric: str, frozen: dict | None, here: dict) -> str:
    """What a difference from the frozen manifest says: the environments' differences where the frozen
    one is recorded, the processor's kernels for a version made before profiles or on a processor
    that cannot take its profile, else a faultgen change (a new version)."""
    new = max(track.versions) + 1
    change = (f"if this faultgen changed the track's data, add version {new} to faultgen/bench/tracks/{track.name}.toml "
              f"and freeze it (faultgen bench make {track.name} --version {new} --freeze)")
    if frozen:
        moved = [f"{k} {frozen.get(k)!r} -> {here.get(k)!r}" for k in ("machine", "blas", "numpy_dispatch")
                 if frozen.get(k) != here.get(k)]
        moved += [f"{name} {frozen['packages'].get(name)} -> {here['packages'].get(name)}"
                  for name in sorted(set(frozen.get("packages", {})) | set(here["packages"]))
                  if frozen.get("packages", {}).get(name) != here["packages"].get(name)]
        if moved:
            change = f"the environment differs from the one that froze it ({'; '.join(moved)}); or {change}"
    if recipe.profile is None:
        pinned = [n for n in sorted(track.versions) if track.versions[n].profile]
        change += (f"; version {recipe.number} was frozen before tracks pinned their numeric profile, so its bits also "
                   "depend on the processor's BLAS and NumPy kernels"
                   + (f": make version {pinned[-1]}" if pinned else ""))
    elif numeric == "unsupported":
        change += f"; this processor cannot take the version's numeric profile {recipe.profile} (faultgen.bench.profile)"
    return change


def _order(track: str, version: int, n: int) -> np.ndarray:
    """The test units' seeded order: a permutation from the track's name and version."""
    seed = int.from_bytes(hashlib.sha256(f"{track}-{version}".encode()).digest()[:8], "little")
    return np.random.default_rng(seed).permutation(n)


def _check_request(track: tracks.Track, recipe: tracks.Version, size: str, out: Path, jobs: int,
                   freeze: bool) -> tuple[str, Path]:
    """Check :func:`make`'s request before any work: return (the numeric profile this process runs,
    :func:`faultgen.bench.profile.check`; the path of the version's frozen manifest).

    Raises
    ------
    ValueError
        For an unknown size, an ``out`` whose folder does not exist or that is a file, ``jobs`` not a
        whole number >= 1, a process that cannot be pinned to the version's profile, a version frozen
        already when ``freeze``, or a track with fleets and no Pinocchio.
    """
    if size not in tracks.SIZES:
        raise ValueError(f"--size {size!r}: expected one of {', '.join(tracks.SIZES)}")
    if not (out.parent if str(out.parent) else Path(".")).is_dir():
        raise ValueError(f"-o {out}: folder {out.parent} does not exist")
    if out.exists() and not out.is_dir():
        raise ValueError(f"-o {out} is a file; give a folder")
    if isinstance(jobs, bool) or not isinstance(jobs, int) or jobs < 1:
        raise ValueError(f"--jobs {jobs!r}: expected a whole number >= 1")
    numeric = profile.check(recipe.profile)  # before any work: a process that cannot be pinned any more is refused
    frozen_path = manifest_path(track.name, recipe.number, size)
    if freeze and frozen_path.exists():
        raise ValueError(f"track {track.name} version {recipe.number} ({size}) is frozen already ({frozen_path}); "
                         "a new recipe is a new version")
    if any(recipe.fleets(split, size) for split in tracks.SPLITS):
        from faultgen.bench import independent

        try:
            independent.pinocchio_module()
        except ImportError as err:  # before any sweep; the command line reports a ValueError in one line
            raise ValueError(f"track {track.name} version {recipe.number}: {err}") from None
    return numeric, frozen_path


def _write_splits(stage: Path, track: tracks.Track, recipe: tracks.Version, size: str, command: str,
                  train: list[files.Unit], test: list[files.Unit], variants: dict | None = None) -> None:
    """Write ``train.h5``, ``test_labels.csv`` and ``test.h5`` (without labels) into ``stage``: the units
    numbered, the test units in the version's shuffled order (:func:`_order`); each of ``variants``
    (name -> the same test units seen otherwise, in the same order) as ``test-<name>.h5``."""
    for k, unit in enumerate(train):
        unit.id = f"train-{k:03d}"
    order = _order(track.name, recipe.number, len(test))
    test = [test[i] for i in order]
    for k, unit in enumerate(test):
        unit.id = f"test-{k:03d}"
    attrs = {"track": track.name, "version": recipe.number, "size": size, "licence": track.licence,
             "faultgen_version": faultgen.__version__, "command": command}
    files.write(stage / "train.h5", train, {**attrs, "split": "train"})
    files.write_labels(stage / "test_labels.csv", test)
    for unit in test:  # the test file holds no label
        unit.fault_level = unit.worn_axis = unit.fault = None
    files.write(stage / "test.h5", test, {**attrs, "split": "test"})
    for name, units in (variants or {}).items():
        seen = [units[i] for i in order]
        for k, unit in enumerate(seen):
            unit.id, unit.fault_level, unit.worn_axis, unit.fault = f"test-{k:03d}", None, None, None
        files.write(stage / f"test-{name}.h5", seen, {**attrs, "split": "test", "variant": name})


def make(track_name: str, out: str | Path, version: int | None = None, size: str = "full", jobs: int = 1,
         progress: bool = True, command: str = "", freeze: bool = False) -> dict:
    """Make the benchmark files of a track version in the folder ``out`` and check them.

    Parameters
    ----------
    track_name : str
        A track (:func:`faultgen.bench.tracks.names`).
    out : path
        The folder to write (``train.h5``, ``test.h5``, ``test_labels.csv``, ``manifest.json``); its
        parent must exist. Files of those names in it are replaced.
    version : int or None
        The track version (None: the latest).
    size : {"full", "small"}
        ``small``: the test-sized version (seconds).
    jobs : int
        Worker processes of the sweeps.
    freeze : bool
        Write the manifest as the track version's frozen one (into the package) when it has none;
        refused when it has one.

    Returns
    -------
    dict
        The manifest: track, version, size, faultgen_version, licence, profile (the version's numeric
        profile or None), environment (:func:`faultgen.bench.profile.describe`), status ("checked" or
        "frozen" or "unfrozen": no frozen manifest to check against), and ``arrays`` (name -> SHA-256).

    Raises
    ------
    ValueError
        For an unknown track, version or size, a slot, a folder that cannot be written, a version with
        a numeric profile in a process started without it (:func:`faultgen.bench.profile.check`), or
        data that differs from the frozen manifest (naming the track, the first differing array and
        what differs from the environment that froze it; nothing is written).
    """
    track = tracks.load(track_name)
    recipe = track.version(version)
    out = Path(out)
    numeric, frozen_path = _check_request(track, recipe, size, out, jobs, freeze)
    # the sweeps' runs live beside the output until it is written: a make stopped by Ctrl-C or a kill
    # resumes from the runs it finished when run again (the sweep's own resume)
    sweeps = (out.parent if str(out.parent) else Path(".")) / f".{out.name}.{track.name}-{recipe.number}-{size}.sweeps"
    if _other_sizing(recipe, sweeps / "robots"):  # runs of robots another sizing rule made are not resumed
        shutil.rmtree(sweeps)
    sweeps.mkdir(exist_ok=True)
    with atomic.atomic_folder(out) as stage:
        added = add_robots(recipe, sweeps / "robots")
        train = _split_units(recipe, "train", size, sweeps, jobs, progress, command, added)
        test = _split_units(recipe, "test", size, sweeps, jobs, progress, command, added)
        others = tuple(n for n in prognostics_v3.VARIANTS if n != prognostics_v3.DEFAULT_VARIANT)
        variants = {name: units for name, units in _record_units(recipe, "test", size, others).items() if units}
        _write_splits(stage, track, recipe, size, command, train, test, variants)
        arrays = hashes(stage)
        manifest = {"track": track.name, "version": recipe.number, "size": size, "faultgen_version": faultgen.__version__,
                    "licence": track.licence, "profile": recipe.profile, "environment": profile.describe(),
                    "arrays": arrays}
        if frozen_path.exists():
            frozen = json.loads(frozen_path.read_text())
            differs = first_difference(arrays, frozen["arrays"])
            if differs:
                key, n = differs
                shutil.rmtree(sweeps, ignore_errors=True)  # the same code would give the same runs again
                raise ValueError(
                    f"track {track.name} version {recipe.number} ({size}): the data differs from the frozen manifest "
                    f"at {key} ({n} of {len(frozen['arrays'])} arrays differ): "
                    f"{_why(track, recipe, numeric, frozen.get('environment'), manifest['environment'])}; "
                    "nothing written")
            manifest["status"] = "checked"
        elif freeze:
            atomic.write_text(frozen_path, json.dumps({**manifest, "status": "frozen"}, indent=1) + "\n")
            manifest["status"] = "frozen"
        else:
            manifest["status"] = "unfrozen"
        atomic.write_text(stage / "manifest.json", json.dumps(manifest, indent=1) + "\n")
    shutil.rmtree(sweeps, ignore_errors=True)
    return manifest
