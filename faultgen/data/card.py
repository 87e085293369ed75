"""A dataset card: what a faultgen dataset holds and what its numbers mean, as Markdown.

``faultgen info FILE --card`` prints it. Built from the file (labels, the command, the version
that wrote it, what each run stored of its robot: friction, gear ratios, torque limits, joint ranges
and speed limits, :mod:`faultgen.data.robot_record`) and the schema tables of
:mod:`faultgen.data.schema`, so it cannot drift from what is stored, and needs no robot's files
(a file written before runs stored them: :attr:`faultgen.data.reader.Run.limits`).
"""

from __future__ import annotations

import platform
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path

import numpy as np

from faultgen import __version__
from faultgen.data import reader, schema
from faultgen.simulation import sensors

#: The wear level the card explains in physical terms when the dataset has no friction wear; a
#: dataset with wear is explained at its largest (a fleet's 50 %, a quick sweep's 20 %).
EXAMPLE_WEAR = 20.0


def _version(name: str) -> str:
    try:
        return version(name)
    except PackageNotFoundError:
        return "not installed"


def _row(cells) -> str:
    return "| " + " | ".join(str(c) for c in cells) + " |"


def _table(head, rows) -> list[str]:
    return [_row(head), "|" + " --- |" * len(head), *(_row(r) for r in rows)]


def card(path: str | Path) -> str:
    """The card of the dataset at ``path``, Markdown: contents, what its largest wear (else
    ``EXAMPLE_WEAR`` %) means
    physically per robot and axis, label definitions, units of every stored array, histogram bin
    edges, the command that wrote it and the versions.

    Raises
    ------
    faultgen.data.schema.DatasetError
        If ``path`` is not a finished faultgen dataset.
    ValueError
        For a file written before its runs stored their drivetrain or limits whose robot cannot be
        loaded on this machine (:attr:`faultgen.data.reader.Run.limits`).
    """
    with reader.open(path) as data:
        runs = data.runs
        names = sorted({name for run in runs for name in run.names})
        kind, command, written_by = data.kind, data.command, data.faultgen_version
        shas = {run.robot: run.provenance["model_sha256"] for run in runs}
        largest = max((float(run.wear.max()) for run in runs), default=0.0)
        labels = {run.id: run.array("label") for run in runs if run.measured}
    wear_pct = round(largest, 1) if largest > 0.05 else EXAMPLE_WEAR
    robot_names = sorted({r.robot for r in runs})
    first = {}  # each robot's and each (robot, task)'s first run: what it stored of the robot
    for run in runs:
        first.setdefault(run.robot, run)
        if not run.measured:
            first.setdefault((run.robot, run.task), run)
    pairs = sorted({(r.robot, r.task) for r in runs if not r.measured})
    measured_robots = sorted({r.robot for r in runs if r.measured})
    imported = all(r.measured for r in runs)  # only logs: no wear is measured, labels come from events
    lines = [f"# Dataset card: {Path(path).name}", "",
             f"A faultgen {kind}: {len(runs)} run(s) ({sum(r.failing for r in runs)} "
             + ("with a log labelled worn" if imported else "with wear or a fault") + "), robots "
             f"{', '.join(robot_names)}, tasks {', '.join(sorted({r.task for r in runs}))}; a sample is "
             + ("a log's record (the largest of its cycles' features, as a simulated day's)"
                if any(r.sample == "log" for r in runs)
                else "a day's record (the day's maximum of its cycles)" if any(r.sample == "day" for r in runs)
                else "one recorded cycle") + ".", ""]

    if imported:
        lines += _imported_labels(runs, labels)
        lines += _arrays_and_edges(names, robot_names, pairs, measured_robots, imported, first)
        lines += _provenance(path, command, written_by, shas)
        return "\n".join(lines)

    lines += _wear_meaning(wear_pct, largest, robot_names, first)
    lines += _labels(measured_robots)
    lines += _arrays_and_edges(names, robot_names, pairs, measured_robots, imported, first)
    lines += _provenance(path, command, written_by, shas)
    return "\n".join(lines)


