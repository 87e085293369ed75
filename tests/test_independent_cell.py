"""The independent fleet as a real cell (issue 90, item 7: :mod:`faultgen.bench.cell`): programs per
unit, logs cut at a random span and phase, a daily friction scatter set apart for the logs and the
tests, a deterministic temperature law of the dry friction, and linear, quadratic and exponential
wear; every fleet made before made again bit for bit."""

import csv
import dataclasses
import hashlib
import math
from pathlib import Path

import numpy as np
import pinocchio_log
import pytest

from faultgen.bench import cell, independent, plant
from faultgen.model import robots

#: sha256 of every file (relative path, then bytes, in sorted path order) of :data:`OLD` written by
#: the generator of main 1ab5ff8 (before the cell's options existed), on this project's numeric stack.
OLD_DIGEST = "39646353fbb05567aca9b66324d06185cd1b6855e987dec494834b0f7ba49abe"
OLD = independent.FleetSpec(units=2, worn=1, days=4, onset=(1, 2), rate=62.5, seed=3, friction_test_every=3)
#: A small cell with every new option on.
CELL = independent.FleetSpec(units=3, worn=3, days=4, onset=(1, 2), rate=62.5, seed=5, programs=3,
                             unit_programs=(1, 2, 3), span=(1.5, 3.0), wear_laws=cell.WEAR_LAWS,
                             log_jitter=0.015, test_jitter=0.01, dry_per_k=0.004, friction_test_every=3)


@pytest.fixture(scope="module")
def kr210(tmp_path_factory):
    return pinocchio_log.add_kr210(tmp_path_factory.mktemp("kr210") / "kr210")


def _digest(root: Path) -> str:
    h = hashlib.sha256()
    for path in sorted(Path(root).rglob("*")):
        if path.is_file():
            h.update(str(path.relative_to(root)).encode())
            h.update(path.read_bytes())
    return h.hexdigest()


def _rows(path: Path) -> list[dict]:
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def test_a_fleet_with_the_default_settings_is_the_one_made_before_the_cells_options_bit_for_bit(kr210, tmp_path):
    independent.write_fleet(tmp_path, OLD, kr210)
    assert not (tmp_path / "truth_programs.csv").exists()
    assert _digest(tmp_path) == OLD_DIGEST


@pytest.fixture(scope="module")
def written(kr210, tmp_path_factory):
    root = tmp_path_factory.mktemp("cell")
    independent.write_fleet(root, CELL, kr210)
    return root


def test_the_same_seed_gives_the_same_bytes_and_another_seed_other_logs(written, kr210, tmp_path):
    independent.write_fleet(tmp_path / "again", CELL, kr210)
    assert _digest(tmp_path / "again") == _digest(written)
    other = dataclasses.replace(CELL, seed=6, units=1, worn=1)
    independent.write_fleet(tmp_path / "other", other, kr210)
    first = sorted((tmp_path / "other" / "logs" / "unit01").glob("*.csv"))[0]
    assert first.read_bytes() != (written / "logs" / "unit01" / first.name).read_bytes()


def test_each_unit_runs_its_share_of_the_cells_programs_one_a_day(written):
    rows = _rows(written / "truth_programs.csv")
    assert [r["unit"] for r in rows] == [u for u in independent.unit_names(CELL) for _ in range(CELL.days)]
    for i, name in enumerate(independent.unit_names(CELL)):
        own = cell.unit_programs(CELL, i)
        assert len(own) == CELL.unit_programs[i] and set(own) <= {0, 1, 2}
        assert {int(r["program"]) for r in rows if r["unit"] == name} <= set(own)


def test_a_log_is_its_programs_motion_cut_at_its_span_and_phase(written, kr210):
    """Every log's angles are the day's program's cycle, repeated, from the phase's sample for the
    span's samples (within the angle noise), and its torque and time columns have that length."""
    model = robots.load(kr210)
    for row in _rows(written / "truth_programs.csv"):
        span, phase = float(row["span_cycles"]), float(row["phase"])
        assert 1.5 - 1e-4 <= span <= 3.0 + 1e-4 and 0.0 <= phase < 1.0
        _, q, _, _ = plant.motion(model, CELL.rate, False, cell.VARIANT_SHRINK[int(row["program"])])
        log = np.loadtxt(written / "logs" / row["unit"] / f"{row['stamp']}.csv", delimiter=",", skiprows=1)
        first = int(phase * len(q))
        assert abs(len(log) - span * len(q)) <= 1.0
        expected = np.tile(q, (4, 1))[first:first + len(log)]
        assert np.max(np.abs(log[:, 1:7] - expected)) < 1e-4
        assert np.allclose(np.diff(log[:, 0]), 1 / CELL.rate, atol=1e-4)


def test_the_worn_units_follow_the_laws_in_turn(written):
    truth = independent.read_truth(written / "truth.csv")
    units = independent._units(CELL, 6)
    for unit, law in zip(units, cell.WEAR_LAWS):
        assert unit["law"] == law
        x = np.clip((np.arange(1, CELL.days + 1) - unit["onset"]) / (CELL.days - unit["onset"]), 0.0, None)
        expected = {"linear": x, "quadratic": x**2, "exponential": np.expm1(4.0 * x) / math.expm1(4.0)}[law]
        assert np.allclose(truth[unit["unit"]]["wear"], CELL.final_wear * expected, atol=1e-4)
    assert truth[units[0]["unit"]]["wear"][-1] == pytest.approx(CELL.final_wear)


