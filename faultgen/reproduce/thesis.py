"""The thesis's own numbers that :mod:`faultgen.reproduce` sets beside ours, copied from
/work/shared/reference/thesis-wear-fdi.md (the thesis "Data-driven Detection and Isolation of
Wear-induced Faults in Industrial Robots"), each with its table number. Tasks T1-T3 are pick and
place, spot welding and arc welding, in that order (thesis ch. 3.5 and 6.3)."""

from __future__ import annotations

#: Thesis task label -> faultgen task name.
TASKS = {"T1": "pick_place", "T2": "spot_weld", "T3": "arc_weld"}

#: Table 6.2: per task and wear level (%), the TE-10-bin marks of axes 1-6 (True: isolated) and the
#: accuracies (%) of TE with 10 bins, TE with 5 bins and cross-correlation.
TABLE_6_2 = {
    ("T1", 1): ("✓×✓××✓", 50, 100, 16.7), ("T1", 5): ("✓✓✓✓✓✓", 100, 83.3, 33.3),
    ("T1", 10): ("✓✓✓✓✓✓", 100, 83.3, 33.3), ("T1", 15): ("✓✓✓✓✓✓", 100, 100, 33.3),
    ("T2", 1): ("✓✓×✓✓✓", 83.3, 66.7, 16.7), ("T2", 5): ("✓✓✓✓×✓", 83.3, 66.7, 0),
    ("T2", 10): ("✓✓✓✓✓✓", 100, 66.7, 33.3), ("T2", 15): ("✓✓✓✓✓✓", 100, 50, 33.3),
    ("T3", 1): ("✓✓✓✓✓✓", 100, 83.3, 50), ("T3", 5): ("✓✓✓✓✓✓", 100, 66.7, 66.7),
    ("T3", 10): ("✓✓✓✓✓✓", 100, 66.7, 83.3), ("T3", 15): ("✓✓✓✓✓✓", 100, 66.7, 100),
}

#: Table 3.5: per friction increase (%), worn axis and task, the hour of detection where the
#: onset was detected and located (None: ×).
TABLE_3_5 = {
    10: {1: (60, 60, None), 2: (None, None, None), 3: (100, 90, None), 4: (None, 80, None),
         5: (None, 115, None), 6: (None, 90, 95)},
    20: {1: (50, 50, 40), 2: (None, None, None), 3: (85, 78, 105), 4: (None, 60, 90),
         5: (None, 95, None), 6: (None, 90, 90)},
}

#: Table 5.2: mean (std) AUC per preprocessing row, classifiers LR, SVM, RF and ES (stacking).
TABLE_5_2 = {
    "control": ((0.47, 0.34), (0.61, 0.48), (0.66, 0.45), (0.64, 0.42)),
    "+estM": ((0.45, 0.33), (0.59, 0.47), (0.69, 0.42), (0.58, 0.38)),
    "+diff": ((0.51, 0.23), (0.48, 0.30), (0.71, 0.28), (0.48, 0.30)),
    "+pca": ((0.69, 0.42), (0.49, 0.50), (0.63, 0.47), (0.44, 0.49)),
    "+var3": ((0.47, 0.34), (0.55, 0.49), (0.66, 0.44), (0.54, 0.49)),
    "+estM+diff": ((0.54, 0.24), (0.61, 0.29), (0.77, 0.27), (0.60, 0.30)),
    "+estM+pca": ((0.50, 0.41), (0.66, 0.44), (0.61, 0.43), (0.67, 0.44)),
    "+estM+var3": ((0.45, 0.33), (0.55, 0.45), (0.69, 0.43), (0.51, 0.46)),
    "+diff+pca": ((0.61, 0.33), (0.60, 0.35), (0.63, 0.27), (0.61, 0.34)),
    "+var3+pca": ((0.69, 0.42), (0.49, 0.50), (0.65, 0.46), (0.48, 0.48)),
    "+estM+diff+pca": ((0.72, 0.31), (0.65, 0.27), (0.69, 0.28), (0.64, 0.27)),
    "+estM+var3+pca": ((0.45, 0.33), (0.55, 0.45), (0.61, 0.44), (0.51, 0.46)),
    "+diff+pca+var3": ((0.67, 0.37), (0.62, 0.37), (0.68, 0.36), (0.67, 0.37)),
    "+diff+var3+pca": ((0.67, 0.38), (0.61, 0.36), (0.64, 0.33), (0.62, 0.37)),
    "+estM+diff+var3+pca": ((0.75, 0.30), (0.76, 0.27), (0.77, 0.29), (0.76, 0.27)),
}
CLASSIFIERS = ("lr", "svm", "rf", "stacking")

#: Tables 4.2-4.4: three-way ANOVA p-values per term, for the coefficient of variation of Q
#: (4.2), the samples above the limit (4.3) and the lead time (4.4); "0" printed there is < 0.001.
TABLES_4_2_TO_4 = {
    "source": (0.88, 0.0, 0.001), "signal": (0.014, 0.0, 0.0), "condition": (0.0, 0.001, 0.0),
    "source*signal": (0.539, 0.0, 0.0), "source*condition": (0.059, 0.017, 0.001),
    "signal*condition": (0.035, 0.0, 0.0), "source*signal*condition": (0.569, 0.001, 0.0),
}
#: Figs. 4-4 to 4-6 (ch. 4.4): the one (training source, signal) cell where Tukey's HSD found
#: failing robots different from normal ones, per descriptor.
TUKEY_4 = {"cov_q": ("OTM", "difference"), "nsat": ("OTO", "difference"), "lead_time_days": ("OTO", "difference")}

#: Table 6.1: task 1 (pick and place), mean |torque| (N m) of axes 1-6 in the 100th cycle with
#: no wear (0) and 20 % wear on one axis; the thesis's worn axis's rise is read off these.
TABLE_6_1_T1 = {
    0: (18.42, 7.45, 15.20, 1.95, 2.53, 1.90), 1: (18.66, 7.45, 15.20, 1.95, 2.54, 2.12),
    2: (18.64, 7.72, 15.18, 1.95, 2.54, 2.12), 3: (18.62, 7.79, 15.59, 1.96, 2.54, 2.12),
    4: (18.63, 7.78, 15.67, 1.89, 2.54, 2.12), 5: (18.42, 7.45, 15.20, 1.95, 2.65, 2.11),
    6: (18.42, 7.45, 15.20, 1.95, 2.67, 2.02),
}