def _wear_meaning(wear_pct: float, largest: float, robot_names: list[str], first: dict) -> list[str]:
    """The card's section on what ``wear_pct`` % wear means (``largest``: the dataset's largest wear, %):
    per robot (its ``first`` run's drivetrain) and axis, the Coulomb friction new and its increase."""
    lines = [f"## What {wear_pct:g} % wear means", "",
             (f"{wear_pct:g} % is the largest wear in this dataset. " if largest > 0.05 else
              f"This dataset has no friction wear; {wear_pct:g} % as an example. ")
             + f"Wear multiplies an axis's Coulomb and static friction: {wear_pct:g} % wear is "
             f"{1 + wear_pct / 100:g} times the new gearbox's (`friction_multiplier` "
             f"{1 + wear_pct / 100:g}; wear_pct = (friction_multiplier - 1) x 100). Viscous friction is "
             "unchanged. Per axis, the Coulomb friction (positive direction) new and its increase, at the motor "
             "and at the arm joint (times the gear ratio), the model's nominal values (with a unit spread, "
             "`dry_friction_factor` scales each unit's):", ""]
    rows = []
    for name in robot_names:
        drive = first[name].drivetrain
        for a in range(len(drive.gear_ratio)):
            coulomb = float(drive.friction["coulomb_pos"][a])
            rise = coulomb * wear_pct / 100
            rows.append([name, a + 1, f"{coulomb:.3g}", f"+{rise:.3g}", f"{drive.gear_ratio[a]:.4g}",
                         f"+{rise * drive.gear_ratio[a]:.3g}",
                         f"{100 * rise / float(drive.motor_torque_limit[a]):.2g}"])
    lines += _table(["robot", "axis", "Coulomb new, N m (motor)", f"+{wear_pct:g} %, N m (motor)", "gear ratio",
                     f"+{wear_pct:g} %, N m (arm)", "% of peak motor torque"], rows)
    return lines


def _labels(measured_robots: list[str]) -> list[str]:
    """The card's section on the labels (with the imported units' when ``measured_robots``)."""
    return ["", "## Labels", "",
           "- `worn_axes`: axes (1-based) that wear or carry the fault; none: a healthy run (a normal robot).",
           "- `wear_pct` / `Run.wear`: true wear of each axis per sample, % (above); `Run.fault_level`: the "
           "fault's growth, % (friction wear: the worn axis's wear; another fault: its parameter's share of "
           "its final change).",
           "- `Run.fault_begins`: the first sample with the fault above 0; alarms before it are false alarms.",
           "- `fault`: a fault other than friction wear (effect, parameter, axis, start, final).",
           "- `seed`: the unit (noise and draws); in a fleet each robot has its own.",
           "- `conditions`: operating conditions (temperature, parts, task mix, unit spread), when on.",
           *(["- units imported from measured logs (`faultgen logs import`, task `measured`): no true wear is "
              "measured; `label` per log and axis is 1 worn, 0 healthy, -1 unknown, from the logs' events, and "
              "`friction_multiplier` holds it as a wear (2 on worn logs, 1 elsewhere)."] if measured_robots else []),
           ""]


#: What an imported dataset's arrays hold where the schema speaks of a simulation.
IMPORTED_ARRAYS = {
    "friction_multiplier": ("1", "cycle, axis", "the log's label as a number (2 labelled worn by events.csv, 1 "
                                                "healthy or unknown): a mark, not a measured friction"),
    "t": ("s", "sample", "empty: the logs' signals are not stored"),
    "q_ref": ("rad", "sample, axis", "empty: the logs' signals are not stored"),
    "cycles": ("1", "cycle", "1-based index of each log record, in stamp order"),
}


