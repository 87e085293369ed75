"""Which axis each isolator names, per run and wear level (thesis Table 6.2): the isolators, the cases
(worn runs up to each level, healthy runs shown as many cycles), the table; and how a motor-speed
window maps to the runs' motor speeds."""

from __future__ import annotations

from collections.abc import Iterable, Mapping

import numpy as np
import pandas as pd
from tqdm.auto import tqdm

from analysis import isolation, scoring
from analysis.benchmark.tables import axis_label
from analysis.benchmark.truth import NO_FAULT, fault_progress, level_cycle, opened
from analysis.evaluate import Data, OwnHistory, evaluate
from faultgen import axes

#: Wear levels of thesis Table 6.2, in percent.
WEAR_LEVELS = (1.0, 5.0, 10.0, 15.0)


#: The ``wear_pct`` of an imported dataset's cases in :func:`isolation_table`: a mark for "up to the
#: first log labelled worn" (a worn log's friction multiplier, :data:`faultgen.data.fleetlogs.WORN_MARK`,
#: read as a wear), not a measured wear.
LABELLED_WORN = 100.0


def default_isolators(bins: Iterable[int] = (5, 10)) -> dict[str, object]:
    """Transfer entropy with each bin count (thesis ch. 6), cross-correlation (ch. 3.4.2), and the
    other registered isolators with their defaults."""
    chosen = {f"te{b}": isolation.make("transfer_entropy", bins=b) for b in bins}
    for name in isolation.ISOLATORS:
        if name != "transfer_entropy":
            chosen[name] = isolation.make(name)
    return chosen


def isolation_table(path, isolators: Mapping[str, object] | None = None, levels: Iterable[float] = WEAR_LEVELS,
                    signal: str = "mean_abs_torque", progress: bool = True,
                    speed_window: tuple[float, float] | None = None) -> pd.DataFrame:
    """Which axis each isolator names as the source, per run and wear level, healthy runs included.

    For a run wearing one axis, the isolator sees the per-cycle ``signal`` (n_cycles, 6) of the
    recorded cycles up to and including the first one whose true wear reaches the level (thesis
    ch. 6.4: 10 % wear is cycle 86 of the exp4 schedule; for a fault other than friction wear, the
    level is a share of its final value, :func:`fault_progress`); it is right when it names that axis.
    A run without wear is shown, for each level, as many cycles as the worn runs of its robot and
    task saw at that level; it is right only when the isolator names no axis (undecided): naming
    one is a false isolation. Runs wearing several axes are skipped.

    A dataset imported from logs (``faultgen logs import``) has no measured wear, only logs
    labelled worn by its events: each worn unit is one case, its logs up to and including the
    first labelled worn (``levels`` do not apply; ``wear_pct`` holds :data:`LABELLED_WORN`, a
    mark), and ``attrs["imported"]`` is True.

    With ``speed_window`` (low, high) in rad/s of motor speed, the per-cycle signal is the mean
    |motor torque| over the samples whose motor speed lies in the window (thesis ch. 6.3.2,
    :func:`analysis.features.speed_window_mean`); an axis of a run with a cycle that has no such
    sample keeps its whole-cycle ``signal`` (column ``windowed``: the axes that were windowed).

    Returns
    -------
    DataFrame with one row per (run, level, isolator): robot, task, run, worn_axis (0: no wear),
    wear_pct (the level; 0 for a run without wear), cycles (samples seen), isolator, predicted
    (0: undecided; -1: too few cycles for the isolator), correct, windowed, n_axes (the run's
    robot's axes N), needed (the fewest cycles the isolator runs on; NaN for a plugin). A case with
    too few cycles is not applicable: :func:`isolation_accuracy` leaves it out.

    Raises
    ------
    ValueError
        If an isolator's parameters are invalid (e.g. bins < 2; the message names it), or the
        dataset has no run with exactly one worn axis.
    """
    isolators = dict(isolators or default_isolators())
    _check_isolators(isolators)
    with opened(path) as data:
        runs = [r for r in data.runs if len(r.worn_axes) <= 1]
        values, windowed = _signals(runs, signal, speed_window)
        worn = [r for r in runs if len(r.worn_axes) == 1]
        if not worn:
            raise ValueError(f"{data.path} has no run with exactly one worn axis to isolate")
        imported = all(r.measured for r in data.runs)
        if imported:  # no wear is measured: one case per unit, up to its first log labelled worn
            levels = [LABELLED_WORN]
        cases = _cases(worn, runs, levels)
    needed = {name: isolation.min_rows(prototype) for name, prototype in isolators.items()}
    signals = Data.of_units([values[run.id] for run in runs], [run.id for run in runs])
    protocol = OwnHistory([(run.id, n) for run, _, _, n in cases])  # each case: the run's first n cycles
    rules = scoring.ISOLATION_TABLE_RULES  # too few cycles: not applicable
    named = {name: evaluate(prototype, signals, protocol, rules, name, role="isolator").named
             for name, prototype in tqdm(isolators.items(), desc="isolation", unit="isolator", disable=not progress)}
    rows = []
    for k, (run, axis, level, n) in enumerate(cases):
        for name in isolators:
            predicted = named[name][k][0]
            rows.append(dict(robot=run.robot, task=run.task, run=run.id, worn_axis=axis,
                             wear_pct=level, cycles=n, isolator=name, predicted=predicted,
                             answer=axis_label(predicted), correct=bool(scoring.isolation_right(predicted, axis)),
                             windowed=" ".join(str(a + 1) for a in np.flatnonzero(windowed[run.id])),
                             n_axes=values[run.id].shape[1], needed=np.nan if needed[name] is None else needed[name]))
    table = pd.DataFrame(rows)
    table.attrs["imported"] = imported
    return table