def test_the_first_worn_units_wear_at_their_rates_and_the_others_by_their_laws():
    spec = dataclasses.replace(CELL, days=30, wear_rates=(3.0, 0.3))
    units = [u for u in independent._units(spec, 6) if u["axis"]]
    truth = {}
    for unit, _, _, wear in independent.truth_rows(spec):
        truth.setdefault(unit, []).append(float(wear))
    for unit, rate in zip(units, (3.0, 0.3)):
        days = np.arange(1, 31)
        assert np.allclose(truth[unit["unit"]], rate * np.clip(days - unit["onset"], 0, None), atol=1e-4)
    assert truth[units[2]["unit"]][-1] == pytest.approx(spec.final_wear)  # the third by its law
    assert [u["rate"] for u in independent._units(CELL, 6)] == [None] * 3


def test_the_dry_friction_falls_with_temperature_by_its_law_and_the_viscous_as_before():
    unit = independent._units(CELL, 6)[0]
    nominal = (np.ones(6), np.full(6, 0.5), np.full(6, 0.01))
    jitter = np.ones((3, 6))
    temperature = np.linspace(10.0, 40.0, 6)
    plain = independent._levels(dataclasses.replace(CELL, dry_per_k=0.0), unit, 1, nominal, jitter, temperature)
    warm = independent._levels(CELL, unit, 1, nominal, jitter, temperature)
    fall = 1.0 - 0.004 * (temperature - 20.0)
    assert np.allclose(warm[0], plain[0] * fall) and np.allclose(warm[1], plain[1] * fall)
    assert np.array_equal(warm[2], plain[2])
    assert np.allclose(plain[2], 0.01 * unit["spread"][2] * np.exp(-0.02 * (temperature - 20.0)))


def test_the_logs_scatter_scales_the_same_draws_and_leaves_the_others_be(kr210):
    model = robots.load(kr210)
    unit = independent._units(CELL, 6)[0]
    days = {s: next(independent._days(dataclasses.replace(CELL, log_jitter=s), unit, model)) for s in (0.03, 0.015)}
    assert np.allclose(np.log(days[0.015].jitter), np.log(days[0.03].jitter) / 2, rtol=1e-12, atol=0)
    for key in ("temperature", "mass", "noise", "program", "phase", "span"):
        assert np.array_equal(getattr(days[0.015], key), getattr(days[0.03], key))


def test_the_tests_truth_carries_the_dry_laws_temperature(written, kr210):
    """truth_tests.csv's Coulomb level over the unit's own at 20 deg C (arm side) is the day's scatter
    times the dry law (1 - 0.004 (T - 20)): within the test's 1 % scatter (4 sigma)."""
    model = robots.load(kr210)
    own = independent.own_friction(CELL, model)
    worn = {u["unit"]: u["axis"] for u in independent._units(CELL, 6)}
    checked = 0
    for row in _rows(written / "truth_tests.csv"):
        axis = int(row["axis"])
        if worn[row["unit"]] == axis:
            continue  # the worn axis: its wear on top
        fall = 1.0 - 0.004 * (float(row["temperature_degC"]) - 20.0)
        coulomb = own[row["unit"]][0, axis - 1] * model.gear_ratio[axis - 1]
        assert abs(float(row["coulomb_Nm"]) / (coulomb * fall) - 1.0) < 0.04
        checked += fall != 1.0
    assert checked >= 20


@pytest.mark.parametrize("field, value, message", [
    ("programs", 4, r"^fleet programs = 4: expected the cell's programs, a whole number in 1\.\.3$"),
    ("unit_programs", (1, 3), r"^fleet unit_programs = \(1, 3\): expected the programs each unit runs"),
    ("span", (3.0, 1.5), r"^fleet span = \(3\.0, 1\.5\): expected \(\) or the cycles a log holds"),
    ("wear_laws", ("cubic",), r"^fleet wear_laws = \('cubic',\): expected laws among linear, quadratic, exponential$"),
    ("log_jitter", 0.6, r"^fleet log_jitter = 0\.6: expected a daily log's friction scatter"),
    ("dry_per_k", 0.1, r"^fleet dry_per_k = 0\.1: expected the dry friction's fall per kelvin in \[0, 0\.02\]$"),
    ("wear_rates", (3.0, 1.0, 1.0, 1.0), r"^fleet wear_rates = \(3\.0, 1\.0, 1\.0, 1\.0\): expected at most 3 \(the worn"),
    ("wear_rates", (0.0,), r"^fleet wear_rates = \(0\.0,\): expected at most"),
])
def test_a_bad_cell_setting_is_refused_by_name(field, value, message):
    settings = {"unit_programs": {"programs": 2}, "wear_rates": {"worn": 3}}.get(field, {})
    with pytest.raises(ValueError, match=message):
        independent.FleetSpec(**{**settings, field: value})


def test_a_span_and_whole_cycles_together_are_refused():
    with pytest.raises(ValueError, match=r"a log holds a span or whole cycles, not both"):
        independent.FleetSpec(span=(1.5, 3.0), cycles=(1, 2))
