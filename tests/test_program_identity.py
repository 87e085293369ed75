"""A run's program is identified by what it is (its text's hash), not by the label it inherits:
an edited export gets its own label, a sweep refuses two programs under one label, and no
analysis pairs runs of different programs (issue 51, item 1)."""

import hashlib

import h5py
import numpy as np
import pytest
from typer.testing import CliRunner

from analysis import benchmark
from faultgen import plot as plotting
from faultgen.cli import app
from faultgen.data import dataset, reader
from faultgen.model import robots
from faultgen.operation import programs
from test_plot import _subset  # a valid dataset of some runs of another

runner = CliRunner()


def _irb():
    """The robot these programs run on (resolved once per process: robots.load caches it)."""
    return robots.load("irb6700")


@pytest.fixture(scope="module")
def sweep_file(shared_sweep):
    """Two tasks x (no wear, axis 2 worn by 20 %), 20 cycles of which 3 are recorded (as test_plot)."""
    return shared_sweep("s", robots=["irb6700"], tasks=["pick_place", "spot_weld"], axes=[0, 2], increases=[20.0],
                        cycles=20, record=[1, 10, 20])


def _edited(folder, name=None):
    """The spot weld exported and edited (slower, first pose moved), as ``folder/mine2.toml``."""
    text = programs.export(_irb(), "spot_weld")
    assert "velocity_scale = 1.0" in text and "pose = [1.55, -0.25, 0.8]" in text
    text = text.replace("velocity_scale = 1.0", "velocity_scale = 0.6", 1)
    text = text.replace("pose = [1.55, -0.25, 0.8]", "pose = [1.57, -0.25, 0.8]", 1)
    if name is not None:
        text = text.replace('name = "spot_weld"', f'name = "{name}"', 1)
    path = folder / "mine2.toml"
    path.write_text(text)
    return path


def test_an_edited_export_is_labelled_by_its_file_and_an_unedited_one_is_the_task(tmp_path):
    builtin = programs.identity(_irb(), "spot_weld")
    assert builtin == ("spot_weld", hashlib.sha256(programs.export(_irb(), "spot_weld").encode()).hexdigest())
    same = tmp_path / "mine.toml"
    same.write_text(programs.export(_irb(), "spot_weld"))
    assert programs.identity(_irb(), str(same)) == builtin  # the same program, bit for bit
    edited = _edited(tmp_path)
    label, digest = programs.identity(_irb(), str(edited))
    assert label == "mine2" and digest == hashlib.sha256(edited.read_bytes()).hexdigest() != builtin[1]
    renamed = _edited(tmp_path, name="slow_weld")  # a name of its own is kept
    assert programs.identity(_irb(), str(renamed))[0] == "slow_weld"


def test_a_sweep_refuses_two_programs_under_one_label_and_writes_nothing(tmp_path):
    a = _edited(tmp_path, name="myweld").rename(tmp_path / "a.toml")
    b = tmp_path / "b.toml"
    b.write_text(programs.export(_irb(), "spot_weld").replace('name = "spot_weld"', 'name = "myweld"'))
    out = tmp_path / "bad.h5"
    result = runner.invoke(app, ["sweep", "--task", str(a), "--task", str(b), "--axis", "0", "--cycles", "2",
                                 "-o", str(out), "--no-progress"])
    assert result.exit_code == 2, result.output
    assert "different programs" in result.output and "'myweld'" in result.output
    assert list(tmp_path.glob("bad*")) == []


def test_every_run_records_its_programs_hash_and_the_validator_checks_it(sweep_file, tmp_path):
    with reader.open(sweep_file) as data:
        for run in data.runs:
            assert run.program_sha256 == programs.identity(_irb(), run.task)[1]
            assert run.program == run.program_sha256
        assert data.unhashed == ""
    bad = tmp_path / "bad.h5"
    bad.write_bytes(sweep_file.read_bytes())
    with h5py.File(bad, "a") as f:
        f["runs"][next(iter(f["runs"]))].attrs[dataset.PROGRAM_ATTRIBUTE] = "not-a-hash"
    assert any("program_sha256" in p and "64 hex digits" in p for p in dataset.validate(bad))


def _mixed(source, path, *, drop_hash=False):
    """The spot weld's worn run beside the pick and place's unworn run relabelled ``spot_weld``: two
    programs under one label, as an older faultgen wrote them for an edited export."""
    _subset(source, path, {"irb6700-spot_weld-axis2-exp420-seed0": "irb6700-spot_weld-axis2-exp420-seed0",
                           "irb6700-spot_weld-nowear-seed0": "irb6700-pick_place-nowear-seed0"})
    with h5py.File(path, "a") as f:
        for group in f["runs"].values():
            group.attrs["task"] = "spot_weld"
            if drop_hash:
                del group.attrs[dataset.PROGRAM_ATTRIBUTE]
    assert dataset.validate(path) == []
    return path


def test_detect_never_pairs_runs_of_different_programs(sweep_file, tmp_path):
    mixed = _mixed(sweep_file, tmp_path / "mixed.h5")
    with pytest.raises(ValueError, match=r"same-run needs the run without wear .* not comparable with it: "
                                         r"irb6700-spot_weld-nowear-seed0 differs in program spot_weld"):
        benchmark.detection_table(mixed, progress=False, protocol="same-run")
    result = runner.invoke(app, ["detect", str(mixed), "--protocol", "same-run", "--no-progress",
                                 "-o", str(tmp_path / "det")])
    assert result.exit_code == 2 and "differs in program" in result.output, result.output


