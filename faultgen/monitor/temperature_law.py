"""A unit's temperature law from its friction tests (:mod:`faultgen.monitor.friction_tests`, whose
docstring gives the method): the relative change of the dry level per kelvin common to the unit's axes
(the median of each axis's least-squares slope of ``ln c`` on the logged temperature), its error, each
axis's scatter about its own law and the unit's test-to-test repeatability, both from each axis's tests
before its wear shows (:func:`healthy_tests`)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

#: The temperature law: tests per axis (since its last repair) and their temperature span, K, an
#: axis needs for its slope; axes whose scatter about their law gives the repeatability.
LAW_TESTS, LAW_SPAN_K, LAW_AXES = 3, 1.0, 3
#: A test whose dry level lies this many repeatabilities above its axis's earlier tests ends the axis's
#: healthy tests, which alone teach the scatter and the repeatability (:func:`healthy_tests`; a healthy
#: axis's test passes it with a chance of 0.13 %).
HEALTHY_Z = 3.0
#: Standard error of the temperature law's slope, 1/K, when the unit's tests cannot tell it.
BETA_PRIOR = 0.005


@dataclass
class Law:
    """A unit's temperature law (module docstring): ``beta`` 1/K, its standard error ``error`` 1/K,
    the test-to-test ``repeatability`` (relative standard deviation; NaN when not known), how it
    was learned (``source``, in words) and each axis's own scatter about its law (``scatter``: axis ->
    relative standard deviation, the plant's day-to-day scatter as that axis's tests before its wear
    show it: :func:`healthy_tests`; the axes with :data:`LAW_TESTS` such tests over :data:`LAW_SPAN_K`)."""

    beta: float
    error: float
    repeatability: float
    source: str
    scatter: dict = field(default_factory=dict)


def learn_law(series: dict[int, tuple[np.ndarray, np.ndarray]]) -> Law:
    """The temperature law of a unit from each axis's tests ``{axis: (T degC, ln c)}``, in the order
    they were run, since its last repair (module docstring): the slope from every test (the median
    over the axes), the scatter from each axis's tests before its wear shows (:func:`healthy_tests`),
    so that it is the plant's and not a worn axis's wear."""
    from scipy import stats

    slopes, errors, everything = [], [], []  # each axis's slope, its error and scatter, on every test
    for t, y in series.values():
        t, y = _finite(t, y)
        if len(t) >= LAW_TESTS and np.ptp(t) >= LAW_SPAN_K:
            fit = stats.linregress(t, y)
            slopes.append(fit.slope)
            errors.append(fit.stderr)
            everything.append(math.sqrt(np.sum((y - fit.intercept - fit.slope * t) ** 2) / (len(t) - 2)))
    # each axis's tests before its wear shows, judged at the law of every test and the axes' median
    # scatter about it (which a worn axis, one of several, does not move)
    first = float(np.median(everything)) if len(everything) >= LAW_AXES else math.nan
    beta = float(np.median(slopes)) if slopes else 0.0
    scatter, repeatability = _scatter({axis: _finite(t[:n], y[:n]) for axis, (t, y) in series.items()
                                       for n in [healthy_tests(t, y, beta, first)]})
    if not slopes:
        return Law(0.0, BETA_PRIOR, repeatability, f"no axis with {LAW_TESTS} tests over {LAW_SPAN_K:g} K: "
                                                     f"not corrected (+-{100 * BETA_PRIOR:g} %/K)", scatter)
    noise = float(np.median(errors))
    spread = 1.4826 * float(np.median(np.abs(np.array(slopes) - beta))) if len(slopes) > 2 else 0.0
    # the median's own error (1.2533 sigma / sqrt(n), a normal sample's), the axes' laws' spread beyond noise
    error = float(np.sqrt((1.2533 * noise) ** 2 / len(slopes) + max(0.0, spread**2 - noise**2)))
    return Law(beta, error, repeatability, f"{100 * beta:+.2f} +- {100 * error:.2f} %/K (median of {len(slopes)} axes)",
               scatter)


def _finite(t: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    ok = np.isfinite(t) & np.isfinite(y)
    return t[ok], y[ok]


def _scatter(series: dict[int, tuple[np.ndarray, np.ndarray]]) -> tuple[dict, float]:
    """Each axis's scatter of ``ln c`` about its own line in ``T`` (the axes with :data:`LAW_TESTS`
    tests over :data:`LAW_SPAN_K`; relative standard deviations) and the unit's repeatability: their
    pooled standard deviation, ``sqrt(sum RSS / sum (n - 2))`` (ISO 5725-2's repeatability standard
    deviation, each axis its own line; unbiased in the variance, each axis weighed by its degrees of
    freedom), NaN with fewer than :data:`LAW_AXES` axes."""
    scatter, rss, dof = {}, 0.0, 0
    for axis, (t, y) in series.items():
        if len(t) < LAW_TESTS or np.ptp(t) < LAW_SPAN_K:
            continue
        slope, intercept = np.polyfit(t, y, 1)
        residual = float(np.sum((y - intercept - slope * t) ** 2))
        scatter[axis] = math.sqrt(residual / (len(t) - 2))
        rss, dof = rss + residual, dof + len(t) - 2
    return scatter, (math.sqrt(rss / dof) if len(scatter) >= LAW_AXES else math.nan)


def healthy_tests(t: np.ndarray, y: np.ndarray, beta: float, repeatability: float) -> int:
    """How many of an axis's first tests (``t`` degC, ``y`` = ``ln c``, in the order run) show no wear:
    up to the first whose dry level, corrected by the law ``beta`` (1/K), lies above the mean of the
    tests before it by more than :data:`HEALTHY_Z` times ``repeatability`` (relative standard
    deviation) times ``sqrt(1 + 1/n)``: wear only raises the dry level, and once it shows it stays. All
    of them where ``repeatability`` is not known (fewer than :data:`LAW_AXES` axes tell it)."""
    if not np.isfinite(repeatability) or repeatability <= 0:
        return len(t)
    level = y - beta * t  # NaN where a temperature or level is missing: never ends the tests
    for n in range(1, len(level)):
        kept = level[:n][np.isfinite(level[:n])]
        if kept.size and level[n] - kept.mean() > HEALTHY_Z * repeatability * math.sqrt(1 + 1 / kept.size):
            return n
    return len(t)
