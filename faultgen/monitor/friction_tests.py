"""A unit's friction tests in ``faultgen monitor``: each axis's wear read
directly, and the production logs' wear put on the tests' scale.

**The folder.** ``LOGS/<unit>/friction-test/<stamp><suffix>`` (:data:`faultgen.data.logfolder.TESTS`):
the suffixes, ``--format`` and stamps of the unit's logs, listed and checked as they are
(:func:`faultgen.data.logfolder.scan_tests`: names, links, stamps; read by the logs' reader and
within its bounds, :func:`faultgen.monitor.logs.parse`); never taken as a production log. A test's
stamps must be of the kind of its unit's logs (dates, or sequence numbers), so that a test falls
between two logs.

**A test read** (:func:`read_tests`): :func:`faultgen.calibrate.friction_report.read` (segments
found, direction differencing, each axis's curve fitted with 95 % intervals; docs/friction-test.md),
once: the fit is cached in ``OUT/.cache/friction-tests`` under the test's SHA-256, the robot's and
the log format (a continued run reads no test twice). A test that cannot be read is named in its
unit's reason and left out.

**Each test's wear** (:func:`tests_wear`), per axis ``k`` read, from the tests since the axis's last
repair or gearbox change (``events.csv``), the first of them the reference ``0``: the dry level
``c`` (``coulomb_Nm``) at the test's logged temperature ``T`` (``temperature_degC``), corrected to
the reference's temperature ``T0`` by the unit's own **temperature law** ``ln c = a_k + beta T``
(a relative change per kelvin common to the unit's axes, each axis its own level ``a_k``)::

    wear = 100 (exp(ln c - ln c0 - beta (T - T0)) - 1)  %

``beta`` is learned from the unit's own tests (:mod:`.temperature_law`): the median over its axes of
each axis's least-squares slope of ``ln c`` on ``T`` (``scipy.stats.linregress``; axes with at least
:data:`.temperature_law.LAW_TESTS` tests spanning at least :data:`.temperature_law.LAW_SPAN_K` K), the
median so that the worn axis, whose slope carries its wear (the season and the wear both grow), does
not move it; its standard error ``s_beta`` the median's own (``1.2533 s / sqrt(n)``, ``s`` the median
of the ``n`` slopes' standard errors: the median of a normal sample) and the axes' scatter about the
median (1.4826 times the median absolute deviation) beyond ``s``, the axes' own laws, together.
Without such axes ``beta`` is 0 with ``s_beta`` = :data:`.temperature_law.BETA_PRIOR` (a stated
assumption: dry friction moves by some 0.5 %/K, Bittencourt 2014); without logged temperatures no
correction is made. The **90 % interval** (:data:`INTERVAL`) is that
of ``ln c - ln c0 - beta (T - T0)`` with the variance ``v + v0 + s_beta^2 (T - T0)^2``, ``v`` the
larger of the fit's own (``(coulomb_Nm_high - coulomb_Nm_low) / (2 1.96 c)``, squared) and the
unit's test-to-test repeatability (the pooled standard deviation of ``ln c`` about each axis's own
temperature law, ISO 5725-2's, when at least :data:`.temperature_law.LAW_AXES` axes give it: what a
test's day adds, the lubricant film, that no fit of one test sees), each axis counted on its tests
before its wear shows (:func:`.temperature_law.healthy_tests`: up to the first test whose corrected dry
level lies :data:`.temperature_law.HEALTHY_Z` of the axes' median scatter above the axis's earlier
tests), so that it is the plant's scatter, not a worn axis's wear.

**The logs on the tests' scale** (:class:`Rescale`): per axis, the tests' wear ``y_j`` against the
monitor's own wear in the twin's scale ``x_j`` at the test's day (the filtered wear of the last log
at or before it, :class:`faultgen.monitor.wear_trend.WearTrend`), the tests after the reference (0 by
definition, its error ``b``'s prior), is the line ``y = b + F x``, ``F = f (1 + b/100)`` (the
reference's error is a factor on every later test's dry level: ``f`` is
:func:`.bounds.reference_factor`'s), fitted by weighted least squares (``statsmodels`` WLS, weights
one over ``var y_j + var x_j``) with the priors of mixed estimation (Theil & Goldberger 1961: one
pseudo-observation each) ``f ~ N(1,`` :data:`SCALE_PRIOR` ``^2)`` (on ``F``, times ``1 + b/100`` of
the fit before) and ``b ~ N(0, s0^2)`` (``b``: the reference test's own error, which every
test's wear shares; ``s0`` that test's own standard error in points, :data:`OFFSET_PRIOR` where it is
not known; the tests before the wear fix it), each test weighed by its own error and the twin-scale
wear's error times ``f`` (weighed at ``f = 1``, then at the fitted ``f``) and by the factor's drift since
the test, :data:`SCALE_DRIFT` times ``x_j`` per later test (the twin's scale may change with the wear; a test
before the wear keeps telling ``b``); the tests' variances (``b``'s prior's too) times their reduced chi-square if
above one, their measured part's upper 90 % limit if below (:func:`.bounds.upper_ratio`), never ``f``'s prior,
but a fleet's up to the default's (:mod:`.scale_prior`; the degrees of freedom: the pairs less their leverages).
A log's wear in the tests' scale is ``f x`` (``f`` from the tests up to the log: what the monitor
knew then), the alarm judged on it (``f`` times the lower bound), and its 90 % interval
``f x -+ z sqrt(f^2 e^2 + s_f^2 x^2)``, ``e`` the filtered wear's own error: the factor's error
``s_f`` in place of the twin's :data:`faultgen.monitor.scoring.SCALE_UNCERTAINTY`, and the filter's
error in place of the log's own (the errors that stay for weeks are the factor's on the tests' scale;
measured in docs/analysis.md). The tests' wear (and so each factor) uses the temperature law as all of
the unit's tests read so far give it: a later test may move an earlier log's wear a little. The remaining life
(:func:`remaining_life`) gets each axis's series rescaled by its latest ``f`` and ``s_f / f`` as the
scale's uncertainty. An axis no test read, and every log before its unit's first test, stay twin-scale.

``OUT/tests.csv`` (:func:`tests_table`, :data:`COLUMNS`): one row per unit, test and axis read;
``scatter_percent`` the axis's day-to-day scatter as the unit's tests show it (the standard deviation
of ``ln c`` about the axis's own temperature law over its tests before its wear shows, %:
:attr:`Law.scatter`; empty for an axis with fewer than :data:`.temperature_law.LAW_TESTS` such tests
over :data:`.temperature_law.LAW_SPAN_K`), the plant's scatter that every test's and log's read carries
(issue 90; the logs' own on the learning days: the alarm's evidence).
"""

