"""Faults other than friction wear: an effect's parameter growing over the cycles. The growing
fault at a cycle must be the physics of the model compiled with the effect at that value (the
effect's own MJCF form), and the labels must say its value per cycle."""

import json

import numpy as np
import pytest

from faultgen.data import dataset
from faultgen.operation.faults import parse_fault
from faultgen.runs import sweep
from faultgen.simulation import sensors
from faultgen.simulation import stepping as sim
from resolved_runs import run_config

QUIET = sensors.NoiseConfig(0.0, 0.0)


def test_fault_values_at_known_cycles():
    linear = parse_fault("backlash:2:width:0.01", last_cycle=10)
    assert linear.values(np.array([0, 5, 10])) == pytest.approx([0.0, 0.005, 0.01])
    grown = parse_fault("torque_offset:1:offset:-20:kind=exp4,start=5", last_cycle=100)
    # the growth follows the schedule's rise at +100 %: exp4 at half the cycles, 2 ** (1 / 16) - 1
    assert grown.values(np.array([0, 50, 100])) == pytest.approx([5.0, 5.0 - 25 * (2 ** (1 / 16) - 1), -20.0], rel=1e-9)
    cogging = parse_fault("cogging:3:amplitude:0.05:poles=8,phase=1", last_cycle=10)
    assert cogging.at(0.02, 6).values(2) == pytest.approx({"amplitude": 0.02, "poles": 8, "phase": 1.0})
    assert cogging.at(0.02, 6).values(0)["amplitude"] == 0.0
    # with an onset: the start value up to it, then exp4's rise over the cycles after it
    late = parse_fault("cogging:3:amplitude:0.05:kind=exp4,onset=60", last_cycle=100)
    assert late.values(np.array([0, 60, 80, 100])) == pytest.approx([0.0, 0.0, 0.05 * (2 ** (1 / 16) - 1), 0.05],
                                                                   rel=1e-9)
    assert late.to_dict()["onset"] == 60 and "onset" not in grown.to_dict()  # labels without one unchanged


@pytest.mark.parametrize(("spec", "message"), [
    ("payload:1:mass:2", r"'payload' is robot-wide"),
    ("temperature:2:amplitude:0.3", r"per-step friction update"),
    ("backlash:8:width:0.01", r"fault axis 8: expected 1..7"),
    ("backlash:2:gap:0.01", r"backlash has no parameter 'gap'; it has: width"),
    ("backlash:2:width:-0.01", r"backlash takes values >= 0"),
    ("backlash:2:width:0", r"a fault must change its parameter"),
    ("backlash:2:width", r"expected 4 or 5"),
    ("cogging:2:amplitude:0.1:kind=exp5", r"unknown wear schedule 'exp5'"),
    ("cogging:2:amplitude:0.1:kind=exp4,onset=10", r"exp4 onset 10 is invalid; expected an int in 0..9"),
    ("cogging:2:amplitude:0.1:onset=3", r"linear schedule has no parameter 'onset'"),
    ("cogging:2:amplitude:0.1:kind=exp4,onset=2.5", r"option onset=2.5 is not a whole cycle"),
    # an absolute fault on the motor friction or one of its parts: their fault is wear (--wear)
    ("coulomb:2:coulomb_pos:0.5", r"part of the motor friction.*--wear AXIS:KIND:PERCENT"),
    ("viscous:2:viscous:0.01", r"part of the motor friction"),
    ("stribeck:2:static:0.1", r"part of the motor friction"),
    ("motor_friction:2:static:0.1", r"part of the motor friction"),
])
def test_bad_fault_specs_are_refused_with_the_value_named(spec, message):
    with pytest.raises(ValueError, match=message):
        parse_fault(spec, last_cycle=10)


