"""Run isolators, detectors and classifiers over a faultgen dataset; tables in the thesis's layouts.

- :func:`isolation_table`: every isolator on every run with one worn axis, at each wear level
  (data up to the first cycle whose true wear reaches it), thesis Table 6.2, and on every run
  without wear, where naming any axis is a false isolation; :func:`isolation_confusion` counts
  true axis (or none) against named axis (or undecided) per isolator.
- :func:`detection_table`: PCA monitoring (Q statistic) of each worn run against the run without
  wear of the same robot, task and seed; onset of wear and its location, thesis Table 3.5.
- :func:`classification_table`: AUC of LR / SVM / RF / stacking over preprocessing combinations,
  leave one worn and one unworn run out, thesis Table 5.2.

Each takes a dataset path and returns a pandas DataFrame; :func:`write_outputs` writes a table as
CSV and Markdown (and a PNG heatmap for isolation).

This module holds no code. It names, in one place, what the commands, the reproduction, the
benchmarks and users call; each name lives in the module of its job, and data flows one way
between them (docs/architecture.md)::

    truth                    a dataset opened; each run's true fault progress and wear levels
    tables                   a table as Markdown, CSV and Markdown files; answers that are no axis
    isolation_answers        Table 6.2's cases and the isolators' answers
    isolation_scores         accuracy, cases decided, confusion, Table 6.2's Markdown, the report
    detection_features       |motor torque| counts -> 12-bin histograms -> KL divergences
    detection                the protocols, the monitors, false alarms held out: Table 3.5
    detection_report         its columns, summary and advice in words, the report
    classification_features  Table 5.1's features and labels, the training sets checked
    classification_auc       Table 5.2 judged against chance
    classification_report    its verdict, printed and tidy forms, caption, the report
    figures                  the PNG figures of all three
"""

from __future__ import annotations

from analysis.benchmark.classification_auc import (
    CHANCE_ALPHA,
    CHANCE_CLASSIFIER,
    CHANCE_PERMUTATIONS,
    STACKING_WORN_RUNS,
    classification_table,
    with_verdict,
)
from analysis.benchmark.classification_features import (
    MIN_CLASS_SAMPLES,
    THESIS_WINDOW,
    ClassificationInputs,
    classification_inputs,
    imported_labels,
)
from analysis.benchmark.classification_report import (
    classification_across_text,
    classification_caption,
    classification_printed,
    classification_text,
    classification_tidy,
    classification_verdict,
)
from analysis.benchmark.detection import (
    FAR_LIMIT,
    FIRST,
    MIN_FIRST,
    PROTOCOLS,
    detection_table,
    false_alarm_interval,
    fitted_first,
    locate_onset,
)
from analysis.benchmark.detection_features import (
    StoredHistograms,
    binned_torque,
    detection_scale,
    group_cycles,
    kl_features,
    sample_histograms,
    torque_record,
)
from analysis.benchmark.detection_report import (
    DETECTION_COLUMNS,
    MEASURED_DETECTION_COLUMNS,
    detection_advice,
    detection_columns,
    detection_summary,
    detection_text,
    false_alarm_meaning,
)
from analysis.benchmark.figures import (
    classification_heatmap,
    confusion_figure,
    detection_figure,
    isolation_heatmap,
)
from analysis.benchmark.isolation_answers import (
    LABELLED_WORN,
    WEAR_LEVELS,
    default_isolators,
    isolation_table,
    motor_speed_coverage,
)
from analysis.benchmark.isolation_scores import (
    ACCURACY_RULE,
    ENOUGH_CYCLES,
    isolation_accuracy,
    isolation_accuracy_text,
    isolation_confusion,
    isolation_csv,
    isolation_decided,
    isolation_levels,
    isolation_markdown,
    isolation_report,
    level_label,
    starved_isolators,
    table_axes,
)
from analysis.benchmark.tables import (
    AXIS_COLUMNS,
    MEASURED_NEXT,
    TOO_FEW_CYCLES,
    UNDECIDED,
    axis_label,
    markdown,
    write_outputs,
)
from analysis.benchmark.truth import NO_FAULT, fault_progress, level_cycle, opened

__all__ = [
    "ACCURACY_RULE",
    "AXIS_COLUMNS",
    "CHANCE_ALPHA",
    "CHANCE_CLASSIFIER",
    "CHANCE_PERMUTATIONS",
    "DETECTION_COLUMNS",
    "ENOUGH_CYCLES",
    "FAR_LIMIT",
    "FIRST",
    "LABELLED_WORN",
    "MEASURED_DETECTION_COLUMNS",
    "MEASURED_NEXT",
    "MIN_CLASS_SAMPLES",
    "MIN_FIRST",
    "NO_FAULT",
    "PROTOCOLS",
    "STACKING_WORN_RUNS",
    "THESIS_WINDOW",
    "TOO_FEW_CYCLES",
    "UNDECIDED",
    "WEAR_LEVELS",
    "ClassificationInputs",
    "StoredHistograms",
    "axis_label",
    "binned_torque",
    "classification_across_text",
    "classification_caption",
    "classification_heatmap",
    "classification_inputs",
    "classification_printed",
    "classification_table",
    "classification_text",
    "classification_tidy",
    "classification_verdict",
    "confusion_figure",
    "default_isolators",
    "detection_advice",
    "detection_columns",
    "detection_figure",
    "detection_scale",
    "detection_summary",
    "detection_table",
    "detection_text",
    "false_alarm_interval",
    "false_alarm_meaning",
    "fault_progress",
    "fitted_first",
    "group_cycles",
    "imported_labels",
    "isolation_accuracy",
    "isolation_accuracy_text",
    "isolation_confusion",
    "isolation_csv",
    "isolation_decided",
    "isolation_heatmap",
    "isolation_levels",
    "isolation_markdown",
    "isolation_report",
    "isolation_table",
    "kl_features",
    "level_cycle",
    "level_label",
    "locate_onset",
    "markdown",
    "motor_speed_coverage",
    "opened",
    "sample_histograms",
    "starved_isolators",
    "table_axes",
    "torque_record",
    "with_verdict",
    "write_outputs",
]