from __future__ import annotations

import dataclasses
import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from statistics import NormalDist

import numpy as np

from faultgen import inputs
from faultgen.calibrate import friction_fit, friction_report
from faultgen.data import cells, logfolder
from faultgen.logs import formats
from faultgen.monitor import bounds
from faultgen.monitor import logs as fleet_logs
from faultgen.monitor import state as stored
from faultgen.monitor.record import Table
from faultgen.monitor.temperature_law import Law, learn_law

#: ``wear_scale`` of a unit's wear (units.csv, wear.csv): on its friction tests' scale, or its twin's.
TESTS_SCALE, TWIN_SCALE = "friction test", "twin"
#: ``wear_scale`` of a unit whose twin fell back to the nominal model (its calibration failed): % of
#: the nominal model's dry friction, not the unit's own (:func:`faultgen.monitor.loop.monitor`).
NOMINAL_SCALE = "nominal model"
#: The columns of ``OUT/tests.csv`` (the friction_fit.csv columns of ``faultgen friction-test``, arm side).
FIT_COLUMNS = ("temperature_degC", "coulomb_Nm", "coulomb_Nm_low", "coulomb_Nm_high", "static_excess_Nm",
               "stribeck_velocity_rad_s", "viscous_Nms_rad", "viscous_Nms_rad_low", "viscous_Nms_rad_high")
