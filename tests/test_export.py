"""faultgen.data.dataset.features and `faultgen export`: the tidy table equals the HDF5 arrays."""

import h5py
import numpy as np
import pandas as pd
import pytest
from typer.testing import CliRunner

from faultgen.cli import app
from faultgen.data import dataset

runner = CliRunner()


@pytest.fixture(scope="module")
def small(shared_sweep):
    """No wear and axis 3 worn, spot weld, 3 of 20 cycles recorded: 2 runs."""
    return shared_sweep("export-small", robots=["irb6700"], tasks=["spot_weld"], axes=[0, 3], cycles=20,
                        record=[1, 10, 20])


def test_features_hold_every_per_cycle_array_value_by_run_cycle_and_axis(small):
    table = dataset.features(small)
    assert len(table) == 2 * 3 * 6
    for run_id in dataset.list_runs(small):
        arrays, attrs = dataset.read_run(small, run_id)
        rows = table[table["run"] == run_id]
        assert (rows[["robot", "task", "friction_model"]].to_numpy() == [attrs["robot"], attrs["task"],
                                                                       attrs["friction_model"]]).all()
        assert (rows["seed"] == attrs["seed"]).all()
        for k, cycle in enumerate(arrays["cycles"]):
            for axis in range(1, 7):
                (row,) = rows[(rows["cycle"] == cycle) & (rows["axis"] == axis)].itertuples(index=False)
                row = row._asdict()
                assert row["worn"] == (axis in attrs["worn_axes"])
                assert row["wear_pct"] == (arrays["friction_multiplier"][k, axis - 1] - 1) * 100
                for name in ("mean_abs_torque", "rms_torque", "mean_friction_torque", "tracking_error",
                             "friction_multiplier", "average_speed", "average_load_torque"):
                    assert row[name] == arrays[name][k, axis - 1], name
                for name in ("angle_hist", "speed_hist", "torque_hist"):
                    np.testing.assert_array_equal([row[f"{name}_{b}"] for b in range(1, 13)],
                                                  arrays[name][k, axis - 1])
    worn = table[table["run"].str.contains("axis3")]
    assert set(worn["worn_axes"]) == {"3"} and set(worn[worn["worn"]]["axis"]) == {3}
    assert worn[worn["axis"] == 3]["wear_pct"].max() == pytest.approx(20.0)
    assert table.attrs["units"]["mean_abs_torque"] == "N m" and table.attrs["units"]["wear_pct"] == "%"
    assert table.attrs["units"]["average_speed"] == "rad/s"


def test_duty_arrays_are_checked_and_files_written_before_them_stay_valid(small, tmp_path):
    copy = tmp_path / "copy.h5"
    copy.write_bytes(small.read_bytes())
    run = dataset.list_runs(copy)[0]
    with h5py.File(copy, "r+") as f:
        f["runs"][run]["average_load_torque"][0, 2] = -1.0
    assert f"run {run}: average_load_torque: negative" in dataset.validate(copy)
    with h5py.File(copy, "r+") as f:
        del f["runs"][run]["average_load_torque"]
    assert dataset.validate(copy) == [(f"run {run}: has one of the duty arrays average_speed, average_load_torque "
                                       "but not the other")]
    with h5py.File(copy, "r+") as f:  # as a run simulated before the duty was recorded
        del f["runs"][run]["average_speed"]
    assert dataset.validate(copy) == []
    assert dataset.runs_with(copy, dataset.DUTY_ARRAYS) == dataset.list_runs(copy)[1:]
    table = dataset.features(copy)
    assert table[table["run"] == run]["average_speed"].isna().all()
    assert table[table["run"] != run]["average_speed"].notna().all()


@pytest.mark.parametrize("name", ["features.parquet", "features.csv", "features.csv.gz"])
def test_export_round_trip(small, tmp_path, name):
    out = tmp_path / name
    result = runner.invoke(app, ["export", str(small), "-o", str(out)])
    assert result.exit_code == 0, result.output
    back = pd.read_parquet(out) if name.endswith(".parquet") else pd.read_csv(out, keep_default_na=False)
    expected = dataset.features(small)
    assert list(back.columns) == list(expected.columns)
    back["worn_axes"] = back["worn_axes"].astype(str)
    pd.testing.assert_frame_equal(back, expected, check_dtype=False, check_exact=name.endswith(".parquet"),
                                  rtol=1e-15)
    assert not list(tmp_path.glob(".*.part"))


def test_export_refuses_unknown_formats_and_existing_outputs(small, tmp_path):
    result = runner.invoke(app, ["export", str(small), "-o", str(tmp_path / "f.xlsx")])
    assert result.exit_code == 2 and "expected a name ending in .csv, .csv.gz, .parquet" in result.output
    (tmp_path / "f.csv").write_text("earlier")
    result = runner.invoke(app, ["export", str(small), "-o", str(tmp_path / "f.csv")])
    assert result.exit_code == 2 and "--overwrite" in result.output
    assert (tmp_path / "f.csv").read_text() == "earlier"
