"""A first look at a dataset: mean absolute motor torque per axis against the true wear, as a PNG.

matplotlib is imported only when :func:`plot` is called, and the figure is drawn without pyplot,
so importing this module needs neither matplotlib nor a display, and no global backend changes.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from faultgen.data import reader
from faultgen.figure_text import plain

TORQUE_LABEL = "mean |motor torque| [N m]"
CHANGE_LABEL = "change of mean |motor torque| [%]"
WEAR_LABEL = "true wear [%]"
WEAR_COLOR = "tab:red"
#: Smallest torque range of a single-run panel, as a fraction of its mean torque: cycle-to-cycle
#: noise (typically < 0.1 %) is not stretched over the whole panel.
MIN_SPAN = 0.01


def plot(path: str | Path, out: str | Path, run: str | None = None) -> Path:
    """Draw how the mean absolute motor torque of every axis follows the true wear, as a PNG.

    One run (``run`` given, or a file with exactly one run): a 2 x 3 grid, one panel per axis
    ("axis 1" .. "axis N", two rows); x is the cycle index (1-based), markers are the mean absolute motor
    torque of the cycle (N m, motor side), and, on a second y axis, a line is the true wear of that
    axis in percent (friction multiplier - 1) * 100, drawn only where the axis wears. Each torque
    axis spans at least 1 % of its mean torque, so cycle-to-cycle noise is not mistaken for a
    trend. The title describes the run from its labels (:func:`run_title`).

    A whole sweep (several runs, ``run`` omitted): a 2 x 3 grid, one panel per axis j; for every
    run that wears axis j, a line of the change of axis j's mean absolute motor torque, in percent
    of the unworn run of the same robot, program (its hash: :attr:`faultgen.data.reader.Run.setup`),
    conditions, seed and friction model on the same cycle, against
    the true wear of axis j (%), one colour per task. Tasks whose torques differ tenfold share
    one scale, and the unworn run is the dashed line at 0, so the wear shows on every axis. A worn
    run without such an unworn run is drawn against its own first recorded cycle, and the title
    says so. The title names the file, the robots and the number of runs.

    Parameters
    ----------
    path : path of a faultgen dataset (HDF5).
    out : path of the PNG to write (suffix ``.png``); its folder must exist.
    run : str, optional
        Run id to draw (:attr:`faultgen.data.reader.Run.id`); required to draw a single run of a sweep.

    Returns
    -------
    Path of the PNG written.

    Raises
    ------
    ValueError
        If ``out`` does not end in ``.png``, or ``run`` is not a run of the file (the message
        names it and lists some run ids).
    faultgen.data.dataset.DatasetError
        If ``path`` is not a finished, valid faultgen dataset.
    """
    out = Path(out)
    if out.suffix.lower() != ".png":
        raise ValueError(f"cannot write {out}: plots are written as PNG, so the output must end in .png")
    with reader.open(path) as data:
        ids = [r.id for r in data.runs]
        if run is not None and run not in ids:
            listed = ", ".join(ids[:5]) + (", ..." if len(ids) > 5 else "")
            raise ValueError(f"{path} has no run {run!r}; its {len(ids)} runs include: {listed}")
        if run is None and data.kind == "fleet" and len(ids) > 1:
            return _draw_fleet(data, out)
        fig = _draw(data, run)
    from faultgen.data.atomic import atomic_path

    with atomic_path(out) as tmp:  # a full disk or a kill leaves no half-written PNG
        fig.savefig(tmp, dpi=110, format="png")
    return out


def _draw(data: reader.Dataset, run: str | None):
    """The figure of one run (``run``, or the file's only run) or of a sweep (``run`` None)."""
    from matplotlib.figure import Figure

    shown = [data[run]] if run is not None else data.runs
    n_axes = max(r.array("friction_multiplier").shape[1] for r in shown)  # the most axes of the robots
    columns = -(-n_axes // 2)  # drawn: one panel each, two rows
    fig = Figure(figsize=(14 * columns / 3, 7.5))
    axes = fig.subplots(2, columns).ravel()
    for ax in axes[n_axes:]:
        ax.set_visible(False)
    if len(shown) == 1:
        _draw_run(fig, axes[:n_axes], shown[0])
    else:
        _draw_sweep(fig, axes[:n_axes], data)
    return fig


#: Days at the start of each robot's record that the fleet plot measures the change from.
BASELINE_DAYS = 5
#: Days of the fleet plot's running median.
TREND_DAYS = 7


def running_median(values: np.ndarray, days: int = TREND_DAYS) -> np.ndarray:
    """The centred running median of ``values`` (n_days, n) over ``days`` days, NaN where the
    window is not full: at a record's ends a median of three or four days is one part's torque,
    not the trend (a healthy robot's last day read -33 % on a 20-day fleet)."""
    import pandas as pd

    return pd.DataFrame(values).rolling(days, center=True, min_periods=days).median().to_numpy()


def _draw_fleet(data, out: Path) -> Path:
    """A fleet (daily records of robots, ``faultgen fleet``): one panel per robot, in file order.
    Against the day of its record: the change of each axis's mean |motor torque| from its median
    over the first :data:`BASELINE_DAYS` days (%), as its running median over 7 days
    (:func:`running_median`, drawn where the week is whole; the parts a robot carries change the
    torque from day to day; the worn axis bold, its days as dots, the others thin grey), the days
    the robot's record carries its lighter part as ticks along the bottom, and, on a second y axis,
    the worn axis's true wear (%, red). Healthy robots show their six axes only: what a monitor sees
    when nothing wears."""
    from matplotlib.figure import Figure

    runs = data.runs
    imported = all(run.measured for run in runs)  # logs: labels from events.csv, no wear measured
    parts = False
    cols = min(4, len(runs))
    rows = -(-len(runs) // cols)
    fig = Figure(figsize=(4.2 * cols, 2.6 * rows + 1.2), layout="constrained")
    panels = fig.subplots(rows, cols, squeeze=False).ravel()
    for ax, run in zip(panels, runs, strict=False):
        parts |= _fleet_panel(ax, run)
    for ax in panels[len(runs):]:
        ax.set_visible(False)
    for ax in panels[max(0, len(runs) - cols):len(runs)]:
        ax.set_xlabel("log of the record (stamp order)" if imported else "day of the record", fontsize=8)
    _fleet_title(fig, data, runs, imported, parts)
    from faultgen.data.atomic import atomic_path

    with atomic_path(out) as tmp:  # a full disk or a kill leaves no half-written PNG
        fig.savefig(tmp, dpi=100, format="png")
    return out


def _fleet_panel(ax, run: reader.Run) -> bool:
    """One robot's panel of :func:`_draw_fleet` on ``ax``; whether its records carry a lighter part."""
    parts = False
    days = run.recorded
    torque = run.array("mean_abs_torque")
    base = np.median(torque[:BASELINE_DAYS], axis=0)
    change = (torque / np.where(base == 0, 1.0, base) - 1.0) * 100.0
    worn = [a - 1 for a in run.worn_axes]
    # the parts a robot carries change its torque from day to day: lines through the days
    # zigzag, so the days are dots and the line is their running median over a week
    trend = running_median(change)
    for j in range(change.shape[1]):
        if j not in worn:
            ax.plot(days, trend[:, j], "-", lw=0.7, color="0.65")
    for j in worn:
        ax.plot(days, change[:, j], ".", ms=3, color="tab:blue", alpha=0.5)
        ax.plot(days, trend[:, j], "-", lw=1.6, color="tab:blue", label=f"axis {j + 1}")
    if run.measured:  # each log's label from events.csv, ticked along the top
        label = run.array("label")
        for flags, color in ((np.any(label == 1, axis=1), WEAR_COLOR), (np.all(label == 0, axis=1), "0.2")):
            ax.plot(days[flags], np.full(int(flags.sum()), 0.97), "|", ms=6, color=color,
                    transform=ax.get_xaxis_transform())
    if run.has("payload_mass"):  # the part of each day's record: the lighter one ticked
        mass = run.array("payload_mass")
        light = mass < mass.max()
        parts = bool(light.any())
        ax.plot(days[light], np.zeros(int(light.sum())), "|", ms=6, color="tab:green",
                transform=ax.get_xaxis_transform(), label="lighter part")
    ax.axhline(0.0, color="0.4", lw=0.6)
    ax.set_ylabel(CHANGE_LABEL.replace("change of ", "").replace(" [%]", "\nchange [%]"), fontsize=7)
    ax.tick_params(labelsize=7)
    ax.grid(alpha=0.3)
    if run.measured:
        label = run.array("label")
        n_worn, n_healthy = int(np.any(label == 1, axis=1).sum()), int(np.all(label == 0, axis=1).sum())
        state = (f"logs {n_worn} worn" + (f" (axis {', '.join(str(a) for a in run.worn_axes)})" if n_worn else "")
                 + f", {n_healthy} healthy, {len(label) - n_worn - n_healthy} unknown")
        ax.set_title(plain(f"{run.id}\n{run.robot}: {state}"), fontsize=8,
                     color=WEAR_COLOR if n_worn else "black")
    else:
        state = (f"fails, axis {', '.join(str(a) for a in run.worn_axes)}" if run.failing else "healthy")
        ax.set_title(plain(f"{run.id}\n{run.robot}, {run.task}: {state}"), fontsize=8,
                     color=WEAR_COLOR if run.failing else "black")
    if run.failing and not run.measured:
        twin = ax.twinx()
        twin.plot(days, run.fault_level, "-", color=WEAR_COLOR, lw=1.2)
        twin.set_ylim(bottom=0.0)
        twin.set_ylabel(WEAR_LABEL, color=WEAR_COLOR, fontsize=7)
        twin.tick_params(axis="y", colors=WEAR_COLOR, labelsize=7)
    return parts


def _fleet_title(fig, data, runs: list[reader.Run], imported: bool, parts: bool) -> None:
    """The title of :func:`_draw_fleet`'s figure: the fleet's ``runs`` (``imported`` from logs or
    simulated) and how to read their panels (``parts``: whether green ticks mark days with the lighter
    part)."""
    if imported:
        worn_units = sum(bool(run.worn_axes) for run in runs)
        fig.suptitle(f"{plain(data.path.name)}: {len(runs)} units imported from logs ({worn_units} with logs "
                     f"labelled worn by events.csv), one panel each\nchange of each axis's mean |motor torque| per log from its "
                     f"first {BASELINE_DAYS} logs, running median over {TREND_DAYS} logs where the window is whole\n"
                     "(grey: axes without a log labelled worn; blue: the axis with worn logs, its logs as dots)\n"
                     "ticks along the top: logs labelled worn (red) and healthy (black), none: unknown"
                     + ("; green ticks: logs with the lighter part" if parts else ""), fontsize=10)
    else:
        fig.suptitle(f"{plain(data.path.name)}: {len(runs)} robots ({len(data.failing)} failing), one panel each\n"
                     f"change of each axis's daily mean |motor torque| from its first {BASELINE_DAYS} days, running "
                     f"median over {TREND_DAYS} days where the week is whole\n(blue: the worn axis, its days as dots; "
                     "grey: the other axes); red: the worn axis's true wear; green ticks: days with the lighter part",
                     fontsize=10)


def _draw_run(fig, axes, run: reader.Run) -> None:
    cycles, torque, wear = run.recorded, run.array("mean_abs_torque"), run.wear
    for j, ax in enumerate(axes):
        ax.plot(cycles, torque[:, j], "o", ms=4, color="tab:blue", label="mean |motor torque|")
        ax.ticklabel_format(axis="y", useOffset=False)
        low, high = torque[:, j].min(), torque[:, j].max()
        half = max(high - low, MIN_SPAN * abs(torque[:, j].mean()), 1e-9) * 0.55  # noise alone stays flat
        ax.set_ylim((low + high) / 2 - half, (low + high) / 2 + half)
        ax.set(title=f"axis {j + 1}", xlabel="cycle", ylabel=TORQUE_LABEL)
        ax.locator_params(axis="x", integer=True)
        ax.grid(alpha=0.3)
        if np.any(run.array("friction_multiplier")[:, j] != 1.0):
            twin = ax.twinx()
            twin.plot(cycles, wear[:, j], "-", color=WEAR_COLOR, label="true wear")
            twin.set_ylabel(WEAR_LABEL, color=WEAR_COLOR)
            twin.tick_params(axis="y", colors=WEAR_COLOR)
            twin.set_ylim(bottom=min(0.0, wear[:, j].min()))
            ax.set_title(f"axis {j + 1} (worn)", color=WEAR_COLOR)
    key = "blue dots: mean |motor torque| per cycle" + (", red line: true wear" if run.worn_axes else "")
    fig.suptitle(plain(f"{run_title(run)}\n{key}"))
    fig.tight_layout()


def _draw_sweep(fig, axes, data: reader.Dataset) -> None:
    runs = data.runs  # only the per-cycle arrays are read: the logged signals can be large
    task_names = sorted({run.task for run in runs})
    robot_names = sorted({run.robot for run in runs})
    colors = {task: f"C{i % 10}" for i, task in enumerate(task_names)}
    styles = {robot: ("-", "--", "-.", ":")[i % 4] for i, robot in enumerate(robot_names)}
    unworn: dict[tuple, list] = {}
    for run in runs:
        if not run.worn_axes:
            unworn.setdefault(_reference_key(run), []).append(run)
    most = max(float((run.array("friction_multiplier") - 1.0).max()) * 100.0 for run in runs)
    legend, own_first = {}, False
    for j, ax in enumerate(axes):
        ax.axhline(0.0, color="0.5", lw=1.0, ls=(0, (5, 3)))  # the unworn run
        worn_here = False
        for run in runs:
            if j + 1 not in run.worn_axes:
                continue
            references = unworn.get(_reference_key(run), [])  # two alike: an ambiguous label, no pairing
            wear, change, against_own = _change(run, references[0] if len(references) == 1 else None, j)
            own_first |= against_own
            name = run.task if len(robot_names) == 1 else f"{run.robot}, {run.task}"
            (line,) = ax.plot(wear, change, marker="o", ms=3, ls=styles[run.robot], color=colors[run.task])
            legend.setdefault(plain(name), line)
            worn_here = True
        if most > 0:
            ax.set_xlim(-0.03 * most, 1.03 * most)  # the same wear range in every panel
        ax.set(title=f"axis {j + 1}" + ("" if worn_here else " (no run wears it)"),
               xlabel=f"{WEAR_LABEL} of axis {j + 1}", ylabel=CHANGE_LABEL)
        ax.grid(alpha=0.3)
    order = sorted(legend)
    fig.legend([legend[k] for k in order], order, loc="lower center", ncol=min(len(order), 6), frameon=False)
    reference = "the unworn run of the same program, conditions and seed (dashed line at 0)"
    if own_first:
        reference += "; runs without one: their own first recorded cycle"
    fig.suptitle(f"{plain(data.path.name)}: robots {plain(', '.join(robot_names))}, {len(runs)} runs\n"
                 "change of the worn axis's mean "
                 f"|motor torque| per cycle against {reference}")
    rows = -(-len(order) // 6)
    fig.tight_layout(rect=(0, 0.035 * rows + 0.01, 1, 1))


def _reference_key(run: reader.Run) -> tuple:
    """What a worn run shares with the unworn run it is compared with: robot, program (its hash),
    friction model, operating conditions (:attr:`faultgen.data.reader.Run.setup`) and seed."""
    return run.setup, run.seed


def _change(run: reader.Run, reference: reader.Run | None, j: int) -> tuple[np.ndarray, np.ndarray, bool]:
    """True wear of axis ``j`` (%) and the change of its mean |motor torque| (%), per cycle.

    Against the unworn ``reference`` run on the cycles both recorded, or, without one, against
    the run's own first recorded cycle (third value True).
    """
    torque, wear = run.array("mean_abs_torque")[:, j], run.wear[:, j]
    if reference is None:
        return wear, (torque / torque[0] - 1.0) * 100.0, True
    _, mine, theirs = np.intersect1d(run.recorded, reference.recorded, return_indices=True)
    base = reference.array("mean_abs_torque")[theirs, j]
    return wear[mine], (torque[mine] / base - 1.0) * 100.0, False


def run_title(run: reader.Run) -> str:
    """A run described by its labels: robot, task, worn axes with schedule and final wear, seed,
    friction model; the run id is added when it says more than the file's default ``run``."""
    schedules = run.wear_schedule.get("schedules", [])
    worn = ", ".join(f"axis {s['axis']} worn ({s['kind']}, +{100 * s['increase']:g} % by cycle {s['last_cycle']})"
                     for s in schedules) or "no wear"
    text = f"{run.robot}, {run.task}, {worn}, seed {run.seed}, {run.friction_model} friction"
    return text if run.id == "run" else f"{run.id}: {text}"