def test_plot_never_draws_a_worn_run_against_another_programs_unworn_run(sweep_file, tmp_path, monkeypatch):
    mixed = _mixed(sweep_file, tmp_path / "mixed.h5")
    references = []
    change = plotting._change

    def spy(run, reference, j):
        references.append(reference)
        return change(run, reference, j)

    monkeypatch.setattr(plotting, "_change", spy)
    plotting.plot(mixed, tmp_path / "mixed.png")
    assert references == [None]  # against its own first cycle, not the pick and place's run
    with reader.open(sweep_file) as data:  # the right pairing still pairs
        worn = data["irb6700-spot_weld-axis2-exp420-seed0"]
        unworn = [r for r in data.healthy if plotting._reference_key(r) == plotting._reference_key(worn)]
        assert [r.id for r in unworn] == ["irb6700-spot_weld-nowear-seed0"]


def test_a_file_without_hashes_is_paired_by_label_and_says_so(sweep_file, tmp_path):
    old = _mixed(sweep_file, tmp_path / "old.h5", drop_hash=True)
    with reader.open(old) as data:
        assert all(r.program_sha256 is None and r.program == "task:spot_weld" for r in data.runs)
        assert "paired by their task label alone" in data.unhashed
    result = runner.invoke(app, ["plot", str(old), "-o", str(tmp_path / "old.png")])
    assert result.exit_code == 0, result.output
    assert "paired by their task label alone" in " ".join(result.output.split())


def test_isolation_shows_healthy_runs_only_the_cycles_of_their_own_programs_worn_runs(sweep_file, tmp_path):
    mixed = _mixed(sweep_file, tmp_path / "mixed.h5")
    table = benchmark.isolation_table(mixed, levels=[5.0], progress=False)
    assert (table["worn_axis"] != 0).all()  # the relabelled unworn run is of another program: not a case
    table = benchmark.isolation_table(sweep_file, levels=[5.0], progress=False)
    healthy = table[table["worn_axis"] == 0]
    assert set(healthy["run"]) == {"irb6700-pick_place-nowear-seed0", "irb6700-spot_weld-nowear-seed0"}
    assert np.all(healthy.groupby("run").size() == len(set(table["isolator"])))


def test_the_issues_sweep_written_the_old_way_is_still_paired_by_program(tmp_path):
    """The issue's workflow: the spot weld and its edited export, which an older faultgen labelled
    both `spot_weld` and wrote without program_sha256. The edited program's runs still carry their
    file's hash (attribute `program`), so detect pairs each worn run with its own program's run."""
    from faultgen.runs import sweep

    edited = _edited(tmp_path)
    path = tmp_path / "mixed.h5"
    sweep.run(sweep.Grid(robots=["irb6700"], tasks=["spot_weld", str(edited)], axes=[0, 2], cycles=4, signals=False),
              path, progress=False)
    with h5py.File(path, "a") as f:  # as written before the hash: one label, no program_sha256
        for group in f["runs"].values():
            group.attrs["task"] = "spot_weld"
            del group.attrs[dataset.PROGRAM_ATTRIBUTE]
    with reader.open(path) as data:
        by_id = {r.id: r for r in data.runs}
        assert by_id["irb6700-mine2-nowear-seed0"].program == hashlib.sha256(edited.read_bytes()).hexdigest()
        assert by_id["irb6700-spot_weld-nowear-seed0"].program == "task:spot_weld"
        assert "2 of 4 runs" in data.unhashed
    table = benchmark.detection_table(path, progress=False, protocol="same-run")
    assert dict(zip(table["run"], table["trained_on"], strict=True)) == {
        "irb6700-mine2-axis2-exp420-seed0": "irb6700-mine2-nowear-seed0",
        "irb6700-spot_weld-axis2-exp420-seed0": "irb6700-spot_weld-nowear-seed0"}


def test_runs_of_another_robot_friction_or_conditions_are_not_comparable_and_the_reason_is_named():
    def run(**changes):
        base = dict(id="r", robot="irb6700", task="spot_weld", friction_model="lugre", seed=0, cycles=10,
                    worn_axes=(), wear_schedule={}, fault=None, conditions=None, noise={}, sample="cycle",
                    has_signals=True, provenance={"model_sha256": "m"}, program_sha256="a" * 64)
        return reader.Run(**{**base, **changes})

    a = run()
    assert reader.difference(a, run(seed=1)) == "" and a.setup == run(seed=1).setup
    assert reader.difference(a, run(robot="puma560")) == "robot irb6700 vs puma560"
    assert reader.difference(a, run(provenance={"model_sha256": "other"})) == "robot model of irb6700"
    assert reader.difference(a, run(program_sha256="b" * 64)).startswith("program spot_weld (aaaaaaaa) vs")
    assert reader.difference(a, run(friction_model="stribeck")) == "friction model lugre vs stribeck"
    hot = run(conditions={"thermal": {"ambient": 35.0}, "payloads": None})
    assert reader.difference(a, hot) == "operating conditions" and a.setup != hot.setup
    assert hot.setup != run(conditions={"thermal": {"ambient": 20.0}, "payloads": None}).setup
    # a fleet's robots each draw their own climate: compared when the same conditions are on
    day = {"sample": "day"}
    assert run(conditions={"thermal": {"ambient": 35.0}}, **day).setup == \
        run(conditions={"thermal": {"ambient": 20.0}}, **day).setup
    assert run(conditions={"thermal": {"ambient": 35.0}}, **day).setup != run(conditions=None, **day).setup
