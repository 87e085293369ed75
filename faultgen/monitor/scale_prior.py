"""A fleet's prior of the friction tests' scale factor (``faultgen monitor --scale-prior OTHER``): what
the twin's wear is times on the robot's friction tests' scale, learned from another monitor run of the
same robot and twin, in place of the default ``N(1,``
:data:`~faultgen.monitor.friction_tests.SCALE_PRIOR` ``^2)``.

Why: before a friction test has seen an axis's wear, its wear on the tests' scale is ``f x`` with the
factor known only to its prior, so the alarm's lower bound, ``x (f - 1.28 s_f)``, passes an 8 % limit
only at a twin-scale wear of 8 / (1 - 1.28 x 0.3) = 13.0 %; the ideal estimator of
``benchmarks/real_cell_ceiling.py`` put every first alarm of the 3 % real-cell fleet in 8-15 % with a
chance of 0.17-0.45 at that prior, 1.00 at a prior of 0.15 around the fleet's factor (docs/analysis.md,
"Issue 90: a fleet's scale prior"). The factor is the twin's (its friction model against the plant's
wear law), so units of one robot model and twin share it up to a scatter between units; the units of
a run whose friction tests saw their wear tell it.

How: from ``OTHER/wear.csv`` (its ``scale_factor`` and ``scale_factor_sd``, written by a run with
friction tests), per unit and axis the factor of its first log on the tests' scale whose tests told it
(its standard error at most :data:`INFORMATIVE` times the default prior's: the tests gave at least three
quarters of its precision): the factor as the tests first saw the wear, the stage at which a new unit's
prior matters (later the unit's own tests outweigh it, and the factor drifts with the wear,
:data:`~faultgen.monitor.friction_tests.SCALE_DRIFT`). A new unit's factor is taken as one more draw of
those ``k`` factors: the normal prediction interval (Hahn, Meeker & Escobar, *Statistical Intervals*, 2nd
ed. 2017, ch. 4.6) ``m -+ t(0.9, k - 1) s sqrt(1 + 1/k)``, ``m`` and ``s`` their mean and standard
deviation, whose one-sided 90 % bound (the alarm's quantile) a normal prior keeps:
``sd = s sqrt(1 + 1/k) t(0.9, k - 1) / z(0.9)``. The factors' spread counts their own estimation error as
scatter between units (a wider prior than a random-effects model's, whose variance between units came out 0
on the 3 % fleet's 7 factors: a prior of +- 0.05 where they lie 0.85-1.14). Not independent of the
monitor: the factors are its own fits, each also shrunk a little towards 1 by the default prior of the
run they come from.
"""

from __future__ import annotations

import csv
import io
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from faultgen import inputs
from faultgen.monitor.alarm import WEAR_ALARM_CONFIDENCE
from faultgen.monitor.friction_tests import SCALE_PRIOR, TESTS_SCALE

#: An axis's factor tells the fleet's prior when its standard error is at most this share of the default
#: prior's (0.5: the tests gave at least three quarters of its precision; a healthy axis's stays at the
#: prior).
INFORMATIVE = 0.5
#: Fewest units' axes a fleet's prior rests on (with two, the prediction interval's t(0.9, 1) is 3.08).
MIN_AXES = 3
#: The columns of wear.csv the prior is learned from.
COLUMNS = ("unit", "axis", "wear_scale", "scale_factor", "scale_factor_sd")
#: The one-sided quantile the prior keeps: the alarm's bound's
#: (:data:`faultgen.monitor.alarm.WEAR_ALARM_CONFIDENCE`).
QUANTILE = WEAR_ALARM_CONFIDENCE
#: Size bound of the wear.csv read (some 100 bytes a row: 10^6 log-axes).
WEAR_MAX_BYTES = 200 * 2**20


