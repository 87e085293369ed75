"""faultgen.open: the typed reader agrees with the HDF5 contents (read with h5py directly), on a
sweep and on a fleet; and detect's honest outputs on a fleet (false alarms on its healthy robots,
no detection before the fault begins)."""

import json

import h5py
import numpy as np
import pytest

import faultgen
from analysis import benchmark
from faultgen.data import dataset


@pytest.fixture(scope="module")
def small(shared_sweep):
    return shared_sweep("analysis-small", robots=["irb6700"], tasks=["pick_place"], axes=[0, 1, 5], cycles=40)


@pytest.fixture(scope="module")
def fleet(shared_fleet_command):
    """Four robots, two failing from a drawn onset day, 12 daily records each (tests/test_new_user.py's
    small fleet: made once by the command for both)."""
    return shared_fleet_command("--robots", "4", "--days", "12", "--cycles-per-day", "1")[0]


@pytest.mark.parametrize("which", ["small", "fleet"])
def test_runs_labels_wear_and_arrays_agree_with_the_hdf5_file(which, request):
    path = request.getfixturevalue(which)
    with faultgen.open(path) as data, h5py.File(path, "r") as f:
        assert [run.id for run in data.runs] == list(f["runs"])
        assert data.kind == ("fleet" if which == "fleet" else "sweep")
        for run in data.runs:
            group = f["runs"][run.id]
            assert run.robot == group.attrs["robot"] and run.task == group.attrs["task"]
            assert run.seed == int(group.attrs["seed"]) and run.cycles == int(group.attrs["cycles"])
            assert run.worn_axes == tuple(int(a) for a in group.attrs["worn_axes"])
            assert run.wear_schedule == json.loads(group.attrs["wear"])
            assert (run.conditions is not None) == ("conditions" in group.attrs)
            np.testing.assert_array_equal(run.wear, (group["friction_multiplier"][()] - 1.0) * 100.0)
            assert run.wear.shape == (len(group["cycles"]), 6)
            np.testing.assert_array_equal(run.recorded, group["cycles"][()])
            assert set(run.names) == set(group)
            if run.worn_axes:  # the fault begins at the first recorded cycle with wear
                worn = group["friction_multiplier"][()][:, run.worn_axes[0] - 1] > 1.0
                assert run.fault_begins == int(np.flatnonzero(worn)[0])
            else:
                assert run.fault_begins is None and not run.failing
        assert data[data.runs[0].id] is data.runs[0]
        with pytest.raises(KeyError, match="has no run 'nope'"):
            data["nope"]


def test_signals_load_lazily_and_a_features_only_file_says_why_it_lacks_them(small, fleet):
    with faultgen.open(small) as data:
        run = data.runs[1]
        assert "tau_m" not in run._cache
        tau = run.signal("tau_m")
        assert tau.shape[0] == len(run.recorded) and tau.shape[2] == 6 and "tau_m" in run._cache
        with pytest.raises(ValueError, match="not a 250 Hz signal"):
            run.signal("friction_multiplier")
    with pytest.raises(dataset.DatasetError, match="closed"):
        data.runs[0].array("mean_abs_torque")
    with faultgen.open(fleet) as data, pytest.raises(dataset.DatasetError, match="recorded without signals"):
        data.runs[0].signal("tau_m")


def test_a_run_names_its_stored_units_and_forgets_a_large_array_it_read(small):
    with faultgen.open(small) as data, h5py.File(small, "r") as f:
        run = data.runs[1]
        for name in ("tau_m", "friction_multiplier", "torque_hist", "t"):
            assert run.units(name) == f["runs"][run.id][name].attrs["units"] == dataset.ARRAYS[name][0]
        with pytest.raises(dataset.DatasetError, match="no array 'nothing'"):
            run.units("nothing")
        tau = run.signal("tau_m")
        run.forget("tau_m", "qd_m")  # qd_m never read: nothing to forget
        assert "tau_m" not in run._cache
        np.testing.assert_array_equal(run.signal("tau_m"), tau)  # read again on asking


