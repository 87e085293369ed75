"""faultgen.plot: PNGs of mean absolute motor torque against true wear, for a run and for a sweep."""

import subprocess
import sys

import h5py
import matplotlib.image
import numpy as np
import pytest

from faultgen.data import dataset
from faultgen.plot import plot
from test_sweep import GRID
from resolved_runs import run_config


@pytest.fixture(scope="module")
def sweep_file(shared_sweep):
    """Two tasks x (no wear, axis 2 worn by 20 %), 20 cycles of which 3 are recorded: 4 runs
    (tests/test_sweep.py's :data:`GRID`: test_sweep.py and test_cluster.py read the same shared sweep,
    which is built from whichever file asks first)."""
    return shared_sweep("s", **GRID)


def _subset(source, path, runs: dict):
    """A valid dataset at ``path`` holding some runs of ``source`` ({new id: run id})."""
    with h5py.File(source, "r") as src, h5py.File(path, "w") as dst:
        for key, value in src.attrs.items():
            dst.attrs[key] = value
        dst.attrs["n_runs"] = len(runs)
        for name, run_id in runs.items():
            src.copy(src[f"runs/{run_id}"], dst.require_group("runs"), name=name)
    assert dataset.validate(path) == []
    return path


def assert_png(path):
    image = matplotlib.image.imread(path)
    assert image.ndim == 3 and image.shape[1] > 300 and image.shape[0] > 200, image.shape
    assert image[..., :3].std() > 0, "blank image"


def test_sweep_plot_shows_the_change_against_the_same_tasks_unworn_run(sweep_file, tmp_path, figures):
    out = plot(sweep_file, tmp_path / "sweep.png")
    assert out == tmp_path / "sweep.png"
    assert_png(out)
    (fig,) = figures
    assert len(fig.axes) == 6
    assert "s.h5" in fig.get_suptitle() and "4 runs" in fig.get_suptitle()
    assert "against the unworn run of the same program, conditions and seed" in fig.get_suptitle()
    axis2 = fig.axes[1]
    assert axis2.get_xlabel() == "true wear [%] of axis 2"
    assert axis2.get_ylabel() == "change of mean |motor torque| [%]"
    worn = [line for line in axis2.get_lines() if len(line.get_xdata()) == 3]
    assert len(worn) == 2  # one per task
    for line, task in zip(worn, ["pick_place", "spot_weld"], strict=True):  # drawn in the file's run order
        unworn, _ = dataset.read_run(sweep_file, f"irb6700-{task}-nowear-seed0")
        arrays, _ = dataset.read_run(sweep_file, f"irb6700-{task}-axis2-exp420-seed0")
        np.testing.assert_allclose(line.get_xdata(), (arrays["friction_multiplier"][:, 1] - 1) * 100)
        expected = (arrays["mean_abs_torque"][:, 1] / unworn["mean_abs_torque"][:, 1] - 1) * 100
        np.testing.assert_allclose(line.get_ydata(), expected)
        assert line.get_ydata()[0] == pytest.approx(0.0, abs=0.05)  # cycle 1: hardly any wear yet
    assert max(line.get_xdata().max() for line in worn) == pytest.approx(20.0)
    assert [list(line.get_ydata()) for line in fig.axes[0].get_lines()] == [[0.0, 0.0]]  # axis 1: the unworn level
    labels = [t.get_text() for t in fig.legends[0].get_texts()]
    assert labels == ["pick_place", "spot_weld"]


def test_a_worn_run_without_an_unworn_one_is_drawn_against_its_first_cycle(sweep_file, tmp_path, figures):
    worn = ["irb6700-pick_place-axis2-exp420-seed0", "irb6700-spot_weld-axis2-exp420-seed0"]
    worn_only = _subset(sweep_file, tmp_path / "worn.h5", {run_id: run_id for run_id in worn})
    plot(worn_only, tmp_path / "worn.png")
    (fig,) = figures
    assert "runs without one: their own first recorded cycle" in fig.get_suptitle()
    lines = fig.axes[1].get_lines()[1:]  # after the dashed line at 0
    assert len(lines) == 2 and all(line.get_ydata()[0] == 0.0 for line in lines)


def test_single_run_plot_shows_torque_per_cycle_and_the_wear_of_the_worn_axis(sweep_file, tmp_path, figures):
    run_id = "irb6700-spot_weld-axis2-exp420-seed0"
    out = plot(sweep_file, tmp_path / "run.png", run=run_id)
    assert_png(out)
    (fig,) = figures
    assert len(fig.axes) == 7  # six panels and the wear axis of axis 2
    title = fig.get_suptitle()
    assert run_id in title and "irb6700" in title and "spot_weld" in title and "lugre" in title
    arrays, _ = dataset.read_run(sweep_file, run_id)
    torque = fig.axes[1].get_lines()[0]
    np.testing.assert_array_equal(torque.get_xdata(), arrays["cycles"])
    np.testing.assert_allclose(torque.get_ydata(), arrays["mean_abs_torque"][:, 1])
    wear = fig.axes[6].get_lines()[0]
    np.testing.assert_allclose(wear.get_ydata(), (arrays["friction_multiplier"][:, 1] - 1) * 100)
    assert fig.axes[6].get_ylabel() == "true wear [%]"