COLUMNS = ("unit", "stamp", "axis", *FIT_COLUMNS, "wear", "wear_lower", "wear_upper", "verdict", "scatter_percent")
#: The two-sided interval of a test's wear and of the logs' wear on the tests' scale.
INTERVAL = 0.90
#: Standard deviation of the prior of the scale factor ``f`` (mean 1: the twin's scale). The factor
#: that maps the twin's scale best onto the truth was 0.80-1.08 on the first independent fleet's worn
#: units and 0.50-0.81 on the second's (seed 0), and a test reads a dry level to some 3 %
#: (the plant's scatter from day to day, not the fit's). Median errors at 0.3 and 0.5, and held out:
#: docs/analysis.md, "The wear on the friction tests' scale".
SCALE_PRIOR = 0.3
#: Standard deviation of the prior of the offset ``b``, points of wear, where the reference test's own
#: error is not known (otherwise that error: ``b`` is the reference's error, which every later test's
#: wear shares; docs/analysis.md, "The wear on the friction tests' scale").
OFFSET_PRIOR = 10.0
#: Smallest scale factor used (a factor fitted below it on an axis whose tests contradict its logs).
SCALE_MIN = 0.2
#: The factor's random walk, its standard deviation per test (the twin's scale need not be one number
#: over the whole wear: on the second independent fleet it grew with the wear): an earlier pair's
#: variance grows by ``(SCALE_DRIFT x)^2`` per later test, so that the pairs before the wear keep telling
#: the offset ``b`` (0.06: a pair at ``x`` 20 % weighs what the earlier forgetting's 0.6 gave it after one
#: test; docs/analysis.md, "the factor is a random walk").
SCALE_DRIFT = 0.06
#: The cache of the tests' readings in OUT, its entries' format and largest size, bytes.
CACHE, CACHE_FORMAT, CACHE_MAX_BYTES = "friction-tests", "faultgen-friction-test-reading/1", 2**20
#: The range of a reading's values (cached or fresh): torques and torque per speed at most this in
#: magnitude (N m, N m s/rad, rad/s; 1000 times a large robot's gearbox torque), a temperature within
#: :data:`TEMPERATURE_RANGE` degC, a dry level below :data:`MIN_DRY_NM` read as none (no wear): the
#: wear's arithmetic stays within floating point (a ratio of dry levels below 1e16).
VALUE_MAX, TEMPERATURE_RANGE, MIN_DRY_NM = 1e7, (-273.15, 1000.0), 1e-9
#: A test's dry level (temperature-corrected) over its reference's beyond ``exp(+-LN_FACTOR_MAX)`` (a
#: factor of 1e6) reads no wear: another gearbox, torque channel or unit.
LN_FACTOR_MAX = math.log(1e6)
#: The fit's interval (friction_fit's 95 %) as a standard error: its half width over this.
FIT_Z = float(NormalDist().inv_cdf(0.5 + friction_fit.LEVEL / 2))


@dataclass(frozen=True)
class FrictionTest:
    """One friction test of a unit as read: ``stamp``, ``key`` (its stamp's sort key), the file's
    ``sha256``, ``fits`` (one dict per axis read: ``axis`` 1..N and :data:`FIT_COLUMNS`) and
    ``error`` (why it could not be read; "" when read)."""

    stamp: str
    key: float
    sha256: str
    fits: tuple[dict, ...] = ()
    error: str = ""


def find(logs_dir: Path, units: dict[str, list], suffixes: tuple[str, ...],
         passed: list[tuple[str, str]] | None = None) -> dict[str, list]:
    """Each unit's tests (:func:`faultgen.data.logfolder.scan_tests`), units without a test folder
    or with an empty one left out (a fleet without tests is monitored as before them). A file there
    that is not a test is passed over and added to ``passed`` (``(name, reason)``, as a unit's logs
    are: :func:`faultgen.monitor.logs.fleet`); without ``passed``, ValueError before any work naming
    it. ValueError for stamps of another kind than the unit's logs."""
    found, bad = logfolder.scan_tests(Path(logs_dir), list(units), suffixes)
    if passed is not None:  # a link out of the folder is refused, never passed over
        passed.extend((name, reason) for name, reason in bad if reason != logfolder.LINK_OUT)
        bad = [(name, reason) for name, reason in bad if reason == logfolder.LINK_OUT]
    if bad:
        name, reason = bad[0]
        more = f" (and {len(bad) - 1} more)" if len(bad) > 1 else ""
        raise ValueError(f"{Path(logs_dir) / name}: {reason}{more}")
    for unit, tests in found.items():
        logs = units[unit]
        if tests and logs and tests[0].kind != logs[0].kind:
            raise ValueError(f"{tests[0].path}: a friction test stamped by {tests[0].kind} where the unit's logs are "
                             f"stamped by {logs[0].kind} ({logs[0].name}); use one kind per unit")
    return {unit: tests for unit, tests in found.items() if tests}  # an empty folder: as none


def _cache_key(robot_sha256: str, sha256: str, log_format: str) -> dict:
    return {"robot": robot_sha256, "test": sha256, "format": log_format, "reader": CACHE_FORMAT}


