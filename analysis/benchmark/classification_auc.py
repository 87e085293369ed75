"""Leave-pair-out AUC per preprocessing and classifier over a dataset (thesis Table 5.2), each cell judged
against its chance level (the AUC with the runs' labels exchanged); the stacking classifier left out
where its inner folds would see one class."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pandas as pd

from analysis.benchmark.classification_features import ClassificationInputs, classification_inputs


def classification_table(path, wear_threshold: float = 10.0, n_pairs: int | None = 20, random_state: int = 0,
                         progress: bool = True, horizon: int | None = None, chance: bool = False,
                         short: bool = False, **kwargs) -> pd.DataFrame:
    """Mean and std of leave-pair-out AUC per preprocessing (rows) and classifier (columns), Table 5.2.

    Samples are recorded cycles (days in a fleet), in time order; the features per axis are those
    of thesis Table 5.1: the speed and torque indicators (:func:`analysis.features.duty_indicators`
    over the run's samples, each standing for the same production time) and the KL divergence of
    the angle, speed and torque histograms against the run's first sample (ch. 5.3.1-5.3.2); the
    estimated speed and torque of the "+estM" rows are each sample's own average speed and
    average load torque (what :func:`analysis.features.estimates_from_indicators` gives back).
    A dataset with runs simulated before the duty was recorded (no ``average_speed``) uses the
    mean absolute and RMS motor torque in place of the indicators and has no "+estM" rows.
    Labels: 1 for samples of a worn run whose true wear is at least ``wear_threshold`` percent, 0
    otherwise; groups are runs (a "robot" of Procedure 1). With ``horizon`` the thesis's protocol
    instead (ch. 5.3.3; its Table 5.2 used 3 days): each run keeps the samples from ``horizon +``
    :data:`THESIS_WINDOW` to ``horizon`` before its last one (the failure day T of a failing
    robot; T-13 to T-3), features computed over the whole record first, and every kept sample of a
    worn run is labelled 1 (the robot's state), of an unworn run 0. With ``chance`` (and no
    ``permutations``) every row's chance level is measured on :data:`CHANCE_CLASSIFIER`
    (:data:`CHANCE_PERMUTATIONS` label exchanges, in the same evaluation as the table: its cells on
    the true labels are the table's, and each held-out pair's preprocessing is shared) and every
    cell judged against it; with ``permutations`` each cell against its own; either way :func:`with_verdict` adds the chance level, the p-value and
    ``above_chance``, and ``attrs`` hold ``pairs`` (held-out pairs scored) and ``chance_source``
    ("cell": every cell measured; a classifier's name: only its cells, the default; None: not measured). With ``short`` (and no ``preprocessing``) only the rows of
    :data:`analysis.classify.SHORT_TABLE` the dataset has (no "+estM" ones without the duty).
    ``kwargs`` go to :func:`analysis.classify.evaluate` (``n_jobs``: pairs in parallel).

    Raises
    ------
    ValueError
        If ``horizon`` is not an integer >= 0 or a run is too short for it (the message names the
        run and its samples), or the training sets would lack a class (see
        :func:`_check_training_sets`).
    """
    from analysis.classify import CLASSIFIERS, ESTIMATED, SHORT_TABLE, evaluate, select_pairs

    inputs = classification_inputs(path, wear_threshold, horizon)
    dropped = _without_stacking(path, inputs, kwargs)
    if short and kwargs.get("preprocessing") is None:
        kwargs["preprocessing"] = [n for n in SHORT_TABLE
                                   if inputs.estimated is not None or not n.startswith(ESTIMATED)]
    judged = None
    if chance and not kwargs.get("permutations"):  # the cheapest classifier's cells, each against its own chance level
        columns = list(kwargs.get("classifiers") or CLASSIFIERS)
        judged = CHANCE_CLASSIFIER if CHANCE_CLASSIFIER in columns else columns[0]
        kwargs.update(permutations=CHANCE_PERMUTATIONS, null_of=[judged])
    table = evaluate(inputs.X, inputs.y, inputs.groups, inputs.failed, inputs.normal, n_pairs=n_pairs,
                     random_state=random_state, progress=progress, estimated=inputs.estimated, **kwargs)
    null_values = {key: np.array(v) for key, v in table.attrs.pop("null_values", {}).items()}
    table = with_verdict(table, null_values)
    table.attrs.update(pairs=len(select_pairs(inputs.failed, inputs.normal, n_pairs, random_state)),
                       chance_source=judged or ("cell" if null_values else None), imported=inputs.imported,
                       notes=[dropped] if dropped else [])
    return table


#: Fewest worn runs (with failed samples) a training set of the stacking classifier needs: its
#: inner cross-validation splits the training runs into folds by run (:func:`analysis.classify.run_folds`),
#: and the base classifiers of a fold need failed samples in the runs outside it.
STACKING_WORN_RUNS = 2


def _without_stacking(path, inputs: ClassificationInputs, kwargs: dict) -> str:
    """Drop the stacking classifier from ``kwargs["classifiers"]`` (default: every classifier)
    when a leave-pair-out training set holds failed samples of fewer than
    :data:`STACKING_WORN_RUNS` runs (its inner folds by run would train on one class: scikit-learn's
    "needs samples of at least 2 classes"); returns the note saying so, "" when kept. Asked for by
    name (``--classifier stacking``) it is refused instead.

    Raises
    ------
    ValueError
        If stacking was asked for by name and cannot be fitted, or it was the only classifier.
    """
    from analysis.classify import CLASSIFIERS

    named = kwargs.get("classifiers")
    classifiers = list(named) if named is not None else list(CLASSIFIERS)
    if "stacking" not in classifiers:
        return ""
    carriers = sorted({g for g, label in zip(inputs.groups, inputs.y, strict=True) if label and g in inputs.failed},
                      key=str)
    if len(carriers) - 1 >= STACKING_WORN_RUNS:  # one worn run is held out with each pair
        return ""
    needs = STACKING_WORN_RUNS + 1
    if inputs.imported:
        what = (f"failed samples (logs labelled worn) in {len(carriers)} unit(s) ({', '.join(map(str, carriers))}); with "
                f"one held out, its inner folds by unit need worn logs of at least {STACKING_WORN_RUNS} other units: "
                f"events.csv needs an `onset` or `failure` row for the worn axis of at least {needs} units in all")
    else:
        what = (f"failed samples in {len(carriers)} worn run(s); with one held out, its inner folds by run need failed "
                f"samples of at least {STACKING_WORN_RUNS} other runs ({needs} worn runs in all)")
    others = [c for c in classifiers if c != "stacking"]
    if named is not None and "stacking" in named or not others:
        raise ValueError(f"{path}: the stacking classifier cannot be fitted here: the dataset has {what}"
                         + (f" ({inputs.imported})" if inputs.imported else "")
                         + "; leave it out (--classifier lr --classifier svm --classifier rf)")
    kwargs["classifiers"] = others
    return f"note: stacking left out: the dataset has {what}."


#: Label exchanges of the chance level ``faultgen classify`` measures per row by default: with 19
#: the smallest permutation p-value is 1/20, so a cell can be above chance at the 5 % level.
CHANCE_PERMUTATIONS = 19


#: The classifier whose AUC with exchanged labels is each row's chance level by default: the
#: cheapest (a row costs 19 of its fits per pair, about half the default table's time in all).
CHANCE_CLASSIFIER = "lr"


#: A cell is above chance when its permutation p-value is at most this.
CHANCE_ALPHA = 0.05


def with_verdict(table: pd.DataFrame, null_values: Mapping[str, np.ndarray]) -> pd.DataFrame:
    """``table`` (:func:`analysis.classify.evaluate`) with each cell judged against chance: per
    classifier ``null`` (the mean exchanged AUC), ``p`` (:func:`analysis.classify.null_p_value`
    of the cell's mean AUC against ``null_values["<classifier> <row>"]``) and ``above`` (p at most
    :data:`CHANCE_ALPHA`; None for a classifier without null values: not judged). Without
    ``null_values`` the table is returned as it is (not measured)."""
    from analysis.classify import null_p_value

    if not null_values:
        return table
    out = {}
    for column in dict.fromkeys(table.columns.get_level_values(0)):
        out[column, "mean"], out[column, "std"] = table[column, "mean"], table[column, "std"]
        if f"{column} {table.index[0]}" not in null_values:  # not measured: no verdict, not a False one
            out[column, "null"] = out[column, "p"] = pd.Series(np.nan, index=table.index)
            out[column, "above"] = pd.Series(None, index=table.index, dtype=object)
            continue
        null = {row: null_values[f"{column} {row}"] for row in table.index}
        out[column, "null"] = pd.Series({row: float(np.nanmean(v)) for row, v in null.items()})
        out[column, "p"] = pd.Series({row: null_p_value(table.loc[row, (column, "mean")], null[row])
                                      for row in table.index})
        out[column, "above"] = (out[column, "p"] <= CHANCE_ALPHA).astype(object)
    judged = pd.DataFrame(out, index=table.index)
    judged.columns = judged.columns.set_names(table.columns.names)
    judged.attrs.update(table.attrs, permutations=min(len(v) for v in null_values.values()))
    return judged
