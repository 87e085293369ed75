"""The benchmark: frozen tracks of seeded train and test files, and one score for any method.

- :mod:`~faultgen.bench.tracks`: the tracks, one TOML recipe each (``tracks/<name>.toml``: robots,
  programs, seeds, conditions; every version kept), read and turned into sweep grids;
- :mod:`~faultgen.bench.files`: the train and test files (features only; the test labels apart);
- :mod:`~faultgen.bench.make`: ``faultgen bench make``, the sweeps and the frozen manifest check;
- :mod:`~faultgen.bench.score`: ``faultgen bench score``, AUROC, delay, false alarms, isolation,
  each with a bootstrap interval over test units;
- :mod:`~faultgen.bench.verdicts`: every score's verdict against chance (above, at, below), and the
  records per unit a method needs;
- :mod:`~faultgen.bench.baselines`: the named baselines (the thesis's methods, two pyod detectors, the
  prognostics track's prognosers, the twin), declared in the one registry (:mod:`analysis.registry`)
  that ``bench score``, ``detect``, ``bench-isolators`` and ``bench baselines`` read (the PCA one's
  class in :mod:`~faultgen.bench.pca_detector`).
- :mod:`~faultgen.bench.independent`: the sim-to-real track's test fleet, made by another simulator
  (Pinocchio's rigid-body dynamics, friction, conditions and wear in forms faultgen does not use;
  its plant in :mod:`~faultgen.bench.plant`, a real cell's programs, cut logs and wear laws in
  :mod:`~faultgen.bench.cell`).
- :mod:`~faultgen.bench.rawlogs`, :mod:`~faultgen.bench.twin`, :mod:`~faultgen.bench.recorded`:
  ``faultgen monitor``'s twin as a baseline: a track's test split written again as raw logs, the
  monitor's outputs read as per-unit answers, and answers made elsewhere scored by :mod:`score`.

The layer sits above ``runs`` (it sweeps) and reads with the ``analysis`` package (it scores); only
the command line sits above it (docs/bench.md).
"""