@pytest.mark.parametrize(("robot_name", "spec", "cycle"), [
    ("irb6700", "backlash:2:width:0.012", 2),
    ("puma560", "cogging:3:amplitude:0.04:poles=8,phase=0.5", 2),
])
def test_a_growing_fault_at_a_cycle_is_the_model_compiled_at_its_value(robot_name, spec, cycle):
    """Cycle ``cycle`` of a run whose fault grows to FINAL over 5 cycles (its value set per
    simulation from the fields of models compiled at two other values) has the torques of a run
    whose model is compiled at exactly that cycle's value (a fault that ends there), within 1e-9 of
    the largest torque; and the fault is seen: the worn axis's torque differs from the nominal run."""
    fault = parse_fault(spec, last_cycle=5)
    value = float(fault.values(np.array([cycle]))[0])
    effect, axis, parameter = spec.split(":")[:3]
    rest = spec.split(":", 4)[4:] or [""]
    exact = parse_fault(f"{effect}:{axis}:{parameter}:{value!r}" + (f":{rest[0]}" if rest[0] else ""), last_cycle=cycle)
    common = {"task": "spot_weld", "record": (cycle,), "nthread": 1, "noise": QUIET}
    run = sim.simulate(run_config(robot_name, cycles=5, fault=fault, **common), progress=False)
    compiled = sim.simulate(run_config(robot_name, cycles=cycle, fault=exact, **common), progress=False)
    nominal = sim.simulate(run_config(robot_name, cycles=5, **common), progress=False)
    scale = np.max(np.abs(compiled.tau_m))
    assert np.max(np.abs(run.tau_m - compiled.tau_m)) < 1e-9 * scale
    worn = fault.axis - 1
    assert np.max(np.abs(run.tau_m - nominal.tau_m)[..., worn]) > 1e-3 * np.max(np.abs(nominal.tau_m[..., worn]))
    assert run.fault_value.tolist() == [pytest.approx(value)]


def test_a_growing_load_dependent_friction_at_a_cycle_is_a_unit_gear_loss_of_that_value(monkeypatch):
    """Load-dependent friction grows as a fault through the plant, its coefficient per simulation
    beside the unit's gear loss: cycle 4 of a run growing it to 0.06 on axis 2 over 5 cycles has the
    friction and motor torques of a run without the fault whose unit gear loss (the same physics,
    the effect's transmitted-load form, unknown to the controller as a fault is) is that cycle's
    value on axis 2, to 1e-9; the nominal run differs on axis 2 by over 2 % of the largest torque, its mean friction by 20 %. Not independent: both
    are faultgen's gear-loss physics (tests of the effect itself: test_calibrate_effects)."""
    from faultgen.simulation.batch import Plant

    fault = parse_fault("load_dependent_friction:2:coefficient:0.06", last_cycle=5)
    value = float(fault.values(np.array([4]))[0])
    assert value == pytest.approx(0.048)
    common = {"task": "pick_place", "friction": "stribeck", "record": (4,), "nthread": 1, "noise": QUIET}
    run = sim.simulate(run_config("irb6700", cycles=5, fault=fault, **common), progress=False)
    nominal = sim.simulate(run_config("irb6700", cycles=5, **common), progress=False)
    plain = Plant.of

    def with_gear_loss(*args, **kwargs):
        plant = plain(*args, **kwargs)
        return Plant(plant.dry, plant.viscous, plant.link_mass, plant.fault, np.array([0, value, 0, 0, 0, 0]))

    monkeypatch.setattr(sim.Plant, "of", staticmethod(with_gear_loss))
    unit = sim.simulate(run_config("irb6700", cycles=5, **common), progress=False)
    for name in ("tau_f", "tau_m"):
        a, b, c = (getattr(r, name)[..., 1] for r in (run, unit, nominal))
        assert np.max(np.abs(a - b)) < 1e-9 * np.max(np.abs(b))
        assert np.max(np.abs(a - c)) > 0.02 * np.max(np.abs(c))
    assert np.abs(run.tau_f[..., 1]).mean() > 1.2 * np.abs(nominal.tau_f[..., 1]).mean()
    assert run.fault_value.tolist() == [pytest.approx(value)]


def test_a_growing_load_dependent_friction_needs_the_static_model_and_its_transmitted_form():
    fault = parse_fault("load_dependent_friction:2:coefficient:0.06", last_cycle=5)
    assert fault.in_plant and not parse_fault("backlash:2:width:0.01", last_cycle=5).in_plant
    with pytest.raises(ValueError, match=r"growing load_dependent_friction fault needs the static friction model "
                                         r"\(friction='stribeck', --friction stribeck\)"):
        run_config("irb6700", "pick_place", cycles=5, fault=fault)
    with pytest.raises(ValueError, match=r"transmitted-load form .*gravity_load = 0"):
        parse_fault("load_dependent_friction:2:coefficient:0.06:gravity_load=1", last_cycle=5)
    with pytest.raises(ValueError, match=r"transmitted-load form .*got parameter 'gravity_load'"):
        parse_fault("load_dependent_friction:2:gravity_load:1", last_cycle=5)


