"""Fault detection by classification: classifiers, preprocessing combinations, thesis ch. 5.

- :data:`CLASSIFIERS`: LR, SVM (RBF), RF and the LR + SVM stack with an LR meta-classifier
  (ch. 5.2), each a factory of a scikit-learn ``Pipeline``;
- :data:`PREPROCESSING` and :func:`preprocessing_steps`: the combinations of Table 5.2 ("control",
  "+diff", "+var3", "+pca", "+diff+var3+pca", ...) as lists of transformer steps, and
  :func:`make_pipeline` to put one in front of a classifier;
- :func:`leave_pair_out_auc`: Procedure 1, leave one failed and one normal robot out, ROC AUC;
- :func:`permuted_roles`: the chance level of Procedure 1 on the same robots, labels exchanged
  between runs (a group-level permutation test);
- :func:`compare_preprocessing`: Procedure 2, Levene, then Welch ANOVA + Games-Howell or ANOVA +
  Tukey HSD (pingouin);
- :func:`evaluate`: every classifier with every combination, Table 5.2's layout.

In faultgen terms a "robot" is a run (a *group*), its samples are the run's recorded cycles in
time order (rows of a per-cycle feature matrix, e.g. mean absolute motor torque and the KL
divergences of the histograms, one column per axis and feature), a "failed" robot is a run with
wear and a "normal" one a run without.

Runs and sequence steps: :class:`~analysis.features.Difference` and
:class:`~analysis.features.WindowConcat` treat every array they transform as one time series.
:func:`fit_by_run` and :func:`score_by_run` (used by :func:`leave_pair_out_auc`) therefore apply
these steps to each run separately, so no difference or window spans two runs, and fit every
other step on all rows at once. A pipeline fitted with plain ``Pipeline.fit`` on several runs
stacked is fine for one run but joins consecutive runs at their boundaries.

This module holds no code: each name lives in the module of its job (docs/architecture.md)::

    classifiers     the classifiers of ch. 5.2
    preprocessing   Table 5.2's combinations as steps; make_pipeline
    by_run          fitting and scoring run by run; stacking's folds by run
    labels          0/1 labels of the samples
    leave_pair_out  Procedure 1
    chance          its chance level: roles exchanged, permutation p-value
    comparison      Procedure 2
    evaluation      Table 5.2: every classifier with every combination
"""

from __future__ import annotations

from analysis.classify.by_run import SEQUENCE_STEPS, ByRun, fit_by_run, run_folds, run_steps, score_by_run
from analysis.classify.chance import null_p_value, permuted_roles
from analysis.classify.classifiers import (
    CLASSIFIERS,
    logistic_regression,
    random_forest,
    stacking,
    support_vector_machine,
)
from analysis.classify.comparison import ALPHA, Comparison, compare_preprocessing
from analysis.classify.evaluation import evaluate
from analysis.evaluate import MAX_PAIRS, select_pairs
from analysis.classify.labels import last_samples, make_labels
from analysis.classify.leave_pair_out import (
    UndefinedAUCWarning,
    check_inputs,
    leave_pair_out_auc,
    matched_rows,
    pair_cells,
)
from analysis.classify.preprocessing import (
    ESTIMATED,
    PCA_VARIANCE,
    PREPROCESSING,
    SHORT_TABLE,
    TABLE_5_2,
    describe_preprocessing,
    make_pipeline,
    preprocessing_steps,
)

__all__ = [
    "ALPHA",
    "CLASSIFIERS",
    "ESTIMATED",
    "MAX_PAIRS",
    "PCA_VARIANCE",
    "PREPROCESSING",
    "SEQUENCE_STEPS",
    "ByRun",
    "SHORT_TABLE",
    "TABLE_5_2",
    "Comparison",
    "UndefinedAUCWarning",
    "check_inputs",
    "compare_preprocessing",
    "describe_preprocessing",
    "evaluate",
    "fit_by_run",
    "last_samples",
    "leave_pair_out_auc",
    "logistic_regression",
    "make_labels",
    "make_pipeline",
    "matched_rows",
    "null_p_value",
    "pair_cells",
    "permuted_roles",
    "preprocessing_steps",
    "random_forest",
    "run_folds",
    "run_steps",
    "score_by_run",
    "select_pairs",
    "stacking",
    "support_vector_machine",
]
