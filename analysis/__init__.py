"""Fault detection and isolation for faultgen datasets (and your own), in scikit-learn style.

- :mod:`analysis.features`: KL divergence of histograms (thesis eq. 4.1 / 5.4), differencing,
  windows (+var3 / +var5), per-cycle statistics.
- :mod:`analysis.monitoring`: PCA monitor with Hotelling T2 (eq. 2.4) and Q (eq. 2.5-2.6) limits,
  contributions (eq. 8), onset detection.
- :mod:`analysis.classify`: LR / SVM / RF / stacking over the preprocessing of Table 5.2,
  leave-one-failed-and-one-normal-out AUC (Procedure 1) and its statistics (Procedure 2).
- :mod:`analysis.isolation`: isolators with one interface (transfer entropy, eqs. 6.4-6.5;
  cross-correlation, ch. 3.4.2; Granger; trend; PCA contribution) and a registry for your own.
- :mod:`analysis.benchmark`: all of them over a dataset, in the layouts of Tables 6.2, 3.5, 5.2.
- :mod:`analysis.registry`: the one registry of named methods (detectors, isolators, prognosers,
  the monitor model ``pca_monitor``) that faultgen's benchmark and monitor both make by name.
- :mod:`analysis.evaluate`: the one evaluation harness, ``evaluate(method, data, protocol, rules)
  -> Scores``, protocols as scikit-learn splitters; the commands that judge a method format its
  scores.
"""