def _imported_labels(runs, labels: dict) -> list[str]:
    """The card's label section of a dataset imported from logs: what its labels are (``labels``:
    each run's ``label`` array) and how many."""
    from faultgen.data import logfolder

    worn = healthy = unknown = 0
    for label in labels.values():
        is_worn, is_healthy = np.any(label == logfolder.WORN, axis=1), np.all(label == logfolder.HEALTHY, axis=1)
        worn, healthy = worn + int(is_worn.sum()), healthy + int(is_healthy.sum())
        unknown += int(len(label) - is_worn.sum() - is_healthy.sum())
    units = [r.id for r in runs if r.worn_axes]
    return ["## Labels", "",
            "Units imported from measured logs (`faultgen logs import`, task `measured`): one run per unit, one "
            "record per log in stamp order. Nothing here is simulated and no wear is measured: what a log is, worn, "
            "healthy or unknown, comes from the events of the logs folder's `events.csv` (`onset`, `failure`, "
            "`repair`, `gearbox_change`, `healthy`; docs/dataset.md, \"A fleet's logs\").", "",
            f"- logs: {worn} worn (in {len(units)} unit(s){': ' + ', '.join(units[:8]) if units else ''}"
            f"{', ...' if len(units) > 8 else ''}), {healthy} healthy, {unknown} unknown (no event covers them).",
            "- `label`: per log and axis, 1 worn, 0 healthy, -1 unknown.",
            "- `worn_axes`: the axes with a log labelled worn; none: no log of the unit is labelled worn (healthy "
            "or unknown).",
            "- `friction_multiplier`: the label as a number the analyses read (2 on worn logs, 1 elsewhere), not a "
            "measured friction.",
            "- `stamp`, `log_file`, `log_cycles`, `log_duration`: each record's log, its cycles and duration.",
            "- `seed`: a number derived from the unit's name (the analyses' unit key).",
            "- next: label more logs in `events.csv` and import again, or run `faultgen monitor` on the logs "
            "folder, which needs no labels.", ""]


def _arrays_and_edges(names, robot_names, pairs, measured_robots, imported, first) -> list[str]:
    """The card's arrays with their units, and the histograms' bin edges (``first``: a robot name, or
    a (robot, task) pair, -> its first run, whose stored limits and drivetrain give the edges)."""
    lines = ["## Arrays and units", ""]
    rows = [[name, *(IMPORTED_ARRAYS.get(name) if imported and name in IMPORTED_ARRAYS else reader.SCHEMA[name])]
            for name in names if name in reader.SCHEMA]
    lines += _table(["array", "units", "axes", "description"], rows)

    lines += ["", "## Histogram bin edges", "",
              f"Each histogram has {sensors.HISTOGRAM_BINS} equal bins; values are fractions of the samples of the "
              "cycle (a day's record: of its maximum cycle). Edges per axis, lowest to highest:", ""]
    rows = []
    for name in robot_names:
        low, high = first[name].limits.joint_range[:, 0], first[name].limits.joint_range[:, 1]
        rows.append([name, "", "angle_hist", "rad", "joint range: " + "; ".join(
            f"{lo:.3g}..{hi:.3g}" for lo, hi in zip(low, high, strict=True))])
        rows.append([name, "", "torque_hist", "N m (motor)", "0..peak motor torque: " + "; ".join(
            f"0..{t:.3g}" for t in first[name].drivetrain.motor_torque_limit)])
    for name, task in pairs:
        limit = first[name, task].limits.task_velocity
        rows.append([name, task, "speed_hist", "rad/s (arm)", "0..the task's speed limit: " + "; ".join(
            f"0..{v:.3g}" for v in limit)])
    for name in measured_robots:
        limit = first[name].limits.velocity
        rows.append([name, schema.MEASURED, "speed_hist", "rad/s (arm)", "0..the robot's speed limit (tasks.toml "
                     "[limits], as its thesis tasks): " + "; ".join(f"0..{v:.3g}" for v in limit)])
    lines += _table(["robot", "task", "histogram", "units", f"range per axis 1..N, split in {sensors.HISTOGRAM_BINS}"],
                    rows)
    return lines


def _provenance(path, command, written_by, shas) -> list[str]:
    """The card's provenance and versions."""
    return ["", "## Provenance and versions", "",
              f"- command: `{command or '(not stored)'}`",
              f"- written by faultgen {written_by}; this card by faultgen {__version__}",
              "- robot models (SHA-256 of the MJCF): " + "; ".join(f"{k} {v[:12]}" for k, v in sorted(shas.items())),
              f"- Python {platform.python_version()}, MuJoCo {_version('mujoco')}, numpy {np.__version__}, "
              f"h5py {_version('h5py')}",
              f"- reading: `import faultgen; data = faultgen.open({str(path)!r})`; `data.runs`, `data.features()`",
              f"- schema: format {schema.FORMAT} version {schema.FORMAT_VERSION}; docs/dataset.md"]
