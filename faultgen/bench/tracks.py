"""Benchmark tracks: versioned recipes (robots, programs, seeds, conditions) for seeded train and test sets.

A track is one TOML file in ``faultgen/bench/tracks/`` holding every version ever released
(``[[versions]]``): a version's recipe never changes once its manifest is frozen
(``faultgen/bench/manifests/<track>-<version>-<size>.json``); a change of the recipe, or of
faultgen, that alters the data is a new version. Each version is one or more *parts*, each a sweep
grid (:class:`faultgen.Grid` fields, ``preset`` allowed) made twice: with the train seeds and with
the test seeds, which must be disjoint (so are the units: a unit is a robot with its own seed, its
own noise and, with ``spread``, its own friction). ``[versions.small]`` holds the overrides of the
test-sized version (``--size small``), made in seconds for tests and examples; a part's own ``small``
table overrides it for that part.

A part of kind ``logs`` (``kind = "logs"``) is not a sweep: it is a fleet's measured logs made by the
independent simulator (:mod:`faultgen.bench.independent`, Pinocchio) for the robot ``robot`` doing
``task``, one fleet per seed of its split (``fleet``: :class:`~faultgen.bench.independent.FleetSpec`
fields), read with ``faultgen logs import`` (:func:`faultgen.data.fleetlogs.import_logs`); its
``small`` overrides ``fleet``. A version's ``[[versions.robots]]`` are robots added from a
third-party file as a user adds them (``faultgen robots add NAME --from FILE --package PKG=DIR``):
``name``, ``from`` and ``packages``, each file given as ``python_package:path/inside`` (an installed
data package such as rtb-data's ``rtbdata``); a part names them as any robot.

A part of kind ``records`` (``kind = "records"``) is a fleet's daily records drawn at the record
level (:mod:`faultgen.bench.prognostics_v3`, the prognostics track's version 3), one fleet per seed of
its split (``records``: ``failing`` and optionally ``days``, ``onset``, ``life_days``; ``small``
overrides it); its test split is written in every variant of that module's ``VARIANTS``.

A version may name the numeric ``profile`` it is made in (:mod:`faultgen.bench.profile`: the same
bits on two machines), and may be ``like`` an earlier version: its recipe (parts, seeds, small,
robots, sizing) with the version's own keys over it. A version's ``sizing`` is the drivetrain sizing
rule its third-party robots are added with (:data:`faultgen.model.sizing.RULE_VERSIONS`); a version
that names none uses rule 1, the rule of every version frozen before the rules were versioned (rule 2,
``robots add``'s default since, changes their robots' drives and so their data).

A track without ``versions`` is a slot: listed, with what it still needs (``needs``).
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path

from faultgen.bench import profile

SIZES = ("full", "small")
SPLITS = ("train", "test")

#: The keys of a track file and of a version (anything else is refused, named).
_TRACK_KEYS = {"name", "summary", "licence", "card", "needs", "versions"}
_VERSION_KEYS = {"version", "released", "notes", "parts", "train_seeds", "test_seeds", "small", "robots", "profile",
                 "like", "sizing"}
#: The keys a version takes from the version it is ``like``.
_RECIPE_KEYS = ("parts", "train_seeds", "test_seeds", "small", "robots", "sizing")
#: The sizing rule of a version that names none: the rule every version frozen before ``sizing`` was
#: a key was made with (module docstring).
DEFAULT_SIZING = 1
#: The sizing rules' numbers: those of :data:`faultgen.model.sizing.RULE_VERSIONS` (not imported here:
#: it loads NumPy, which a profiled make must load only after its profile is set).
SIZING_RULES = (1, 2)
_ROBOT_KEYS = {"name", "from", "packages"}
_LOGS_KEYS = {"name", "kind", "robot", "task", "fleet", "small", "train_seeds", "test_seeds"}
_RECORDS_KEYS = {"name", "kind", "records", "small", "train_seeds", "test_seeds"}
#: Keys of a part that are not :class:`faultgen.Grid` fields.
_PART_KEYS = ("name", "kind", "small", "train_seeds", "test_seeds")


@dataclass(frozen=True)
class Version:
    """One frozen recipe of a track.

    Attributes
    ----------
    number : int
        1, 2, ...
    parts : list of dict
        Each a table of :class:`faultgen.Grid` fields (``name`` beside them names the part).
    train_seeds, test_seeds : list of int
        Disjoint unit seeds of the two splits (a part may give its own ``train_seeds`` / ``test_seeds``).
    small : dict
        Grid-field overrides of every part for ``--size small``.
    notes : str
    robots : list of dict
        Robots added from a third-party file (``name``, ``from``, ``packages``; module docstring).
    profile : str or None
        The numeric profile the version is made in (:mod:`faultgen.bench.profile`), None for the
        versions frozen before profiles (their bits depend on the processor's kernels).
    sizing : int
        The drivetrain sizing rule its ``robots`` are added with
        (:data:`faultgen.model.sizing.RULE_VERSIONS`; :data:`DEFAULT_SIZING` when the version names none).
    """

    number: int
    parts: list[dict]
    train_seeds: list[int]
    test_seeds: list[int]
    small: dict = field(default_factory=dict)
    notes: str = ""
    robots: list[dict] = field(default_factory=list)
    profile: str | None = None
    sizing: int = DEFAULT_SIZING

    def _seeds(self, part: dict, split: str) -> list[int]:
        return list(part.get(f"{split}_seeds", getattr(self, f"{split}_seeds")))

    def grids(self, split: str, size: str = "full") -> list[tuple[str, dict]]:
        """(part name, grid fields) of each part for ``split`` ("train" or "test") at ``size``."""
        if split not in SPLITS:
            raise ValueError(f"split {split!r}: expected one of {', '.join(SPLITS)}")
        if size not in SIZES:
            raise ValueError(f"size {size!r}: expected one of {', '.join(SIZES)}")
        out = []
        for k, part in enumerate(self.parts):
            if part.get("kind", "grid") != "grid":
                continue
            fields = {key: value for key, value in part.items() if key not in _PART_KEYS}
            fields["seeds"] = self._seeds(part, split)
            if not fields["seeds"]:  # a part of one split only (the transfer track's nominal unit)
                continue
            fields["signals"] = False  # features only: the benchmark scores per-cycle features
            if size == "small":
                fields.update(self.small)
                fields.update(part.get("small", {}))
            out.append((str(part.get("name", f"part{k + 1}")), fields))
        return out

    def _per_seed(self, kind: str, table: str, split: str, size: str) -> list[tuple[str, dict, dict]]:
        """(part name and seed, the part, its ``table`` with its ``small`` over it at ``size`` and the seed) of
        each part of ``kind``, one per seed of ``split``; raises ``ValueError`` for an unknown split or size."""
        if split not in SPLITS or size not in SIZES:
            raise ValueError(f"split {split!r}, size {size!r}: expected one of {', '.join(SPLITS)} and of "
                             f"{', '.join(SIZES)}")
        return [(f"{part.get('name', f'part{k + 1}')}-{seed}", part,
                 {**part.get(table, {}), **(part.get("small", {}) if size == "small" else {}), "seed": seed})
                for k, part in enumerate(self.parts) if part.get("kind", "grid") == kind
                for seed in self._seeds(part, split)]

    def fleets(self, split: str, size: str = "full") -> list[tuple[str, dict]]:
        """(part name, fleet) of each part of kind ``logs`` for ``split`` at ``size``, one per seed:
        ``{"robot", "task", "spec"}``, ``spec`` the :class:`~faultgen.bench.independent.FleetSpec`
        fields with the seed."""
        return [(name, {"robot": part["robot"], "task": part["task"], "spec": spec})
                for name, part, spec in self._per_seed("logs", "fleet", split, size)]

    def records(self, split: str, size: str = "full") -> list[tuple[str, dict]]:
        """(part name, spec) of each part of kind ``records`` for ``split`` at ``size``, one per seed:
        the part's ``records`` table (its ``small`` over it) with the seed
        (:func:`faultgen.bench.prognostics_v3.split_units`)."""
        return [(name, spec) for name, _, spec in self._per_seed("records", "records", split, size)]


@dataclass(frozen=True)
class Track:
    """A benchmark track: its name, what it asks, the licence of its data, and its versions.

    Attributes
    ----------
    name, summary, licence : str
    card : str
        The dataset card's file in docs/bench/ (what the data is and is not).
    needs : str
        For a slot without versions: what it still needs.
    versions : dict of int to Version
    """

    name: str
    summary: str
    licence: str
    card: str = ""
    needs: str = ""
    versions: dict[int, Version] = field(default_factory=dict)

    @property
    def latest(self) -> int | None:
        return max(self.versions) if self.versions else None

    def version(self, number: int | None = None) -> Version:
        """Version ``number`` (None: the latest).

        Raises
        ------
        ValueError
            For a slot (no version yet: the message says what it needs) or an unknown number.
        """
        if not self.versions:
            raise ValueError(f"track {self.name!r} has no version yet: {self.needs}")
        number = self.latest if number is None else number
        if number not in self.versions:
            raise ValueError(f"track {self.name!r} has no version {number}; versions: "
                             f"{', '.join(map(str, sorted(self.versions)))}")
        return self.versions[number]


def _folder() -> Path:
    return Path(str(resources.files("faultgen.bench") / "tracks"))


def parse(data: dict, source: str) -> Track:
    """A :class:`Track` from the table of a track file (``source`` names it in errors).

    Raises
    ------
    ValueError
        Naming the file and the first unknown key, missing field, or train and test seeds that overlap.
    """
    unknown = sorted(set(data) - _TRACK_KEYS)
    if unknown:
        raise ValueError(f"{source}: unknown key {unknown[0]!r}; expected: {', '.join(sorted(_TRACK_KEYS))}")
    for key in ("name", "summary", "licence"):
        if not isinstance(data.get(key), str) or not data[key]:
            raise ValueError(f"{source}: {key!r} must be a non-empty string")
    versions, raw = {}, {}
    for entry in data.get("versions", []):
        bad = sorted(set(entry) - _VERSION_KEYS)
        if bad:
            raise ValueError(f"{source}: version {entry.get('version')}: unknown key {bad[0]!r}; expected: "
                             f"{', '.join(sorted(_VERSION_KEYS))}")
        number = entry.get("version")
        if not isinstance(number, int) or isinstance(number, bool) or number < 1 or number in versions:
            raise ValueError(f"{source}: version {number!r}: expected a new whole number >= 1")
        if "like" in entry:  # the recipe of an earlier version, with this entry's own keys over it
            if entry["like"] not in raw:
                raise ValueError(f"{source}: version {number}: like = {entry['like']!r}: expected an earlier version "
                                 f"of this file ({', '.join(map(str, raw)) or 'none'})")
            entry = {**{k: v for k, v in raw[entry["like"]].items() if k in _RECIPE_KEYS}, **entry}
        raw[number] = entry
        try:
            profile.unknown(entry.get("profile"))
        except ValueError as err:
            raise ValueError(f"{source}: version {number}: {err}") from None
        rule = entry.get("sizing", DEFAULT_SIZING)
        if isinstance(rule, bool) or not isinstance(rule, int) or rule not in SIZING_RULES:
            raise ValueError(f"{source}: version {number}: sizing = {rule!r}: expected one of "
                             f"{', '.join(map(str, SIZING_RULES))} (faultgen.model.sizing.RULE_VERSIONS)")
        version = Version(number=number, parts=list(entry.get("parts", [])), train_seeds=list(entry["train_seeds"]),
                          test_seeds=list(entry["test_seeds"]), small=dict(entry.get("small", {})),
                          notes=str(entry.get("notes", "")), robots=list(entry.get("robots", [])),
                          profile=entry.get("profile"), sizing=rule)
        if not version.parts:
            raise ValueError(f"{source}: version {number}: no [[versions.parts]]")
        _check_robots_and_logs(version, f"{source}: version {number}")
        seeds = {split: {s for _, grid in version.grids(split) for s in grid["seeds"]}
                 | {fleet["spec"]["seed"] for _, fleet in version.fleets(split)}
                 | {spec["seed"] for _, spec in version.records(split)} for split in SPLITS}
        shared = sorted(seeds["train"] & seeds["test"])
        if shared or not seeds["train"] or not seeds["test"]:
            raise ValueError(f"{source}: version {number}: train seeds {sorted(seeds['train'])} and test seeds "
                             f"{sorted(seeds['test'])}: each split needs seeds, and no seed (unit) may be in both")
        versions[number] = version
    return Track(name=data["name"], summary=data["summary"], licence=data["licence"], card=data.get("card", ""),
                 needs=data.get("needs", ""), versions=versions)


def _check_robots_and_logs(version: Version, where: str) -> None:
    """Refuse a malformed ``[[versions.robots]]`` entry or part of kind ``logs`` (naming it)."""
    added = set()
    for robot in version.robots:
        bad = sorted(set(robot) - _ROBOT_KEYS)
        if bad or not isinstance(robot.get("name"), str) or not isinstance(robot.get("from"), str):
            raise ValueError(f"{where}: robot {robot!r}: expected a table of name and from (and packages)")
        for spec in (robot["from"], *dict(robot.get("packages", {})).values()):
            if ":" not in spec:
                raise ValueError(f"{where}: robot {robot['name']!r}: {spec!r}: expected python_package:path/inside")
        added.add(robot["name"])
    for part in version.parts:
        kind = part.get("kind", "grid")
        if kind not in ("grid", "logs", "records"):
            raise ValueError(f"{where}: part {part.get('name')!r}: kind {kind!r}: expected grid, logs or records")
        if kind == "records":
            bad = sorted(set(part) - _RECORDS_KEYS)
            if bad or not isinstance(part.get("records"), dict):
                raise ValueError(f"{where}: records part {part.get('name')!r}: "
                                 + (f"unknown key {bad[0]!r}; expected: {', '.join(sorted(_RECORDS_KEYS))}" if bad
                                    else "expected a records table (failing, and days, onset, life_days)"))
            continue
        if kind != "logs":
            continue
        bad = sorted(set(part) - _LOGS_KEYS)
        if bad:
            raise ValueError(f"{where}: logs part {part.get('name')!r}: unknown key {bad[0]!r}; expected: "
                             f"{', '.join(sorted(_LOGS_KEYS))}")
        if part.get("robot") not in added or not isinstance(part.get("task"), str):
            raise ValueError(f"{where}: logs part {part.get('name')!r}: robot {part.get('robot')!r} must be one of "
                             f"the version's [[versions.robots]] ({', '.join(sorted(added)) or 'none'}), and task a name")


def source_path(spec: str) -> Path:
    """The file or folder ``python_package:path/inside`` of an installed data package (rtb-data's
    ``rtbdata:xacro/...``), found without importing the package.

    Raises
    ------
    ValueError
        If the package is not installed or has no such path (naming both, and the extra that installs it).
    """
    from importlib.util import find_spec

    package, _, inside = spec.partition(":")
    found = find_spec(package) if package.isidentifier() else None
    if found is None or not found.submodule_search_locations:
        raise ValueError(f"{spec}: the data package {package!r} is not installed; it comes with the bench extra: "
                         "pip install 'faultgen-robots[bench]'")
    path = Path(list(found.submodule_search_locations)[0]) / inside
    if not path.exists():
        raise ValueError(f"{spec}: {path} does not exist in the installed {package!r}")
    return path


def load(name: str) -> Track:
    """The track ``name`` (``faultgen bench list`` lists them).

    Raises
    ------
    ValueError
        For an unknown name (the message lists the tracks), or a malformed track file.
    """
    path = _folder() / f"{name}.toml"
    if not name.replace("-", "").replace("_", "").isalnum() or not path.is_file():
        raise ValueError(f"unknown track {name!r}; expected one of: {', '.join(names())} (faultgen bench list)")
    with path.open("rb") as f:
        return parse(tomllib.load(f), str(path))


#: The order tracks are listed in (any other track file follows, by name).
ORDER = ("thesis", "faults", "conditions", "transfer", "sim-to-real")


def names() -> list[str]:
    """Every track's name, in :data:`ORDER`."""
    found = sorted(p.stem for p in _folder().glob("*.toml"))
    return [n for n in ORDER if n in found] + [n for n in found if n not in ORDER]
