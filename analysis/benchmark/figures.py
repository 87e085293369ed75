"""The PNG figures of the analysis tables: isolation accuracy and confusion, the detection charts (Q and
T2 per worn run), the classification AUC heatmap. Matplotlib is imported only when one is drawn."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from analysis.benchmark.classification_auc import CHANCE_ALPHA
from analysis.benchmark.isolation_scores import isolation_accuracy, level_label
from faultgen.figure_text import plain


def confusion_figure(confusion: pd.DataFrame, out: Path) -> Path:
    """PNG of :func:`isolation_confusion`: one matrix per isolator, counts in the cells."""
    from matplotlib.figure import Figure

    isolators = list(dict.fromkeys(confusion.index.get_level_values("isolator")))
    cols = min(3, len(isolators))
    rows = -(-len(isolators) // cols)
    fig = Figure(figsize=(4.6 * cols, 4.0 * rows))
    panels = fig.subplots(rows, cols, squeeze=False).ravel()
    for ax, name in zip(panels, isolators, strict=False):
        matrix = confusion.loc[name]
        values = matrix.to_numpy(dtype=float)
        share = values / np.maximum(values.sum(axis=1, keepdims=True), 1)
        ax.imshow(share, vmin=0, vmax=1, cmap="Blues", aspect="auto")
        for i in range(values.shape[0]):
            for j in range(values.shape[1]):
                if values[i, j]:
                    ax.text(j, i, f"{values[i, j]:.0f}", ha="center", va="center",
                            color="white" if share[i, j] > 0.6 else "black", fontsize=8)
        ax.set_xticks(range(values.shape[1]), ["undec.", *map(str, range(1, values.shape[1] - 1)), "short"],
                      fontsize=8)
        ax.set_yticks(range(values.shape[0]), [plain(i) for i in matrix.index], fontsize=8)
        ax.set(title=plain(name), xlabel="named axis", ylabel="true worn axis")
    for ax in panels[len(isolators):]:
        ax.set_visible(False)
    fig.suptitle("isolation confusion: true worn axis (none = run without wear) x named axis "
                 "(undec. = undecided, short = too few cycles); shade: share of the row")
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    return out


def isolation_heatmap(table: pd.DataFrame, out: Path) -> Path:
    """PNG heatmap of accuracy: isolators (rows) x task and wear level (columns)."""
    from matplotlib.figure import Figure

    accuracy = isolation_accuracy(table).T  # isolators x (task, wear)
    fig = Figure(figsize=(max(6.0, 0.7 * accuracy.shape[1] + 2), 0.5 * accuracy.shape[0] + 2))
    ax = fig.subplots()
    image = ax.imshow(accuracy.to_numpy(dtype=float), vmin=0, vmax=100, cmap="viridis", aspect="auto")
    ax.set_yticks(range(accuracy.shape[0]), [plain(i) for i in accuracy.index])
    imported = bool(table.attrs.get("imported"))
    ax.set_xticks(range(accuracy.shape[1]), [plain(f"{t} {level_label(w, imported)}")
                                             + (" %" if w and not imported else "") for t, w in accuracy.columns],
                  fontsize=8, rotation=35, ha="right")
    for i in range(accuracy.shape[0]):
        for j in range(accuracy.shape[1]):
            value = accuracy.iat[i, j]
            ax.text(j, i, "n/a" if np.isnan(value) else f"{value:.0f}", ha="center", va="center",
                    color="white" if np.isnan(value) or value < 60 else "black")
    fig.colorbar(image, ax=ax, label="source axis isolated (%)")
    ax.set_title("isolation accuracy per task and " + ("case (logs up to the first labelled worn)" if imported
                                                     else "wear level") + " (n/a: too few cycles for the isolator)")
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    return out


def detection_figure(charts: dict, out: Path, most: int = 40) -> Path:
    """PNG of the Q and T2 charts of :func:`detection_table` (``return_charts=True``): per worn run
    (every one, up to ``most``: the title then says how many are shown), Q and T2 against the
    cycle (a day in a fleet) on a log scale, with the
    limit (dashed), the samples the monitor learned from (shaded), where the fault begins (dotted)
    and the onset called (red). A detector without statistics shows its alarms instead."""
    from matplotlib.figure import Figure

    shown = list(charts.items())[:most]
    # constrained layout leaves the title its own room above the first row
    fig = Figure(figsize=(11, 2.3 * max(1, len(shown)) + 0.8), layout="constrained")
    panels = fig.subplots(max(1, len(shown)), 2, squeeze=False)
    for (run_id, chart), row in zip(shown, panels, strict=False):
        x = chart["cycle"]
        for ax, name in zip(row, ("q", "t2"), strict=True):
            if name in chart:
                ax.semilogy(x, np.maximum(chart[name], 1e-12), ".-", lw=0.8, ms=3, color="C0")
                ax.axhline(chart[f"{name}_limit"], ls="--", color="k", lw=0.8)
            else:
                ax.step(x, chart["alarm"].astype(int), where="mid")
            if chart["trained"]:
                ax.axvspan(x[0], x[min(chart["trained"], len(x)) - 1], color="0.85", lw=0)
            if chart["begins"] is not None:
                ax.axvline(x[chart["begins"]], ls=":", color="C2", lw=1.2)
            if chart["onset"] is not None:
                ax.axvline(x[chart["onset"]], color="C3", lw=1.2)
            ax.set_ylabel({"q": "Q", "t2": "T2"}[name])
            ax.set_title(plain(f"{run_id} (axis {chart['worn_axis']}, {chart['protocol']})"), fontsize=8)
    for ax in panels[-1]:
        ax.set_xlabel("cycle (a day in a fleet)")
    count = (f"all {len(charts)} worn runs" if len(shown) == len(charts)
             else f"the first {len(shown)} of {len(charts)} worn runs (every run in the table)")
    fig.suptitle(f"PCA monitoring, {count}: Q (left) and T2 (right); dashed: 1 - alpha limit; grey: learned as "
                 "normal;\ndotted green: fault begins; red: onset called", fontsize=9)
    fig.savefig(out, dpi=100)
    return out


def heat_values(table: pd.DataFrame) -> tuple[np.ndarray, np.ndarray, str]:
    """What :func:`classification_heatmap` colours: per cell (preprocessing x classifier) its mean AUC
    minus the chance level of its row (the cell's measured chance, ``null``; else the mean of the row's
    measured ones; else 0.5), and which cells are greyed out (judged and not above chance: an AUC of
    0.95 against a chance of 0.89 is no result). Returns ``(delta, grey, what)``: arrays of the
    table's shape (rows x classifiers) and the words on the chance level used."""
    means = table.xs("mean", axis=1, level=-1).to_numpy(dtype=float)
    if "null" not in table.columns.get_level_values(-1):
        return means - 0.5, np.zeros(means.shape, dtype=bool), "0.5, chance not measured"
    null = table.xs("null", axis=1, level=-1).to_numpy(dtype=float)
    with np.errstate(all="ignore"):
        row = np.array([np.nanmean(r) if np.isfinite(r).any() else 0.5 for r in null])
    chance = np.where(np.isfinite(null), null, row[:, None])
    above = table.xs("above", axis=1, level=-1)
    grey = np.array([[a is not None and not (isinstance(a, float) and np.isnan(a)) and not bool(a) for a in r]
                     for r in above.to_numpy(dtype=object)], dtype=bool).reshape(means.shape)
    return means - chance, grey, "the row's measured chance level"


