"""Each table of docs/reproduction.md, made from the outputs of its steps (:mod:`.plan`), set beside
the thesis's numbers (:mod:`.thesis`) with a verdict computed from both and the explanation of
the differences that docs/reproduction.md gives.

Each builder takes the output folder and returns a :class:`Part`. A verdict is ``agrees``,
``agrees in part`` or ``differs``, followed by the numbers it rests on.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from faultgen.reproduce import thesis
from faultgen.reproduce.plan import REDUCTIONS as REDUCTIONS_TEXT

#: Largest output of a step a table reads, bytes: the steps write tables of kilobytes (the j2
#: isolation table, the largest, about 100 kB); a file past this is not one of theirs.
CSV_MAX_BYTES = 64 * 2**20

#: Thesis task label per faultgen task, and the order of docs/reproduction.md's comparisons.
LABEL = {task: label for label, task in thesis.TASKS.items()}


@dataclass(frozen=True)
class Part:
    """One table of the reproduction: its title, the thesis tables it answers, the Markdown body
    (ours beside the thesis's, and why they differ), the one-line verdict, and what the reduced
    work of the full scale changes in it (empty: nothing)."""

    key: str
    title: str
    thesis_tables: str
    body: str
    verdict: str
    reduced: str = ""
    steps: tuple[str, ...] = ()


def _csv(path: Path) -> pd.DataFrame:
    """A step's CSV output read through :func:`faultgen.inputs.read_text` (a regular file, at most
    :data:`CSV_MAX_BYTES`, UTF-8), then parsed by pandas.

    Raises
    ------
    faultgen.inputs.InputError
        Naming the file: not a regular file, too large, not UTF-8, or not a CSV table.
    """
    import io

    from faultgen import inputs

    text = inputs.read_text(path, "reproduction step's CSV output", CSV_MAX_BYTES)
    try:
        return pd.read_csv(io.StringIO(text))
    except (pd.errors.ParserError, pd.errors.EmptyDataError) as err:
        raise inputs.InputError(f"{path}: not a CSV table ({' '.join(str(err).split())[:200]}); expected the "
                                "output of the reproduction's step that writes it") from None


def _md(frame: pd.DataFrame) -> str:
    from analysis import benchmark

    return benchmark.markdown(frame, digits=3)


def _accuracy(frame: pd.DataFrame) -> pd.DataFrame:
    """Accuracy (%) of each isolator per task and wear level on the worn runs of a
    bench-isolators CSV: index (task, wear_pct), one column per isolator."""
    worn = frame[frame["worn_axis"] > 0]
    return (worn.groupby(["task", "wear_pct", "isolator"])["correct"].mean().mul(100).unstack("isolator"))


def _range(values) -> str:
    values = [v for v in values if pd.notna(v)]
    return f"{min(values):.3g}-{max(values):.3g}" if values else "-"


def table_6_2(folder: Path) -> Part:
    frame = _csv(folder / "j2-isolation.csv")
    acc = _accuracy(frame)
    te10 = frame[(frame["isolator"] == "te10") & (frame["worn_axis"] > 0)]
    rows = []
    for (label, level), (marks, t10, t5, cc) in thesis.TABLE_6_2.items():
        task = thesis.TASKS[label]
        if (task, float(level)) not in acc.index:
            continue
        ours = te10[(te10["task"] == task) & (te10["wear_pct"] == level)].sort_values("worn_axis")
        our_marks = "".join("✓" if c else "×" for c in ours["correct"])
        a = acc.loc[(task, float(level))]
        rows.append({"task": f"{label} {task}", "wear %": level, "TE10 marks, ours": our_marks,
                     "TE10 marks, thesis": marks, "TE10 ours": a.get("te10"), "TE10 thesis": t10,
                     "TE5 ours": a.get("te5"), "TE5 thesis": t5, "CC ours": a.get("cross_correlation"),
                     "CC thesis": cc, "trend ours": a.get("trend")})
    table = pd.DataFrame(rows)
    mean = table.groupby("wear %")[["TE10 ours", "TE10 thesis", "TE5 ours", "TE5 thesis", "CC ours", "CC thesis",
                                    "trend ours"]].mean().reset_index()
    te_wins = int((mean["TE10 ours"] > mean["CC ours"]).sum())
    at10 = mean.loc[mean["wear %"] == 10, "TE10 ours"]
    at10 = float(at10.iloc[0]) if len(at10) else float("nan")
    claims = [te_wins == len(mean), at10 >= 99.9]
    verdict = (f"{_word(claims)}: TE (10 bins) beats cross-correlation at {te_wins} of {len(mean)} wear levels over "
               f"the tasks (thesis: all 4); TE (10 bins) at 10 % wear {at10:.1f} % (thesis: 100 %)")
    healthy = frame[frame["worn_axis"] == 0]
    named = healthy[healthy["predicted"] > 0].groupby("isolator").size() / healthy.groupby("isolator").size() * 100
    body = "\n\n".join([
        "Per task and wear level (thesis Table 6.2; T1 pick and place, T2 spot weld, T3 arc weld):",
        _md(table.set_index(["task", "wear %"])),
        "Over the three tasks (%):", _md(mean.set_index("wear %")),
        "Runs without wear: share of cases in which each isolator named an axis anyway (%; the thesis never showed "
        "its isolators a healthy robot): " + ", ".join(f"{k} {v:.0f}" for k, v in named.fillna(0).items()) + ".",
        "Why it differs (docs/reproduction.md, Table 6.2): the thesis's signals came from another simulator (an "
        "IRB 6700 model in RobotStudio); here the misses concentrate on axes 2 and 3, whose mean absolute torque "
        "barely rises with wear (the drive brakes as often as it drives); cross-correlation of slowly drifting "
        "per-cycle means has its maximum near zero lag, where noise decides. Six runs per task and level: one run "
        "is 16.7 points of a cell.",
    ])
    return Part("table-6.2", "Isolating the worn axis (j2)", "Table 6.2", body, verdict,
                steps=("sweep j2", "isolation j2"))


def _word(claims: list[bool]) -> str:
    return "agrees" if all(claims) else "agrees in part" if any(claims) else "differs"


def speed_window(folder: Path) -> Part:
    whole = _accuracy(_csv(folder / "j2-isolation.csv"))
    window = _accuracy(_csv(folder / "j2-window.csv"))
    rows = []
    for (label, level), (_, t10, t5, cc) in thesis.TABLE_6_2.items():
        key = (thesis.TASKS[label], float(level))
        if key not in window.index:
            continue
        rows.append({"task": f"{label} {key[0]}", "wear %": level,
                     "TE10 whole / window / thesis": _slash(whole.loc[key].get("te10"), window.loc[key].get("te10"), t10),
                     "TE5 whole / window / thesis": _slash(whole.loc[key].get("te5"), window.loc[key].get("te5"), t5),
                     "CC whole / window / thesis": _slash(whole.loc[key].get("cross_correlation"),
                                                          window.loc[key].get("cross_correlation"), cc)})
    over_w = window.groupby("wear_pct")["te10"].mean()
    over_n = whole.groupby("wear_pct")["te10"].mean()
    better = int((over_w > over_n + 1e-9).sum())
    verdict = (f"{'agrees' if better == len(over_w) else 'differs'}: the thesis's 50-120 rad/s window raises TE "
               f"(10 bins) over the tasks at {better} of {len(over_w)} wear levels (means with it "
               f"{_range(over_w)} %, without {_range(over_n)} %); the thesis used it as an improvement")
    body = "\n\n".join([
        "TE and cross-correlation per task and wear level: ours averaging the whole cycle / ours in the window "
        "(`--speed-window 50,120`, thesis ch. 6.3.2) / the thesis's Table 6.2:",
        _md(pd.DataFrame(rows).set_index(["task", "wear %"])),
        "Why (docs/reproduction.md, \"The thesis's motor-speed window\"): the window was chosen for the thesis's "
        "robot; on ours pick and place runs its motors at 140-400 rad/s, so the window keeps only the 5-8 % of "
        "samples where a move speeds up or slows down, where inertia dwarfs friction; the wrists of the welding "
        "tasks never reach 50 rad/s and keep the whole-cycle mean.",
    ])
    return Part("window", "Table 6.2 with the thesis's motor-speed window", "Table 6.2, ch. 6.3.2", body, verdict,
                steps=("sweep j2", "isolation j2 window"))


def _slash(*values) -> str:
    return " / ".join("-" if v is None or pd.isna(v) else f"{v:.3g}" for v in values)


def bins(folder: Path) -> Part:
    acc = _accuracy(_csv(folder / "j2-bins.csv"))
    task = "pick_place" if "pick_place" in acc.index.get_level_values("task") else acc.index[0][0]
    te = acc.loc[task][[c for c in acc.columns if c.startswith("te")]]
    te = te[sorted(te.columns, key=lambda c: int(c[2:]))].T
    te.index = [int(c[2:]) for c in te.index]
    te.index.name = "bins"
    full = [b for b in te.index if te.loc[b].get(15.0, np.nan) >= 99.9]
    last = max(te.index)
    at = te.loc[last]
    claims = [bool(at.get(10.0, 0) >= 99.9 and at.get(15.0, 0) >= 99.9)]
    verdict = (f"{_word(claims)}: with {last} bins TE isolates {at.get(10.0, np.nan):.1f} % at 10 % wear and "
               f"{at.get(15.0, np.nan):.1f} % at 15 % ({task}; thesis Fig. 6-5: 100 % from 10 % on with 20 bins); "
               f"{len(full)} of {len(te)} bin counts reach 100 % at 15 %")
    body = "\n\n".join([
        f"TE accuracy (%) against the number of bins, {task} (thesis Fig. 6-5; columns: wear %):", _md(te),
        "Why (docs/reproduction.md, Fig. 6-5): on six runs per cell one run is 16.7 points, and the best bin count "
        "moves between physics versions; no bin count is best at every level.",
    ])
    return Part("fig-6.5", "TE accuracy against the number of bins", "Fig. 6-5", body, verdict,
                steps=("sweep j2", "isolation j2 bins"))


def table_6_1(folder: Path) -> Part:
    table = _csv(folder / "j2-table-6-1.csv")
    seed = table["seed"].min()
    first = table[table["seed"] == seed]
    task = "pick_place" if "pick_place" in set(first["task"]) else first["task"].iloc[0]
    t1 = first[first["task"] == task].set_index("worn_axis")
    n_axes = sum(c.startswith("mean_") for c in t1.columns)
    shown = pd.DataFrame({f"axis {k}": [f"{t1.loc[w, f'mean_{k}']:.3f} ± {t1.loc[w, f'std_{k}']:.3f}" for w in t1.index]
                          for k in range(1, n_axes + 1)}, index=t1.index)
    ours_rise = first.dropna(subset=["rise"])
    theirs = [thesis.TABLE_6_1_T1[k][k - 1] - thesis.TABLE_6_1_T1[0][k - 1] for k in range(1, 7)]
    rise = pd.DataFrame({"worn axis": range(1, 7), "thesis rise (N m, T1)": theirs})
    for name, group in ours_rise.groupby("task"):
        rise[f"ours, {name}"] = group.set_index("worn_axis")["rise"].reindex(range(1, 7)).to_numpy()
    ours_values = ours_rise["rise"].to_numpy()
    small = bool(np.all(np.abs(ours_values) < 0.5)) if len(ours_values) else False
    verdict = (f"{'agrees' if small else 'differs'}: 20 % wear moves the worn axis's mean |torque| in the last cycle "
               f"by {_range(ours_values)} N m (thesis, task 1: {_range(theirs)} N m): small against the torque itself "
               "in both, as the thesis found")
    body = "\n\n".join([
        f"Mean ± std of |motor torque| (N m) in the last cycle (cycle {int(t1['cycle'].max())}), {task}, seed {seed}, "
        "per worn axis (0: no wear); read off the j2 sweep's last cycle (thesis Table 6.1's layout):", _md(shown),
        "The worn axis's rise of the mean against no wear:", _md(rise.set_index("worn axis")),
        "Why the numbers differ (docs/simulation.md, \"Thesis Table 6.1 on the IRB-6700-like arm\"): motor-side "
        "torques of our IRB-6700-like model, not the thesis's RobotStudio model; the rise of the mean equals the "
        "added friction only where the drive always drives, and axes that brake part of the cycle (2, 3) show "
        "little or a negative rise. This table reads j2's own cycle 100; `python benchmarks/table_6_1.py` "
        "simulates that cycle alone, and both gave the same numbers to the printed digits (2026-11-25).",
    ])
    return Part("table-6.1", "Torque in the last cycle with 20 % wear", "Table 6.1", body, verdict,
                steps=("sweep j2", "table 6.1 j2"))


def detection_j2(folder: Path) -> Part:
    frame = _csv(folder / "j2-detection.csv")
    worn = frame[frame["worn_axis"] > 0]
    shown = worn[["task", "worn_axis", "detected", "onset", "onset_wear_pct", "located_axis", "located"]]
    detected = int(worn["detected"].sum())
    located = int(worn["located"].sum())
    verdict = (f"differs: {detected} of {len(worn)} runs detected at a median {worn['onset_wear_pct'].median():.2f} % "
               f"wear, {located} located (thesis Table 3.5, its own grid: 19 of 36 detected and located, located in "
               "all detections but one)")
    body = "\n\n".join([
        "Same-run protocol (the thesis's ch. 3: the monitor learns the run without wear of the same task and seed):",
        _md(shown.set_index(["task", "worn_axis"])),
        "Why (docs/reproduction.md, Table 3.5): the same-run monitor learns the exact noise of the run it tests "
        "against, so it reacts to any departure, including the tiny change 0.1 % more friction causes; the "
        "cross-correlation rule on slowly drifting KL features is dominated by noise and stays undecided.",
    ])
    return Part("table-3.5-j2", "Detecting and locating wear, j2 (same-run)", "Table 3.5", body, verdict,
                steps=("sweep j2", "detect j2 same-run"))


def detection_held_out(folder: Path) -> Part:
    labels = {"same-run": "same-run, in-sample limit", "other-seeds-ins": "other-seeds, in-sample limit (eq. 2.6)",
              "other-seeds": "other-seeds, 20 folds (default)", "first-ins": "first-cycles, in-sample limit",
              "first": "first-cycles, 20 folds"}
    rows = []
    for name, label in labels.items():
        summary = _csv(folder / f"j2s3-{name}-summary.csv")
        row = summary[summary["by"] == "all"].iloc[0]
        rows.append({"protocol": label, "runs": row["runs"], "false alarms (%)": row["false_alarm_pct"],
                     "detected (%)": row["detected_pct"], "median onset wear (%)": row["median_onset_wear_pct"],
                     "located (%)": row["located_pct"]})
    table = pd.DataFrame(rows).set_index("protocol")
    fa = float(table.loc[labels["other-seeds"], "false alarms (%)"])
    fa_ins = float(table.loc[labels["other-seeds-ins"], "false alarms (%)"])
    verdict = (f"{'agrees' if fa <= 7.5 else 'differs'} with docs/reproduction.md (no thesis counterpart): held out, "
               f"the out-of-fold Q limit alarms on {fa:.2f} % of healthy runs of other seeds for a nominal 5 % "
               f"(the thesis's in-sample limit: {fa_ins:.2f} %)")
    body = "\n\n".join([
        "j2 with three seeds; each protocol judged on the healthy runs of the tested seed:", _md(table),
        "Why (docs/reproduction.md, \"Held out\"): with 5 of 6 components kept, Q lives in one residual direction "
        "whose variance the training samples underestimate; the out-of-fold limit corrects it. The thesis judged "
        "its monitor in-sample only.",
    ])
    return Part("table-3.5-held-out", "Detection judged on healthy runs it did not learn (j2, three seeds)",
                "Table 3.5 (protocol)", body, verdict, REDUCTIONS_TEXT["j2s3"],
                steps=("sweep j2", "sweep j2 seeds 1-2", "combine j2s3", *(f"detect j2s3 {n}" for n in labels)))


def detection_c2(folder: Path) -> Part:
    frame = _csv(folder / "c2-detection.csv")
    worn = frame[frame["worn_axis"] > 0].copy()
    cells = {}
    for _, row in worn.iterrows():
        final = float(row["final_wear_pct"])  # the logistic reaches its level at the last hour, within rounding
        level = min(thesis.TABLE_3_5, key=lambda lv: abs(lv - final))
        level = level if abs(level - final) < 1 else round(final)
        mark = (f"✓ ({int(row['onset'])} h, {row['onset_wear_pct']:.1f} %)" if row["detected"] else "×")
        located = "" if not row["detected"] else (" located" if row["located"] else " not located")
        hours = thesis.TABLE_3_5.get(level, {}).get(int(row["worn_axis"]), (None,) * 3)
        theirs = hours[list(thesis.TASKS.values()).index(row["task"])] if row["task"] in thesis.TASKS.values() else None
        cells[(int(row["worn_axis"]), f"{level} %, {LABEL.get(row['task'], row['task'])}")] = (
            f"{mark}{located} / {'✓ (' + str(theirs) + ' h)' if theirs else '×'}")
    table = pd.Series(cells).unstack()
    table.index.name = "axis"
    detected = int(worn["detected"].sum())
    located = int(worn["located"].sum())
    verdict = (f"differs: {detected} of {len(worn)} worn runs detected, after {_range(worn['onset'])} h at "
               f"{_range(worn['onset_wear_pct'])} % wear, {located} located (thesis Table 3.5: 19 of 36 detected and "
               "located, at 40-115 h, never axis 2)")
    body = "\n\n".join([
        "Ours / the thesis's (hour of onset and true wear at onset; same-run protocol, hourly samples):", _md(table),
        "Why (docs/reproduction.md, c2 preset): the same-run monitor learns the reference run's own noise from 120 "
        "hourly samples, so it reacts to any departure and flags wear early; the cross-correlation rule on 25-70 "
        "samples of slowly drifting KL features is dominated by noise. The thesis's simulator (MATLAB Robotics "
        "Toolbox) and noise were its own.",
    ])
    return Part("table-3.5-c2", "Detecting and locating wear, c2 (PUMA 560, hourly samples)", "Table 3.5", body,
                verdict, REDUCTIONS_TEXT["c2"], steps=("c2 grid", "sweep c2", "detect c2 same-run"))


def training_source(folder: Path) -> Part:
    from analysis import training_source as ts

    p_rows, tukey_rows, hits = [], [], {}
    for stem, label in (("fleet-ch4", "with conditions"), ("fleet-nc-ch4", "without")):
        anova_path = folder / f"{stem}-anova.csv"
        if not anova_path.exists():  # no ANOVA where a cell had no case (the tiny scale)
            continue
        anova = _csv(anova_path)
        pivot = anova[anova["term"] != "Error"].pivot(index="term", columns="descriptor", values="p")
        for term, values in pivot.iterrows():
            p_rows.append({"term": term, "fleet": label, **{f"p {d} ours": values.get(d) for d in ts.DESCRIPTORS}})
        diff = ts.failure_vs_normal(_csv(folder / f"{stem}-tukey.csv"))
        found = diff[diff["different"]]
        for descriptor, cell in thesis.TUKEY_4.items():
            mine = found[found["descriptor"] == descriptor]
            cells = ", ".join(f"{s} {k} ({d:+.2g})" for s, k, d in
                              zip(mine["source"], mine["signal"], mine["failure_minus_normal"], strict=True)) or "none"
            tukey_rows.append({"descriptor": descriptor, "fleet": label, "thesis": " ".join(cell), "ours": cells})
            hits[(descriptor, label)] = bool(((mine["source"] == cell[0]) & (mine["signal"] == cell[1])).any())
    p_table = pd.DataFrame(p_rows)
    if len(p_table):
        for i, d in enumerate(("cov_q", "nsat", "lead_time_days")):
            p_table[f"p {d} thesis"] = p_table["term"].map(lambda t, i=i: thesis.TABLES_4_2_TO_4.get(t, (None,) * 3)[i])
    with_hits = [v for (d, label), v in hits.items() if label == "with conditions"]
    verdict = (f"{_word(with_hits) if with_hits else 'differs'}: on the fleet with its conditions Tukey's HSD finds "
               f"the thesis's cell (OTM difference for CoV, OTO difference for NSAT and lead time) in "
               f"{sum(with_hits)} of {len(with_hits)} descriptors; the thesis's headline (OTO + difference) "
               f"{'holds' if hits.get(('nsat', 'with conditions')) else 'is not reproduced'}")
    body = "\n\n".join([
        "Three-way ANOVA p-values beside thesis Tables 4.2-4.4 (0 in the thesis is p < 0.001):",
        _md(p_table.set_index(["term", "fleet"])) if len(p_table) else "(no ANOVA: a design cell had no test case)",
        "Tukey HSD, failure against normal robots, cells at p < 0.05 (the starred bars of thesis Figs. 4-4 to 4-6):",
        _md(pd.DataFrame(tukey_rows).set_index(["descriptor", "fleet"])) if tukey_rows else "(none)",
        "Why (docs/reproduction.md, Chapter 4 on a fleet): the daily record is the day's maximum over two cycles "
        "with randomly drawn parts and a seasonal hall climate, so a normal robot's test days drift from its "
        "training days as much as a failing robot's; without the conditions OTO separates failing robots on "
        "every signal, best on the raw one. Our failures are friction wear of one axis; the thesis's were "
        "gearbox, motor, brake and computer failures of 10 real robots.",
    ])
    return Part("tables-4.1-4.4", "Where a monitor learns normal operation (fleet)", "Tables 4.1-4.4, Figs. 4-4 to 4-6",
                body, verdict, steps=("fleet", "fleet no conditions", "training-source fleet",
                                      "training-source fleet-nc"))


def classification(folder: Path, stem: str, title: str, why: str, steps: tuple[str, ...]) -> Part:
    tidy = _csv(folder / f"{stem}.csv")
    rows = []
    for prep, group in tidy.groupby("preprocessing", sort=False):
        row = {"preprocessing": prep}
        theirs = thesis.TABLE_5_2.get(prep)
        for i, clf in enumerate(thesis.CLASSIFIERS):
            cell = group[group["classifier"] == clf]
            ours = f"{cell['auc_mean'].iloc[0]:.2f} ({cell['auc_std'].iloc[0]:.2f})" if len(cell) else "-"
            row[clf] = ours + (f" / {theirs[i][0]:.2f} ({theirs[i][1]:.2f})" if theirs else " / -")
        rows.append(row)
    table = pd.DataFrame(rows).set_index("preprocessing")
    means = tidy["auc_mean"].dropna()
    judged = tidy[tidy.get("above_chance", pd.Series(dtype=object)).notna()] if "above_chance" in tidy else tidy.iloc[:0]
    above = int(judged["above_chance"].astype(str).str.lower().eq("true").sum()) if len(judged) else 0
    inside = bool(len(means)) and means.min() >= 0.44 - 0.05 and means.max() <= 0.77 + 0.05
    chance = (f"; {above} of {len(judged)} judged cells above their chance level (p <= 0.05)" if len(judged)
              else "; chance level not measured")
    verdict = (f"{'agrees' if inside else 'differs'}: AUC {_range(means)} (thesis Table 5.2: 0.44-0.77){chance}")
    body = "\n\n".join([
        "Mean (std) AUC, ours / the thesis's Table 5.2 (thesis: 26 real robots, labels by state, T-13 to T-3):",
        _md(table), why])
    return Part(stem, title, "Table 5.2", body, verdict, REDUCTIONS_TEXT["classify"], steps=steps)


_WHY_J2 = ("Why (docs/reproduction.md, Table 5.2): every run repeats the same task, the unworn runs of each task "
           "are in the training set and wear is the only change, so the task is much easier than the thesis's 26 "
           "real robots; differencing lowers the scores here because the wear signal is in the level.")
_WHY_FLEET = ("Why (docs/reproduction.md, Table 5.2 on a fleet): the documented conditions (parts drawn at random, "
              "hall climate, unit spread) move a robot's daily record more than 3-37 % friction wear of one axis; on "
              "the thesis's protocol most cells are within the chance level of 26 robots. The thesis's failures were "
              "real gearbox failures and it gave no chance level.")
_WHY_WEAR = ("Why (docs/reproduction.md, \"Every day labelled by its wear\" and \"with the time control\"): with "
             "labels by wear a failing robot's failed days are its last, so a classifier that learns when in the "
             "record a day lies scores well without seeing wear (chance 0.73-0.78 with differencing); matched days "
             "remove that cue, and without the conditions the fault is found above chance.")


def parts(folder: Path) -> list[Part]:
    """Every table of the reproduction, in the order of docs/reproduction.md."""
    return [
        table_6_2(folder), speed_window(folder), bins(folder), table_6_1(folder),
        detection_j2(folder), detection_held_out(folder), detection_c2(folder),
        training_source(folder),
        classification(folder, "j2-classification", "Classifying worn cycles (j2)", _WHY_J2,
                       ("sweep j2", "classify j2")),
        classification(folder, "fleet-thesis", "Classifying failing robots, the thesis's protocol (fleet)", _WHY_FLEET,
                       ("fleet", "classify fleet thesis")),
        classification(folder, "fleet-wear", "Classifying days by their wear (fleet)", _WHY_WEAR,
                       ("fleet", "classify fleet wear")),
        classification(folder, "fleet-matched", "Days by their wear, with the time control (fleet)", _WHY_WEAR,
                       ("fleet", "classify fleet matched")),
        classification(folder, "fleet-nc-matched", "The same without the operating conditions (fleet)", _WHY_WEAR,
                       ("fleet no conditions", "classify fleet-nc matched")),
    ]
