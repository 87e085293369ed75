"""A classification table (:mod:`analysis.benchmark.classification_auc`) in words and tables: the
verdict against chance, the table as ``faultgen classify`` prints it, its tidy CSV form, its caption."""

from __future__ import annotations

import shlex

import numpy as np
import pandas as pd

from analysis.benchmark.classification_auc import CHANCE_ALPHA
from analysis.benchmark.tables import MEASURED_NEXT, markdown


def classification_verdict(table: pd.DataFrame, command: str = "faultgen classify FILE") -> str:
    """One line saying whether any judged cell of a :func:`classification_table` is above chance,
    which classifiers were not judged, and when none is above, that its AUCs are no finding and
    what would help."""
    if "above" not in table.columns.get_level_values(-1):
        return (f"verdict: not judged: the chance level was not measured (`{command} --permutations 19` measures it), "
                "so these AUCs cannot be read as better than chance")
    above = table.xs("above", axis=1, level=-1)
    judged = [c for c in above.columns if above[c].notna().all()]
    above = above[judged].astype(bool)
    means, null = table.xs("mean", axis=1, level=-1)[judged], table.xs("null", axis=1, level=-1)[judged]
    unjudged = [c for c in table.columns.get_level_values(0).unique() if c not in judged]
    others = (f"; {', '.join(unjudged)} not judged (their chance level may be higher than {', '.join(judged)}'s: "
              f"`{command} --permutations 19` measures every cell)" if unjudged else "")
    k = int(table.attrs.get("permutations", 0))
    if above.to_numpy().any():
        best = means.where(above).stack().idxmax()
        return (f"verdict: {int(above.to_numpy().sum())} of {above.size} judged cells above chance at the "
                f"{100 * CHANCE_ALPHA:g} % level (best: {best[1]} {best[0]}, AUC {means.loc[best]:.2f} against chance "
                f"{null.loc[best]:.2f}, p {table.loc[best[0], (best[1], 'p')]:.2f}); at {100 * CHANCE_ALPHA:g} % each, "
                f"{CHANCE_ALPHA * above.size:.2g} of {above.size} would pass by chance alone on average{others}")
    reason = (f" (with {k} label exchanges p cannot go below {1 / (k + 1):.2f}: use --permutations 19)"
              if k and 1 / (k + 1) > CHANCE_ALPHA else "")
    return (f"verdict: no judged cell is above chance at the {100 * CHANCE_ALPHA:g} % level{reason}: the AUCs of "
            f"{', '.join(judged)} ({np.nanmin(means.to_numpy()):.2f}-{np.nanmax(means.to_numpy()):.2f}) are what it reaches "
            f"with the runs' labels exchanged (chance {np.nanmin(null.to_numpy()):.2f}-{np.nanmax(null.to_numpy()):.2f}), "
            "so they do not show that worn samples are told from healthy ones. More data would help: "
            + (f"more labelled logs: {MEASURED_NEXT}" if table.attrs.get("imported") else
               "more worn and unworn runs (several seeds: --seed 0 --seed 1 --seed 2, or more robots in a fleet) and "
               "more recorded cycles per run (--record all, more --cycles or --days)") + others)


def classification_printed(table: pd.DataFrame) -> pd.DataFrame:
    """A :func:`classification_table` as ``faultgen classify`` prints it: per classifier mean, std
    and, where judged, p; the chance level (one column when only one classifier or every one
    shares it, else per classifier) and ``above_chance``, the classifiers above chance in the row
    ("none"; the unjudged ones are named in the verdict)."""
    if "above" not in table.columns.get_level_values(-1):
        return table
    classifiers = list(dict.fromkeys(table.columns.get_level_values(0)))
    judged = [c for c in classifiers if table[c, "above"].notna().all()]
    null = table.xs("null", axis=1, level=-1)[judged]
    shared = bool((null.nunique(axis=1) <= 1).all())
    out = {}
    for c in classifiers:
        out[c, "mean"], out[c, "std"] = table[c, "mean"], table[c, "std"]
        if c in judged:
            out[c, "p"] = table[c, "p"]
            if not shared:
                out[c, "chance"] = table[c, "null"]
    if shared:
        out["chance", ""] = null.iloc[:, 0]
    above = table.xs("above", axis=1, level=-1)[judged].astype(bool)
    out["above_chance", ""] = above.apply(lambda row: " ".join(c for c in judged if row[c]) or "none", axis=1)
    return pd.DataFrame(out, index=table.index)


def classification_tidy(table: pd.DataFrame) -> pd.DataFrame:
    """A :func:`classification_table` as a tidy table: one row per (preprocessing, classifier)
    cell, one header row; columns preprocessing, steps (what the combination does, in order),
    classifier, auc_mean, auc_std and, where chance was measured, auc_null (the chance level), p,
    above_chance (p at most :data:`CHANCE_ALPHA`; empty where the cell was not judged: by default
    only each row's lr cell is)."""
    from analysis.classify import describe_preprocessing

    long = table.stack(0, future_stack=True).reset_index()
    long = long.rename(columns={long.columns[1]: "classifier"})
    long = long.rename(columns={"mean": "auc_mean", "std": "auc_std", "null": "auc_null", "above": "above_chance"})
    long.insert(1, "steps", long["preprocessing"].map(describe_preprocessing))
    long.columns.name = None
    return long