def read_tests(found: dict[str, list], robot, out: Path,
               log_format: formats.LogFormat = formats.MEASURED) -> dict[str, list[FrictionTest]]:
    """Each unit's tests read (module docstring), in stamp order: from ``OUT/.cache/friction-tests``
    when an earlier run read the same bytes (checked against its key), else parsed by the logs'
    reader (``log_format``, :func:`faultgen.monitor.logs.reader_of`) and fitted, and cached."""
    reader, _ = fleet_logs.reader_of(log_format)
    held = bool(log_format.reads_held)
    robot_sha256 = stored.sha256_file(robot.path)
    fmt = log_format.key
    confined = stored.out_folder(out)
    root = Path(out) / ".cache" / CACHE
    read: dict[str, list[FrictionTest]] = {}
    for unit, tests in found.items():
        read[unit] = []
        for log in tests:
            try:  # its size first: a sparse test of terabytes apparent is refused unread
                digest = fleet_logs.log_sha256(log.path)
            except OSError as err:
                read[unit].append(FrictionTest(log.stamp, log.key, "", error=f"cannot be read ({err.strerror or err})"))
                continue
            except inputs.InputError as err:
                read[unit].append(FrictionTest(log.stamp, log.key, "", error=str(err)[:300]))
                continue
            key = _cache_key(robot_sha256, digest, fmt)
            path = root / f"{stored.key_name(key)}.json"
            if path.exists() or path.is_symlink():
                read[unit].append(_cached(path, out, key, log))
                continue
            parsed = fleet_logs.parse(log.path, robot, reader, held)
            test = _reading(parsed, robot, log)
            confined.mkdir(root)
            key = _cache_key(robot_sha256, parsed.sha256 or digest, fmt)
            confined.write_text(root / f"{stored.key_name(key)}.json",
                                json.dumps({"format": CACHE_FORMAT, "key": key, "fits": list(test.fits),
                                            "error": test.error}))
            read[unit].append(test)
    return read


def _reading(parsed: fleet_logs.Parsed, robot, log) -> FrictionTest:
    """A parsed test fitted (:func:`faultgen.calibrate.friction_report.read`), or why not."""
    try:
        fits = friction_report.read(parsed.checked(), robot).fits
    except ValueError as err:
        text = " ".join(str(err).split())
        return FrictionTest(log.stamp, log.key, parsed.sha256, error=text[:300])
    rows = tuple({"axis": int(r["axis"]), **{c: float(r[c]) for c in FIT_COLUMNS}} for _, r in fits.iterrows())
    wrong = next(filter(None, map(out_of_range, rows)), "")
    if wrong:
        return FrictionTest(log.stamp, log.key, parsed.sha256, error=f"its fit gives {wrong}")
    return FrictionTest(log.stamp, log.key, parsed.sha256, rows)


def out_of_range(fit: dict) -> str:
    """Why a reading's ``fit`` of one axis (``axis`` and :data:`FIT_COLUMNS`) holds a value no test
    reads (:data:`VALUE_MAX`, :data:`TEMPERATURE_RANGE`: infinite, or beyond them; NaN is a value
    the fit leaves out), naming the axis, column and value; "" when none."""
    for column in FIT_COLUMNS:
        value = fit[column]
        low, high = TEMPERATURE_RANGE if column == "temperature_degC" else (-VALUE_MAX, VALUE_MAX)
        if not (math.isnan(value) or low <= value <= high):
            return f"axis {fit['axis']} {column} = {value:g}, outside {low:g}..{high:g}"
    return ""


def _cached(path: Path, out: Path, key: dict, log) -> FrictionTest:
    """A cached reading, checked (a :class:`faultgen.monitor.state.StateError` naming the file otherwise)."""
    d = stored.load_json(stored.inside(path, out), "cached friction test reading", CACHE_MAX_BYTES)
    fits, error = d.get("fits"), d.get("error")
    ok = d.get("format") == CACHE_FORMAT and d.get("key") == key and isinstance(error, str) and isinstance(fits, list)
    ok = ok and all(isinstance(f, dict) and isinstance(f.get("axis"), int) and not isinstance(f.get("axis"), bool)
                    and all(isinstance(f.get(c), (int, float)) and not isinstance(f.get(c), bool) for c in FIT_COLUMNS)
                    for f in fits)
    if not ok:
        raise stored.StateError(f"{path}: not the cached reading of the friction test {log.name}; delete it (the test "
                                "is read again)")
    try:
        wrong = next(filter(None, (out_of_range({c: float(f[c]) for c in FIT_COLUMNS} | {"axis": f["axis"]})
                                   for f in fits)), "")
    except OverflowError:  # an integer beyond a float's range
        wrong = "a number beyond a float's range"
    if wrong or any(f["axis"] < 1 for f in fits):
        raise stored.StateError(f"{path}: the cached reading of the friction test {log.name} holds "
                                f"{wrong or 'an axis below 1'}, which no test reads; delete it (the test is read "
                                "again)")
    return FrictionTest(log.stamp, log.key, key["test"], tuple({c: (int(f[c]) if c == "axis" else float(f[c]))
                                                       for c in ("axis", *FIT_COLUMNS)} for f in fits), error)