def test_features_table_is_the_exported_table_and_carries_units(fleet):
    with faultgen.open(fleet) as data:
        table = data.features()
        n = sum(len(run.recorded) for run in data.runs) * 6
    assert len(table) == n and table.attrs["units"]["wear_pct"] == "%"
    assert table.attrs["units"]["mean_abs_torque"] == "N m" and table.attrs["units"]["joint_temperature"] == "degC"
    with h5py.File(fleet, "r") as f:  # one cell checked against the file by hand
        run_id = list(f["runs"])[2]
        expected = f["runs"][run_id]["average_load_torque"][4, 3]
    row = table[(table["run"] == run_id) & (table["cycle"] == 5) & (table["axis"] == 4)]
    assert row["average_load_torque"].item() == expected


def test_a_missing_or_unfinished_file_is_refused_naming_it(tmp_path, small):
    with pytest.raises(dataset.DatasetError, match="no such file"):
        faultgen.open(tmp_path / "none.h5")
    copy = tmp_path / "copy.h5"
    copy.write_bytes(small.read_bytes())
    with h5py.File(copy, "a") as f:
        f.attrs["complete"] = False
    with pytest.raises(dataset.DatasetError, match="incomplete"):
        faultgen.open(copy)


def test_the_public_api_is_named_in_the_package():
    assert faultgen.open is faultgen.data.reader.open
    from faultgen.model import robots
    from faultgen.simulation import stepping

    assert faultgen.load_robot is robots.load and faultgen.simulate is stepping.simulate
    assert {"open", "Dataset", "Run", "simulate", "load_robot", "Fleet", "Grid"} <= set(faultgen.__all__)


def test_detect_on_a_fleet_counts_false_alarms_on_its_healthy_robots_and_no_detection_before_the_fault(fleet):
    """Issue 40: on a fleet false_alarm_pct was NaN in every row and alarms before any wear counted
    as detections (median onset day 1 at 0 % wear)."""
    table = benchmark.detection_table(fleet, persistence=2, first=5, limit_folds=None, progress=False)
    assert len(table) == 2 and set(table["protocol"]) == {"first-cycles"}
    assert np.isfinite(table["false_alarm_pct"]).all() and (table["false_alarm_runs"] >= 1).all()
    detected = table[table["detected"]]
    assert (detected["onset_cycle"] >= detected["fault_begins_cycle"]).all()
    assert (detected["onset_wear_pct"] >= 0).all()
    with faultgen.open(fleet) as data:  # the fault's start is the first day with true wear
        begins = {run.id: int(run.recorded[run.fault_begins]) for run in data.failing}
    assert dict(zip(table["run"], table["fault_begins_cycle"], strict=True)) == begins
    assert benchmark.false_alarm_meaning(table["protocol"]).startswith("first-cycles: each healthy run")
    assert "sweep several seeds" not in benchmark.detection_advice(table)



def test_the_dataset_card_explains_wear_labels_units_and_bins(fleet):
    from typer.testing import CliRunner

    from faultgen.cli import app
    from faultgen.model import robots

    result = CliRunner().invoke(app, ["info", str(fleet), "--card"])
    assert result.exit_code == 0, result.output
    text = result.output
    import faultgen

    with faultgen.open(fleet) as data:  # the card explains the fleet's own largest wear (issue 51: 20 % at 50 %)
        largest = round(max(float(run.wear.max()) for run in data.runs), 1)
    assert largest == 50.0
    for heading in ("## What 50 % wear means", "## Labels", "## Arrays and units", "## Histogram bin edges",
                    "## Provenance and versions"):
        assert heading in text
    irb = robots.load("irb6700")
    coulomb = irb.friction.coulomb_pos[2]
    assert f"| irb6700 | 3 | {coulomb:.3g} | +{0.5 * coulomb:.3g} |" in text
    assert "| average_load_torque | N m | cycle, axis |" in text and "| joint_temperature | degC |" in text
    assert "| tau_m |" not in text  # a fleet stores no signals: the card lists what the file holds
    with h5py.File(fleet, "r") as f:  # a library-made fleet stores no command
        assert f"command: `{f.attrs['command'] or '(not stored)'}`" in text
