"""The prognoser contract of ``faultgen bench score prognostics --prognoser MODULE:CLASS``, its loader,
and the naive prognoser every score is judged against.

A **prognoser** is any class built with no argument (``Class()``) that has

- ``fit(units, failure_wear)``: learns from the train split's run-to-failure units
  (:class:`faultgen.bench.files.Unit`, each with its per-record ``fault_level``, %, its
  ``worn_axis`` and its records' ``arrays``) and ``failure_wear`` (%: the wear that ends a unit's
  life); returns itself;
- ``predict(unit)``: from a test unit's records *so far* (a :class:`~faultgen.bench.files.Unit`
  whose arrays end at the time of prediction; no labels), the distribution of the time of its end of
  life: a 1-D array of samples (at least 1, at most :data:`MAX_SAMPLES`), in the time of the unit's
  records (``arrays["cycles"]``: one record a day on the prognostics track), ``numpy.inf`` for a
  sample with no end of life within the horizon; ``None``: no prediction (every sample beyond the
  horizon).

This is NASA ProgPy's shape of a prediction (a time-of-event distribution,
``progpy.uncertain_data.UnweightedSamples``), which the scoring (:mod:`faultgen.bench.prognostics`)
builds from the samples.
"""

from __future__ import annotations

import numpy as np

from faultgen.bench import files

#: Most samples a prediction may hold.
MAX_SAMPLES = 100_000
#: The latest time of end of life a sample may give (the largest cycle number a record may hold,
#: :data:`faultgen.bench.files.VALUE_RANGES`); ``inf``: none within the horizon.
MAX_TIME = float(files.VALUE_RANGES["cycles"][1])


def end_of_life(unit: files.Unit, failure_wear: float) -> float | None:
    """The time (``arrays["cycles"]``) of the first record of a labelled ``unit`` whose fault level
    reaches ``failure_wear`` %; None when it never does."""
    reached = np.flatnonzero(np.asarray(unit.fault_level, dtype=float) >= failure_wear)
    return float(unit.arrays["cycles"][reached[0]]) if reached.size else None


def prefix(unit: files.Unit, n: int) -> files.Unit:
    """``unit``'s first ``n`` records (every array cut), without labels: what a prognoser sees."""
    return files.Unit(id=unit.id, robot=unit.robot, task=unit.task, sample=unit.sample,
                      arrays={name: values[:n] for name, values in unit.arrays.items()})


class MeanLife:
    """The naive prognoser: every unit's end of life is drawn from the train split's lives (the
    time each train unit reached the failure wear), whatever its records say. The level a method
    must beat: it knows how long units live on average and nothing of the unit at hand."""

    def fit(self, units: list[files.Unit], failure_wear: float) -> MeanLife:
        lives = [end_of_life(u, failure_wear) for u in units if u.fault_level is not None]
        self.lives_ = np.array([life for life in lives if life is not None], dtype=float)
        if not self.lives_.size:
            raise ValueError(f"mean_life: no train unit reaches the failure wear {failure_wear:g} %")
        return self

    def predict(self, unit: files.Unit) -> np.ndarray:
        now = float(unit.arrays["cycles"][-1])
        # a unit still alive past a train life lives at least until now (the life's distribution, given survival)
        return np.maximum(self.lives_, now)


def load(spec: str):
    """A new prognoser from ``spec`` (``"package.module:Class"``; the current folder is searched first).

    Raises
    ------
    ValueError
        If ``spec`` is not ``module:Class``, the module cannot be imported, it has no such class,
        ``Class()`` raises, or the object lacks ``fit`` or ``predict`` (naming ``spec``).
    """
    from analysis.plugins import import_here

    module_name, _, class_name = str(spec).partition(":")
    if not module_name or not class_name.isidentifier():
        raise ValueError(f"prognoser {spec!r}: expected package.module:Class, e.g. mine:MyPrognoser")
    try:
        module = import_here(module_name)
    except (Exception, SystemExit) as err:  # noqa: BLE001 (the user's module may raise anything: named on one line)
        raise ValueError(f"prognoser {spec!r}: importing {module_name!r} failed: {type(err).__name__}: {err}") from None
    cls = getattr(module, class_name, None)
    if not isinstance(cls, type):
        raise ValueError(f"prognoser {spec!r}: module {module_name!r} has no class {class_name!r}")  # noqa: TRY004 (a wrong spec)
    try:
        made = cls()
    except Exception as err:  # noqa: BLE001
        raise ValueError(f"prognoser {spec!r}: {class_name}() failed: {type(err).__name__}: {err}") from None
    missing = [m for m in ("fit", "predict") if not callable(getattr(made, m, None))]
    if missing:
        raise ValueError(f"prognoser {spec!r}: no {' and no '.join(missing)} method; expected fit(units, failure_wear) "
                         "and predict(unit) (faultgen.bench.prognosers)")
    return made


def samples(values, name: str, now: float) -> np.ndarray:
    """A prognoser's answer as an array of times of end of life (``inf``: beyond the horizon).

    Raises
    ------
    ValueError
        Naming ``name``: not a 1-D array of 1..:data:`MAX_SAMPLES` numbers, or a sample that is
        neither ``inf`` nor a time within 0..:data:`MAX_TIME` (NaN, -inf, a negative time).
    """
    if values is None:
        return np.array([np.inf])
    try:
        out = np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{name}: predict() gave {type(values).__name__}; expected a 1-D array of times of end "
                         "of life") from None
    if out.ndim != 1 or not 1 <= out.size <= MAX_SAMPLES:
        raise ValueError(f"{name}: predict() at time {now:g} gave shape {out.shape}; expected 1..{MAX_SAMPLES} "
                         f"samples, times within 0..{MAX_TIME:g} or inf")
    bad = ~((out >= 0) & (out <= MAX_TIME) | (out == np.inf))  # NaN and -inf too
    if bad.any():
        raise ValueError(f"{name}: predict() at time {now:g} gave {int(bad.sum())} samples that are NaN, -inf or "
                         f"outside 0..{MAX_TIME:g} (the first {float(out[bad][0])!r}); expected times within "
                         f"0..{MAX_TIME:g} or inf (no end of life)")
    return out