@dataclass(frozen=True)
class ScalePrior:
    """The scale factor's prior (module docstring): ``mean`` and ``sd``, the predictive standard deviation
    (dimensionless, the twin's wear times it is the wear on the tests' scale), ``spread`` the factors'
    standard deviation, ``axes`` the units' axes it rests on, ``source`` the output folder it was learned
    from. Raises ValueError for a mean or sd that is not a finite number above 0."""

    mean: float
    sd: float
    spread: float = math.nan
    axes: int = 0
    source: str = ""

    def __post_init__(self) -> None:
        for name in ("mean", "sd"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
                raise ValueError(f"scale prior {name} = {value!r}; expected a finite number above 0")

    @property
    def pair(self) -> tuple[float, float]:
        """(mean, sd), as :class:`faultgen.monitor.friction_tests.Rescale` takes it."""
        return float(self.mean), float(self.sd)

    def note(self) -> str:
        """What the console says of it."""
        return (f"scale prior {self.mean:.3f} +- {self.sd:.3f}: the factor onto the friction tests' scale "
                f"where the tests first saw the wear on {self.axes} units' axes of {self.source} (standard "
                f"deviation {self.spread:.3f}; a new unit's, normal prediction; the default "
                f"1 +- {SCALE_PRIOR:g})")


def informative_factors(rows: list[dict], where: str) -> list[tuple[str, int, float, float]]:
    """``(unit, axis, factor, standard error)`` of each unit's axis at its first row of wear.csv (``rows``,
    in the file's order: each unit's logs in stamp order) on the tests' scale with a factor its tests told
    (:data:`INFORMATIVE`). Raises ValueError naming ``where`` and the row for a factor that is no number."""
    first: dict[tuple[str, int], tuple[float, float]] = {}
    for line, row in enumerate(rows, start=2):
        if row.get("wear_scale") != TESTS_SCALE:
            continue
        try:
            key = (row["unit"], int(row["axis"]))
            factor, sd = float(row["scale_factor"]), float(row["scale_factor_sd"])
        except (TypeError, ValueError):
            raise ValueError(f"{where}, line {line}: axis {row.get('axis')!r}, scale_factor "
                             f"{row.get('scale_factor')!r}, scale_factor_sd {row.get('scale_factor_sd')!r}; "
                             "expected a whole number and two numbers") from None
        if key not in first and math.isfinite(factor) and factor > 0 and 0 < sd <= INFORMATIVE * SCALE_PRIOR:
            first[key] = (factor, sd)
    return [(unit, axis, f, s) for (unit, axis), (f, s) in first.items()]


def pooled(factors: np.ndarray, source: str = "") -> ScalePrior:
    """The fleet's prior from ``factors`` ((k,), k >= :data:`MIN_AXES`): their mean, and the normal
    prediction interval's one-sided 90 % bound kept (module docstring). ValueError for fewer factors."""
    from scipy import stats

    factors = np.asarray(factors, dtype=float)
    k = len(factors)
    if k < MIN_AXES:
        raise ValueError(f"{k} units' axes whose friction tests saw their wear (a factor's error at most "
                         f"{INFORMATIVE * SCALE_PRIOR:g}); expected at least {MIN_AXES} for a fleet's "
                         "scale prior")
    spread = float(np.std(factors, ddof=1))
    z, t = stats.norm.ppf(QUANTILE), stats.t.ppf(QUANTILE, k - 1)
    return ScalePrior(float(np.mean(factors)), spread * math.sqrt(1 + 1 / k) * t / z, spread, k, source)


def learn(out: str | Path) -> ScalePrior:
    """The fleet's scale prior learned from the monitor output folder ``out`` (module docstring).

    Raises
    ------
    ValueError
        ``out/wear.csv`` missing, too large, a link out of ``out``, without the columns
        :data:`COLUMNS` (a run without friction tests, or of a faultgen before them), a bad number, or
        fewer than :data:`MIN_AXES` axes whose tests saw their wear.
    """
    out = Path(out)
    path = out / "wear.csv"
    if not path.is_file():
        raise ValueError(f"--scale-prior {out}: no wear.csv there; expected the output folder of a "
                         "`faultgen monitor` run with friction tests on the same robot")
    if not inputs.inside(path, out):
        raise ValueError(f"{path}: a link leading outside {out}; it is not read")
    text = inputs.read_text(path, "monitor wear table", WEAR_MAX_BYTES)
    rows = list(csv.DictReader(io.StringIO(text, newline="")))
    missing = [c for c in COLUMNS if rows and c not in rows[0]]
    if not rows or missing:
        raise ValueError(f"{path}: no column {', '.join(missing or COLUMNS)}; expected a monitor run with "
                         "friction tests by this faultgen (score that fleet again)")
    kept = informative_factors(rows, str(path))
    try:
        return pooled(np.array([k[2] for k in kept]), str(out))
    except ValueError as err:
        raise ValueError(f"--scale-prior {out}: {err}") from None