def classification_caption(table: pd.DataFrame, *, n_pairs: int | None, horizon: int | None, wear_threshold: float,
                           matched: bool, command: str, short: bool = False) -> str:
    """The caption of a classification table: what the cells are (and over how many held-out pairs,
    as scored: ``attrs["pairs"]``), how samples were labelled, the chance level and how each cell
    is judged against it (per cell, per row on lr, or not measured with the command that measures
    it), why two orders of the same steps are two rows (when both are), and with ``short`` (the
    default rows of ``faultgen classify``) how to get every row."""
    imported = table.attrs.get("imported", "")
    labels = (f"the thesis's window (T-{horizon + 10} to T-{horizon}) labelled by the robot's state" if horizon is not None
              else f"every log labelled worn by events.csv is a failed sample ({imported})" if imported
              else f"every sample labelled failed when its true wear reaches {wear_threshold:g} %")
    pairs = table.attrs.get("pairs", "every" if n_pairs is None else n_pairs)
    parts = [f"Leave-pair-out ROC AUC (mean and std over {pairs} held-out "
             f"(worn, unworn) run pair(s), thesis Procedure 1 and Table 5.2) per preprocessing (rows) and classifier; "
             f"{labels}{'; time-matched (--matched-days)' if matched else ''}."]
    source = table.attrs.get("chance_source")
    k = table.attrs.get("permutations", 0)
    level = f"p at most {CHANCE_ALPHA:g}"
    if source == "cell":
        parts.append(f"Chance level measured per cell: null, the mean AUC with the runs' labels exchanged ({k} times), "
                     f"and p, the permutation p-value of the AUC; above_chance: {level}.")
    elif source is not None:
        parts.append(f"Chance level per row (column chance): the mean AUC of {source} on that row with the runs' "
                     f"labels exchanged {k} times (robots of one kind look alike, so it is not 0.5); p: {source}'s AUC "
                     f"against those {k} exchanged AUCs; above_chance: the classifiers with {level}. The other "
                     f"classifiers are not judged (one that fits runs more closely can have a higher chance level, "
                     f"docs/analysis.md): `{command} --permutations 19` measures every cell.")
    else:
        parts.append(f"Chance level not measured, so no cell can be read as better than chance: "
                     f"`{command} --permutations 19` measures it per cell.")
    if source is not None and k and 1 / (k + 1) > CHANCE_ALPHA:
        parts.append(f"With {k} exchanges p cannot go below {1 / (k + 1):.2f}, so no cell can be above chance at "
                     f"{CHANCE_ALPHA:g}: use --permutations 19 or more.")
    if {"+diff+pca+var3", "+diff+var3+pca"} <= set(table.index):
        parts.append("Token order is step order: +diff+pca+var3 concatenates windows of PCA scores, +diff+var3+pca "
                     "takes PCA of the concatenated windows; the thesis's Table 5.2 lists both.")
    if short:
        parts.append("Rows: each step alone and the fullest combinations; every row of Table 5.2: "
                     f"`{command} --full`.")
    parts += [note.removeprefix("note: ").capitalize() for note in table.attrs.get("notes", [])]
    return " ".join(parts)


def classification_text(table: pd.DataFrame, file, *, pairs: int, horizon: int | None, wear_threshold: float,
                        matched: bool, full: bool, classifiers=None, preprocessing=None) -> str:
    """What ``faultgen classify FILE`` prints and writes to OUT.md: the printed table, its caption and
    its verdict against chance, with the command line that reproduces it (its options as given:
    ``pairs``, 20 by default, 0 all; ``horizon``; ``matched`` days; ``full``; the cells)."""
    command = " ".join(["faultgen classify", shlex.quote(str(file)),
                        *([f"--horizon {horizon}"] if horizon is not None else []),
                        *(["--matched-days"] if matched else []), *(["--pairs", str(pairs)] if pairs != 20 else []),
                        *(["--full"] if full else []),
                        *(f"--classifier {c}" for c in classifiers or []),
                        *(f"--preprocessing {shlex.quote(p)}" for p in preprocessing or [])])
    caption = classification_caption(table, n_pairs=pairs or None, horizon=horizon, wear_threshold=wear_threshold,
                                     matched=matched, command=command, short=not (full or preprocessing))
    return (markdown(classification_printed(table), digits=3) + "\n\n" + caption + "\n\n"
            + classification_verdict(table, command))


def classification_across_text(table: pd.DataFrame, file, train) -> str:
    """What ``faultgen classify FILE --train OTHER`` prints and writes to OUT.md: the table of
    :func:`analysis.crossdata.classification_across` and what its columns mean."""
    return (markdown(table, digits=3) + f"\n\nprotocol: {table.attrs['protocol']}. auc: the samples of "
            f"{file} ranked by a model fitted on {train}; null: its mean over label sets with the tested runs' roles "
            "exchanged (the chance level on these robots); p: the permutation p-value.")