def classification_heatmap(table: pd.DataFrame, out: Path) -> Path:
    """PNG heatmap of a classification table's mean AUC (preprocessing x classifier), coloured by the
    AUC minus its row's chance level (:func:`heat_values`: red above it, blue below), the cells judged
    not above chance grey; the value in each cell, its p and a star where it is above chance, where
    measured."""
    from matplotlib import colormaps
    from matplotlib.colors import Normalize
    from matplotlib.figure import Figure

    means = table.xs("mean", axis=1, level=-1)
    measured = "null" in table.columns.get_level_values(-1)
    delta, grey, what = heat_values(table)
    fig = Figure(figsize=(1.3 * means.shape[1] + 3.2, 0.38 * means.shape[0] + 1.8))
    ax = fig.subplots()
    cmap = colormaps["RdBu_r"].with_extremes(bad="lightgrey")
    span = max(0.05, float(np.nanmax(np.abs(np.where(grey, np.nan, delta)), initial=0.0)))
    image = ax.imshow(np.ma.masked_array(delta, mask=grey | ~np.isfinite(delta)), cmap=cmap, aspect="auto",
                      norm=Normalize(vmin=-span, vmax=span))
    ax.set_xticks(range(means.shape[1]), [plain(c) for c in means.columns])
    ax.set_yticks(range(means.shape[0]), [plain(i) for i in means.index], fontsize=8)
    for i in range(means.shape[0]):
        for j in range(means.shape[1]):
            text = f"{means.iat[i, j]:.2f}"
            if measured:
                column = means.columns[j]
                above, p = table[(column, "above")].iat[i], table[(column, "p")].iat[i]
                if pd.notna(above) and pd.notna(p):  # not judged: None or NaN (NaN is truthy), no p, no star
                    text += f"\np {p:.2f}" + (" *" if bool(above) else "")
            ax.text(j, i, text, ha="center", va="center", fontsize=7)
    fig.colorbar(image, ax=ax, label=f"AUC minus chance ({what}); grey: not above chance")
    title = "leave-pair-out AUC per preprocessing and classifier"
    if measured:
        above = int((table.xs("above", axis=1, level=-1) == True).to_numpy().sum())  # noqa: E712 (None: not judged)
        title += f"\n*: above chance (p <= {CHANCE_ALPHA:g}): {above} cells; without p: not judged"
    ax.set_title(title, fontsize=9)
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    return out