def test_a_file_with_one_run_is_drawn_as_that_run(sweep_file, tmp_path, figures):
    one = _subset(sweep_file, tmp_path / "one.h5", {"only": "irb6700-pick_place-nowear-seed0"})
    assert_png(plot(one, tmp_path / "one.png"))
    (fig,) = figures
    assert len(fig.axes) == 6  # no wear: no wear axes
    assert fig.get_suptitle().startswith("only: irb6700, pick_place, no wear, seed 0, lugre friction\n")


def test_a_simulated_run_is_titled_by_what_it_is(tmp_path, figures):
    from faultgen.operation.wear import WearPlan
    from faultgen.simulation import stepping as sim

    config = run_config(robot="puma560", task="spot_weld", wear=WearPlan.from_specs(["3:linear:10"], 4),
                           cycles=4, record=(1, 4), seed=7)
    out = tmp_path / "one.h5"
    dataset.write_run(out, sim.simulate(config, progress=False))  # stored as the file's default run id
    plot(out, tmp_path / "one.png")
    (fig,) = figures
    assert fig.get_suptitle().startswith(
        "puma560, spot_weld, axis 3 worn (linear, +10 % by cycle 4), seed 7, lugre friction\n")


def test_unknown_run_is_refused_naming_it_and_listing_runs(sweep_file, tmp_path):
    with pytest.raises(ValueError, match="no run 'irb6700-nope'.*irb6700-pick_place-nowear-seed0"):
        plot(sweep_file, tmp_path / "x.png", run="irb6700-nope")
    assert not (tmp_path / "x.png").exists()


@pytest.mark.parametrize("name", ["plot.pdf", "plot", "plot.PNG.txt"])
def test_output_that_is_not_png_is_refused(sweep_file, tmp_path, name):
    with pytest.raises(ValueError, match=r"\.png"):
        plot(sweep_file, tmp_path / name)
    assert not (tmp_path / name).exists()


def test_invalid_files_raise_dataset_error(tmp_path):
    incomplete = tmp_path / "incomplete.h5"
    with h5py.File(incomplete, "w") as f:
        f.attrs["format"] = dataset.FORMAT
        f.attrs["complete"] = False
        f.create_group("runs")
    foreign = tmp_path / "foreign.h5"
    with h5py.File(foreign, "w") as f:
        f["x"] = np.zeros(3)
    text = tmp_path / "text.h5"
    text.write_text("not hdf5")
    for path, message in [(incomplete, "incomplete"), (foreign, "not a faultgen file"), (text, "cannot be opened"),
                          (tmp_path / "missing.h5", "no such file")]:
        with pytest.raises(dataset.DatasetError, match=message):
            plot(path, tmp_path / "x.png")


def test_importing_the_module_does_not_import_matplotlib():
    code = "import sys, faultgen.plot; assert 'matplotlib' not in sys.modules, 'matplotlib imported'"
    subprocess.run([sys.executable, "-c", code], check=True)


def test_a_fleet_is_drawn_per_robot_with_its_wear_against_the_day(shared_fleet, tmp_path, figures):
    """Issue 40: `faultgen plot fleet.h5` drew the sweep's wear-vs-change panels (zigzag lines
    between robots, an axis no robot wears left empty, the title cut). Now one panel per robot."""
    import faultgen

    # the small fleet tests/test_fleet.py and tests/test_cluster.py read (built once a session): one
    # failing robot and one healthy, a panel each (4 robots of 24 days cost 12 s of CPU for two more)
    fleet = shared_fleet("fleet-small", size=2, failing=1, days=6, cycles_per_day=1)
    out = plot(fleet, tmp_path / "fleet.png")
    assert_png(out)
    (fig,) = figures
    shown = [ax for ax in fig.axes if ax.get_visible() and ax.get_title()]
    with faultgen.open(fleet) as data:
        assert [ax.get_title().splitlines()[0] for ax in shown] == [run.id for run in data.runs]
        for ax, run in zip(shown, data.runs, strict=True):
            x = ax.lines[0].get_xdata()
            np.testing.assert_array_equal(x, run.recorded)  # against the day of the record
            if run.failing:  # the twin axis carries the true wear
                twin = [t for t in fig.axes if t is not ax and t.bbox.bounds == ax.bbox.bounds]
                np.testing.assert_allclose(twin[0].lines[0].get_ydata(), run.fault_level)
    assert fig.get_layout_engine() is not None  # constrained: the title is laid out, not cut
