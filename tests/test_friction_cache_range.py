"""A friction test's reading cached in ``OUT/.cache/friction-tests`` is range-checked when a run
continues, as a fresh reading is (issue 86, item 10): an Infinity planted there was taken ("+inf
%"), and extreme levels stopped the run with a bare "math domain error" naming no file."""

from __future__ import annotations

import hashlib
import json
import math
from types import SimpleNamespace

import pytest

from faultgen.logs import formats
from faultgen.model import robots
from faultgen.monitor import friction_tests
from faultgen.monitor import state as stored


def _fit(axis: int, coulomb: float, temperature: float = 20.0) -> dict:
    fit = dict.fromkeys(friction_tests.FIT_COLUMNS, math.nan)
    fit.update(axis=axis, coulomb_Nm=coulomb, coulomb_Nm_low=0.99 * coulomb, coulomb_Nm_high=1.01 * coulomb,
               temperature_degC=temperature)
    return fit


def _planted(tmp_path, fits_text: str):
    """A unit's one friction test and, in OUT's cache, a reading of it with ``fits_text`` (JSON)."""
    robot = robots.load("puma560")
    test = tmp_path / "LOGS" / "u1" / "friction-test" / "2026-03-02.csv"
    test.parent.mkdir(parents=True)
    test.write_text("t,q1\n0,0\n")
    out = tmp_path / "OUT"
    key = friction_tests._cache_key(stored.sha256_file(robot.path), hashlib.sha256(test.read_bytes()).hexdigest(),
                                    formats.MEASURED.key)
    path = out / ".cache" / friction_tests.CACHE / f"{stored.key_name(key)}.json"
    path.parent.mkdir(parents=True)
    path.write_text('{"format": "%s", "key": %s, "error": "", "fits": %s}'
                    % (friction_tests.CACHE_FORMAT, json.dumps(key), fits_text))
    log = SimpleNamespace(path=test, stamp="2026-03-02", key=2.0, name=test.name)
    return {"u1": [log]}, robot, out, path


@pytest.mark.parametrize("column, text, shown", [("coulomb_Nm", "Infinity", "inf"), ("coulomb_Nm", "-Infinity", "-inf"),
                                                 ("viscous_Nms_rad", "1e300", "1e+300"),
                                                 ("temperature_degC", "-300", "-300"),
                                                 ("coulomb_Nm_high", "1e400", "inf")])
def test_a_cached_reading_out_of_range_is_refused_naming_the_file_axis_and_column(tmp_path, column, text, shown):
    fit = json.dumps(_fit(1, 100.0)).replace("NaN", "null")
    fit = json.loads(fit)
    fit = {k: (math.nan if v is None else v) for k, v in fit.items()}
    body = json.dumps([{**fit, column: "@"}]).replace('"@"', text)
    found, robot, out, path = _planted(tmp_path, body)
    with pytest.raises(stored.StateError) as raised:
        friction_tests.read_tests(found, robot, out)
    message = str(raised.value)
    assert message.startswith(f"{path}: the cached reading of the friction test 2026-03-02.csv holds axis 1 "
                              f"{column} = {shown}, outside"), message
    assert "delete it" in message and "\n" not in message


def test_a_cached_reading_in_range_is_taken(tmp_path):
    found, robot, out, _ = _planted(tmp_path, json.dumps([_fit(1, 100.0)]))
    read = friction_tests.read_tests(found, robot, out)
    assert read["u1"][0].fits[0]["coulomb_Nm"] == 100.0 and read["u1"][0].error == ""


def test_extreme_levels_within_the_range_give_a_verdict_and_never_a_math_error():
    """A dry level of 5e-324 N m after one of 1e7 (a ratio below floating point: "math domain error"
    before), and a temperature law so steep that its correction leaves floating point ("math range error")."""
    tests = [friction_tests.FrictionTest("2026-01-01", 1.0, "a" * 64, (_fit(1, 1e7),)),
             friction_tests.FrictionTest("2026-01-02", 2.0, "b" * 64, (_fit(1, 5e-324),))]
    rows, _ = friction_tests.tests_wear(tests, 1)
    assert rows[1].verdict == "no positive dry level read: no wear" and math.isnan(rows[1].wear)
    steep = [friction_tests.FrictionTest(f"2026-01-0{i + 1}", i + 1.0, "c" * 64, tuple(_fit(k, c, t) for k in (1, 2, 3)))
             for i, (c, t) in enumerate(((1e-8, 20.0), (1.0, 21.0), (1e7, 22.0)))]  # ln c rising 17 per kelvin
    steep += [friction_tests.FrictionTest("2026-01-04", 4.0, "d" * 64, (_fit(4, 1.0, 1000.0),)),
              friction_tests.FrictionTest("2026-01-05", 5.0, "e" * 64, (_fit(4, 1.0, -273.0),))]
    rows, law = friction_tests.tests_wear(steep, 4)
    assert law.beta > 10
    last = rows[-1]
    assert last.axis == 4 and math.isnan(last.wear), last
    assert "against 2026-01-04's 1 N m, a factor of e^" in last.verdict and last.verdict.endswith("no wear"), last.verdict
    for r in rows:  # every number of tests.csv a finite number or none
        assert all(math.isnan(v) or math.isfinite(v) or v == math.inf for v in (r.wear, r.lower, r.upper))
        assert math.isnan(r.wear) or math.isfinite(r.wear)