def _check_isolators(isolators: Mapping[str, object]) -> None:
    """Fit each isolator on a probe: bad parameters (bins < 2, ...) raise here, named.

    Raises
    ------
    ValueError
        Naming the isolator whose fit refuses its parameters or sets no ``source_axis_``.
    """
    from sklearn.base import clone

    probe = np.random.default_rng(0).standard_normal((200, 6))
    for name, prototype in isolators.items():  # bad parameters (bins < 2, ...) raise here, named
        try:
            fitted = clone(prototype).fit(probe)
        except ValueError as err:
            raise ValueError(f"isolator {name}: {err}") from err
        if not hasattr(fitted, "source_axis_"):
            raise ValueError(f"isolator {name}: fit(X) set no source_axis_ (the isolator contract of "
                             "analysis.isolation: 1-based axis, 0 when undecided)")


def _signals(runs: list, signal: str, speed_window: tuple[float, float] | None) -> tuple[dict, dict]:
    """(run id -> its per-cycle ``signal`` (n_cycles, N), run id -> which of its axes were windowed): with
    ``speed_window``, the windowed mean |motor torque| where every cycle has samples in the window."""
    values = {r.id: r.array(signal) for r in runs}
    windowed = {r.id: np.zeros(values[r.id].shape[1], dtype=bool) for r in runs}
    if speed_window:  # the windowed mean where every cycle has samples in the window
        from analysis.features import speed_window_mean

        for run in runs:
            inside = speed_window_mean(run.signal("tau_m"), run.signal("qd_m"), *speed_window)
            run.forget("tau_m", "qd_m")  # large: not kept
            windowed[run.id] = ~np.isnan(inside).any(axis=0)
            values[run.id] = np.where(windowed[run.id], inside, values[run.id])
    return values, windowed


def _cases(worn: list, runs: list, levels) -> list[tuple]:
    """The isolation cases ``(run, worn axis or NO_FAULT, level, cycles seen)``: each worn run up to the
    first cycle at each level, and each run without wear shown as many cycles as the worn runs of its
    setup (reader.Run.setup) saw at that level."""
    # cycles seen per (setup, level): what the worn runs saw, shown to the healthy runs of the same
    # robot, program, friction and conditions (reader.Run.setup) too
    seen: dict[tuple, int] = {}
    cases = []
    for run in worn:
        axis = run.worn_axes[0]
        grown = fault_progress(run, axis)
        for level in levels:
            k = level_cycle(grown, level)
            if k is not None:
                seen.setdefault((run.setup, level), k + 1)
                cases.append((run, axis, level, k + 1))
    for run in runs:
        if not run.worn_axes:
            cases += [(run, NO_FAULT, 0.0, n) for (setup, _), n in seen.items() if setup == run.setup]
    return cases


def motor_speed_coverage(path, speed_window: tuple[float, float]) -> pd.DataFrame:
    """How a motor-speed window maps to each robot's and task's motor speeds: per robot, task and
    axis, the 50th and 99th percentile of |motor speed| (rad/s) over the runs without wear, and
    the share of their samples inside the window (%)."""
    rows = []
    with opened(path) as data:
        for run in data.healthy:
            qd_m = run.signal("qd_m")
            speed = np.abs(qd_m).reshape(-1, qd_m.shape[-1])
            inside = (speed >= speed_window[0]) & (speed <= speed_window[1])
            for a in range(speed.shape[1]):
                rows.append(dict(robot=run.robot, task=run.task, run=run.id, axis=axes.number(a),
                                 p50_rad_s=np.percentile(speed[:, a], 50), p99_rad_s=np.percentile(speed[:, a], 99),
                                 in_window_pct=100.0 * inside[:, a].mean()))
    table = pd.DataFrame(rows)
    return table.groupby(["robot", "task", "axis"])[["p50_rad_s", "p99_rad_s", "in_window_pct"]].mean().round(1)