@dataclass
class AxisWear:
    """One test's wear of one axis (module docstring): ``wear`` % and its 90 % interval, its
    standard error in ``ln`` (``log_error``), the reference's own (``reference_error``), the verdict."""

    stamp: str
    key: float
    axis: int
    fit: dict
    wear: float
    lower: float
    upper: float
    log_error: float
    reference_error: float
    verdict: str
    reference: bool = False
    own_error: float = math.nan  # its own error in ln, the reference's apart (what the scale's fit weighs it by)
    scatter: float = math.nan  # the axis's tests' scatter about the unit's temperature law, relative (Law.scatter)


def _relative_error(fit: dict) -> float:
    c, low, high = fit["coulomb_Nm"], fit["coulomb_Nm_low"], fit["coulomb_Nm_high"]
    if not (np.isfinite(low) and np.isfinite(high)) or c <= 0:
        return math.nan
    return (high - low) / (2 * FIT_Z * c)


def tests_wear(tests: list[FrictionTest], n_axes: int, maintenance=()) -> tuple[list[AxisWear], Law | None]:
    """Each read axis's wear at each test (module docstring), and the unit's temperature law; the
    ``maintenance`` events (repairs, gearbox changes: ``key`` and ``axis``) start an axis's tests again."""
    segments: dict[int, list[list[tuple[FrictionTest, dict]]]] = {}  # axis -> its tests between repairs
    for test in tests:
        if test.error:
            continue
        for fit in test.fits:
            k = fit["axis"]
            if not 1 <= k <= n_axes:
                continue
            events = [m.key for m in maintenance if m.axis in (k, 0) and m.key <= test.key]
            reset = max(events) if events else -math.inf
            mine = segments.setdefault(k, [[]])
            if mine[-1] and mine[-1][-1][0].key < reset:
                mine.append([])
            mine[-1].append((test, fit))
    series = {}
    for k, mine in segments.items():  # the law from each axis's tests since its last repair
        good = [(t, f) for t, f in mine[-1] if f["coulomb_Nm"] > MIN_DRY_NM]
        series[k] = (np.array([f["temperature_degC"] for _, f in good]), np.log([f["coulomb_Nm"] for _, f in good]))
    if not segments:
        return [], None
    law = learn_law(series)
    z = NormalDist().inv_cdf(0.5 + INTERVAL / 2)
    rows = []
    for k, items in ((k, items) for k, mine in sorted(segments.items()) for items in mine):
        reference = next(((t, f) for t, f in items if f["coulomb_Nm"] > MIN_DRY_NM), None)
        for test, fit in items:
            if reference is None or not fit["coulomb_Nm"] > MIN_DRY_NM:
                rows.append(AxisWear(test.stamp, test.key, k, fit, math.nan, math.nan, math.nan, math.nan, math.nan,
                                     no_wear_verdict(k, fit["coulomb_Nm"])))
                continue
            t0, f0 = reference
            error0 = _spread(f0, law)
            dt = fit["temperature_degC"] - f0["temperature_degC"]
            corrected = np.isfinite(dt)
            d = math.log(fit["coulomb_Nm"]) - math.log(f0["coulomb_Nm"]) - (law.beta * dt if corrected else 0.0)
            if test is not t0 and not abs(d) <= LN_FACTOR_MAX:  # no wear: another gear, channel or unit
                verdict = (f"dry level {fit['coulomb_Nm']:.4g} N m against {t0.stamp}'s {f0['coulomb_Nm']:.4g} N m, a "
                           f"factor of e^{d:.3g} after the temperature correction: beyond any wear (another gearbox, "
                           "torque channel or unit?); no wear")
                rows.append(AxisWear(test.stamp, test.key, k, fit, *[math.nan] * 5, verdict))
                continue
            if test is t0:
                sd = own = error0
                verdict = f"reference: the first test since the axis's last repair (temperature law {law.source})"
                d = 0.0
            else:
                own = math.sqrt(_spread(fit, law) ** 2 + ((law.error * dt) ** 2 if corrected else 0.0))
                sd = math.sqrt(own**2 + error0**2)
                verdict = (f"dry level {100 * (math.exp(d) - 1):+.1f} % over {t0.stamp}'s"
                           + (f", corrected from {fit['temperature_degC']:.1f} to {f0['temperature_degC']:.1f} degC"
                              if corrected else ", no temperature logged: not corrected"))
            sd = sd if np.isfinite(sd) else math.nan
            rows.append(AxisWear(test.stamp, test.key, k, fit, 100 * (math.exp(d) - 1),
                                 100 * (_exp(d - z * sd) - 1), 100 * (_exp(d + z * sd) - 1), sd, error0,
                                 verdict, test is t0, own))
    rows = [dataclasses.replace(r, scatter=law.scatter.get(r.axis, math.nan)) for r in rows]
    rows.sort(key=lambda r: (r.key, r.axis))
    return rows, law