def test_a_fault_sweep_labels_every_cycle_and_isolates(tmp_path):
    from analysis import benchmark

    grid = sweep.Grid(robots=["puma560"], tasks=["pick_place"], axes=[0, 3], cycles=8, record=[2, 4, 6, 8],
                      fault="cogging:each:amplitude:0.05:poles=8")
    out = sweep.run(grid, tmp_path / "faults.h5", progress=False)
    assert dataset.validate(out) == []
    rows = {row["run"]: row for row in dataset.labels(out)}
    worn = rows["puma560-pick_place-axis3-cogging0.05-seed0"]
    assert worn["worn_axes"].tolist() == [3] and json.loads(worn["fault"])["parameter"] == "amplitude"
    arrays, _ = dataset.read_run(out, worn["run"], names=("fault_value", "friction_multiplier"))
    assert arrays["fault_value"] == pytest.approx([0.0125, 0.025, 0.0375, 0.05])
    assert np.all(arrays["friction_multiplier"] == 1.0)  # no friction wear in a cogging fault
    table = benchmark.isolation_table(out, levels=(50, 100), progress=False)
    assert set(table["wear_pct"]) == {0.0, 50.0, 100.0}
    assert set(table.loc[table["worn_axis"] == 3, "cycles"]) == {2, 4}  # 50 % at cycle 4, the 2nd record


def test_the_fault_text_is_parsed_once_into_what_grids_and_fleets_hold():
    """One text for every command, read into a FaultSpec at the boundary: a sweep's grid and a
    fleet hold that object (a text given to them is read once), build each run's Fault from it, and
    store the text again; the text keeps every digit of its numbers."""
    from faultgen.operation.faults import FaultSpec
    from faultgen.operation.wear import Schedule, WearPlan
    from faultgen.runs.fleet import Fleet

    spec = FaultSpec.parse("backlash:each:width:0.01:kind=exp4")
    assert spec == FaultSpec("backlash", None, "width", 0.01, "exp4") and str(spec) == "backlash:each:width:0.01:kind=exp4"
    exact = FaultSpec.parse("cogging:3:amplitude:0.0123456789:poles=8")
    assert FaultSpec.parse(str(exact)) == exact and str(exact) == "cogging:3:amplitude:0.0123456789:poles=8"
    for bad, message in [("gearbox:2:width:0.01", r"unknown effect 'gearbox'; known effects: motor_friction"), ("backlash:9:width:0.01", r"fault axis 9: expected 1..7"),
                         ("backlash:2:width:inf", r"FINAL = inf: expected a finite number"),
                         ("backlash:width:0.01", r"write 'each' for the worn axis: 'backlash:each:width:0.01'")]:
        with pytest.raises(ValueError, match=message):
            FaultSpec.parse(bad)
    grid = sweep.Grid(robots=["puma560"], tasks=["pick_place"], axes=[0, 2, 3], cycles=4, record=[4],
                      fault="backlash:each:width:0.01:kind=exp4")
    assert grid.fault == spec and sweep.Grid(**{**json.loads(grid.to_json())}) == grid
    assert json.loads(grid.to_json())["fault"] == str(spec)
    assert [config.fault for _, config in grid.runs()] == [None, spec.fault(4, axis=2), spec.fault(4, axis=3)]
    worn = sweep.Grid(robots=["puma560"], tasks=["pick_place"], axes=[2], cycles=4, record=[4], increases=[12.5])
    assert worn.wear_schedules == (Schedule("exp4", 0.125, 4),)
    assert worn.runs()[0][1].wear == WearPlan.from_specs(["2:exp4:12.5"], last_cycle=4)
    fleet = Fleet(size=2, failing=1, days=6, cycles_per_day=1, models=("puma560",), fault="backlash:each:width:0.01")
    assert fleet.fault == FaultSpec("backlash", None, "width", 0.01)
    assert json.loads(fleet.to_json())["fleet"]["fault"] == "backlash:each:width:0.01"