def _exp(x: float) -> float:
    """``exp(x)``, inf where it leaves floating point (an interval's end of a test read loosely)."""
    return math.inf if x >= 709.0 else math.exp(x)  # NaN stays NaN


def no_wear_verdict(axis: int, coulomb: float) -> str:
    """tests.csv's verdict on a test of ``axis`` whose dry level ``coulomb`` (N m, arm side) is no
    positive one: a negative level names its likely cause."""
    if coulomb < 0:
        return (f"dry level read negative ({coulomb:.4g} N m): a likely sign error (tau{axis} or q{axis} "
                f"negated against the other) or side error (a motor-side torque referred to the arm through a "
                f"gear ratio of the wrong sign); check the log's sign convention; no wear")
    return "no positive dry level read: no wear"


def _spread(fit: dict, law: Law) -> float:
    """A test's relative standard error of its dry level: the fit's, or the unit's repeatability when larger."""
    own = _relative_error(fit)
    values = [v for v in (own, law.repeatability) if np.isfinite(v)]
    return max(values) if values else math.nan


@dataclass
class Rescale:
    """The factors that put a unit's wear on its tests' scale (module docstring), fed the twin-scale wear log by log
    (:meth:`at`): ``wears`` the tests' :class:`AxisWear` in stamp order; ``prior`` the factor's (mean, standard
    deviation): ``(1,`` :data:`SCALE_PRIOR` ``)``, or a fleet's (:mod:`faultgen.monitor.scale_prior`)."""

    unit: str
    n_axes: int
    wears: list[AxisWear]
    pairs: dict[int, list[tuple[float, float, float, float]]] = field(default_factory=dict)  # axis -> (y, sy, x, sx)
    last: tuple[float, np.ndarray, np.ndarray] | None = None  # key, twin-scale wear and error of the last log
    done: int = 0  # wears paired so far
    offset_sd: dict[int, float] = field(default_factory=dict)  # axis -> its reference test's own error, points
    # axis -> its last test read at once (bounds.test_read): (f, s_f) before, (y less b, s_y, x_t, e_t), log
    read: dict[int, tuple] = field(default_factory=dict)
    floors: dict[int, float] = field(default_factory=dict)  # axis -> the alarm's bound on its last test's log
    tested: set = field(default_factory=set)  # axes whose test was read into the last log (floored)
    referenced: set = field(default_factory=set)  # axes whose reference test came since their last reset
    prior: tuple[float, float] = (1.0, SCALE_PRIOR)
    fits: dict[int, tuple] = field(default_factory=dict)  # axis -> (its pairs, offset and prior; its fit)

    def reset(self, axis: int = 0) -> None:
        """Forget the pairs of ``axis`` (0: every axis): a repair, a new program."""
        for k in list(self.pairs) if axis == 0 else [axis]:
            self.pairs[k] = []
            self.read.pop(k, None)
            self.floors.pop(k, None)
            self.referenced.discard(k)

    def at(self, stamp: str, wear: np.ndarray, error: np.ndarray) -> tuple[np.ndarray, np.ndarray, list[str]]:
        """The factor ``f`` (n_axes,) and its standard error for the log ``stamp`` whose filtered wear
        in the twin's scale is ``wear`` % -+ ``error`` % (each (n_axes,)), and each axis's scale's
        name; the tests up to the log paired with the last log at or before each."""
        key = logfolder.parse_stamp(stamp, f"{self.unit}/{stamp}")[0]
        while self.done < len(self.wears) and self.wears[self.done].key <= key:
            w = self.wears[self.done]
            self.done += 1
            if w.log_error != w.log_error or (self.last is None and w.key < key):  # before any log: no pair
                continue
            source = (wear, error) if w.key == key or self.last is None else self.last[1:]
            if w.reference_error == w.reference_error and w.reference_error > 0:
                self.offset_sd[w.axis] = 100 * w.reference_error
            if w.reference:  # reads 0 by definition: its error is the offset b (its prior), not a pair's
                self.reset(w.axis)
                self.referenced.add(w.axis)
                continue
            sy = 100 * (1 + w.wear / 100) * w.own_error
            x = (float(source[0][w.axis - 1]), float(source[1][w.axis - 1]))
            # the test read at once (bounds.test_read), on the factor known before it, less the reference's b
            before, offset = self._fitted(w.axis) if self.pairs.get(w.axis) else \
                (self.prior, (0.0, self.offset_sd.get(w.axis, OFFSET_PRIOR)))
            test = (*bounds.less_reference(w.wear, sy, *offset), *x)
            self.read[w.axis] = (before, test, key if w.key == key else self.last[0])
            self.floors.pop(w.axis, None)
            self.pairs.setdefault(w.axis, []).append((w.wear, sy, *x))
        self.last = (key, np.asarray(wear, dtype=float), np.asarray(error, dtype=float))
        # an axis no test has paired yet: the twin's scale, known to the factor's prior (module bounds)
        factor, factor_error = np.full(self.n_axes, self.prior[0]), np.full(self.n_axes, self.prior[1])
        names = [TWIN_SCALE] * self.n_axes
        for k, pairs in self.pairs.items():  # an axis with its reference only: on its scale, at the prior
            if pairs or k in self.referenced:
                names[k - 1] = TESTS_SCALE
            if pairs:
                factor[k - 1], factor_error[k - 1] = self._fitted(k)[0]
        return factor, factor_error, names

    def wear(self, wear: np.ndarray, error: np.ndarray, factor: np.ndarray,
             factor_error: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The wear on the tests' scale of the log :meth:`at` was last called for and its standard
        error, points (both (n_axes,)), from its twin-scale filtered ``wear`` % -+ ``error`` %: ``f x``
        -+ ``sqrt((f e)^2 + (s_f x)^2)`` (``factor``, ``factor_error``), or, on the log a test of the
        axis was paired with (a test since its reference), that test read into it at once
        (:func:`faultgen.monitor.bounds.test_read`, on the factor known before the test), less the reference's
        error ``b`` its pairs tell (:func:`.bounds.less_reference`). On the later logs the test is in the
        factor alone (carried on by the logs' growth, a fast unit's lagging filter was read as a scale),
        its log's bound a floor of theirs."""
        wear, error = np.asarray(wear, dtype=float), np.asarray(error, dtype=float)
        value = factor * wear
        sd = np.asarray(bounds.standard_error(factor * error, value, factor_error / factor), dtype=float)
        self.tested = set()
        for k, (before, test, logged) in self.read.items():
            if logged == self.last[0]:  # the test's own log
                value[k - 1], sd[k - 1] = bounds.test_read(before, (wear[k - 1], error[k - 1]), test, True)
                self.tested.add(k)
        return value, sd

    def floored(self, bound: np.ndarray) -> np.ndarray:
        """The alarm's lower ``bound`` (n_axes,) of the log :meth:`wear` was last called for, each axis's
        at least the one on its last test's log (which sets it) until its next test or repair: a wear
        does not fall, so a lower bound of it then is one of every later day's, as likely true."""
        bound = np.array(bound, dtype=float)
        for k in self.tested:
            self.floors[k] = float(bound[k - 1])
        for k, floor in self.floors.items():
            if k not in self.tested and floor > bound[k - 1]:
                bound[k - 1] = floor
        return bound

    def _fitted(self, axis: int) -> tuple[tuple[float, float], tuple[float, float]]:
        """(The factor, its sd), (the offset ``b``, points, its sd) of ``axis``; refitted on a test's day."""
        key = (tuple(self.pairs[axis]), self.offset_sd.get(axis, OFFSET_PRIOR), self.prior)
        if self.fits.get(axis, (None,))[0] != key:
            self.fits[axis] = (key, _fit(*key))
        return self.fits[axis][1]


def _fit(pairs: tuple, sb: float, prior: tuple) -> tuple[tuple[float, float], tuple[float, float]]:
    """:meth:`Rescale._fitted` of ``pairs`` (y, sy, x, sx), offset prior ``sb``, factor ``prior``."""
    import statsmodels.api as sm

    (y, sy, x, sx), n, (factor, prior_sd) = np.array(pairs, dtype=float).T, len(pairs), prior
    design = np.vstack([np.column_stack([np.ones_like(x), x]), [[0.0, 1.0], [1.0, 0.0]]])
    target = np.r_[y, prior[0], 0.0]
    drift = np.arange(len(y))[::-1] * (SCALE_DRIFT * x) ** 2  # the factor's random walk: SCALE_DRIFT x a test
    for _ in range(2):  # x's error enters y's as F times it: weighed at the prior's f, then at the fitted F
        measured = sy**2 + (factor * sx) ** 2  # the tests' and the twin-scale wear's errors, the drift apart
        weights = np.r_[1.0 / np.maximum(measured + drift, 1e-6), 1 / prior_sd**2, 1 / sb**2]
        result = sm.WLS(target, design, weights=weights).fit(cov_type="fixed scale")
        factor, level = max(float(result.params[1]), SCALE_MIN), bounds.reference_level(result.params[0])
        target[n], prior_sd = prior[0] * level, prior[1] * level  # f's prior, on F = f (1 + b/100)
    residual = y - design[:n] @ result.params
    dof = n - float(np.sum(weights[:n, None] * (design[:n] @ np.asarray(result.cov_params())) * design[:n]))
    if (chi2 := float(np.sum(weights[:n] * residual**2) / dof) if dof >= 1 else 1.0) > 1.0:
        weights[:n], weights[-1] = weights[:n] / chi2, weights[-1] / chi2  # the tests', not f's prior...
        weights[n] = 1 / min(prior_sd**2 * chi2, max(prior_sd, SCALE_PRIOR * level) ** 2)  # ...a fleet's, 0.3
    elif (ratio := bounds.upper_ratio(residual, measured, dof)) < 1.0:  # they scatter less than stated
        weights = np.r_[1.0 / np.maximum(ratio * measured + drift, 1e-6), 1 / prior_sd**2, 1 / (ratio * sb**2)]
    if chi2 > 1.0 or ratio < 1.0:
        result = sm.WLS(target, design, weights=weights).fit(cov_type="fixed scale")
    return bounds.reference_factor(result.params, result.cov_params(), SCALE_MIN)


def tests_table(wears: dict[str, list[AxisWear]]) -> Table:
    """``OUT/tests.csv`` (:data:`COLUMNS`): per unit, test and axis read, in stamp order; empty cells
    where there is no number."""

    def cell(value) -> str:  # no number: empty, NaN included
        return cells.figure(None if isinstance(value, float) and not math.isfinite(value) else value)

    return Table("tests.csv", COLUMNS, [[unit, r.stamp, r.axis, *(cell(r.fit[c]) for c in FIT_COLUMNS), cell(r.wear),
                                         cell(r.lower), cell(r.upper), r.verdict, cell(100 * r.scatter)]
                                        for unit, rows in wears.items() for r in rows])


def on_tests_scale(rows: list, n_axes: int) -> tuple[list, dict[int, float] | None]:
    """``rows`` (a monitor's :class:`faultgen.monitor.record.LogRow`, in order) as
    :func:`remaining_life` fits them: each axis's own estimates (``wear.log``, ``wear.log_lower``,
    %) the twin-scale ones times the *last* row's factor, and each axis's scale uncertainty
    (relative: the last factor's standard error over it; an axis in the twin's scale
    :data:`faultgen.monitor.scoring.SCALE_UNCERTAINTY`). A prefix ``rows[:i]`` gives what the
    monitor said after its ``i``-th log. ``(rows, None)`` unchanged when the last row has no
    twin-scale values (no friction test)."""
    from faultgen.monitor import prognosis

    last = rows[-1].wear.tests if rows and rows[-1].wear is not None else None
    if last is None:
        return rows, None
    factor = last.factor
    rescaled = [dataclasses.replace(r, wear=r.wear.with_log(factor * r.wear.tests.twin_log,
                                                            factor * r.wear.tests.twin_log_lower))
                if r.wear is not None and r.wear.tests is not None else r for r in rows]
    uncertainty = {k + 1: float(last.factor_error[k] / factor[k]) if last.scale[k] == TESTS_SCALE
                   else prognosis.SCALE_UNCERTAINTY for k in range(n_axes)}
    return rescaled, uncertainty


def remaining_life(monitor, failure_wear: float) -> list:
    """:func:`faultgen.monitor.prognosis.of_monitor` of a monitor on its tests' scale
    (:func:`on_tests_scale`: each axis's own estimates rescaled by its latest factor, the factor's
    relative error as the scale's uncertainty; an axis in the twin's scale keeps the default)."""
    from faultgen.monitor import prognosis

    rows, uncertainty = on_tests_scale(monitor.rows, monitor.stages.n_axes)  # (rows, None): as they are
    return prognosis.of_monitor(monitor, failure_wear, rows=rows, scale_uncertainty=uncertainty)
