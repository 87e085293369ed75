"""Issue 51, items 3 and 6: defaults that work on the data they are given, one fault text for
every command, and a distribution name a user can install."""

import re
import shutil
import tomllib
from pathlib import Path

import h5py
import pytest
from typer.main import get_command
from typer.testing import CliRunner

import faultgen
from faultgen.cli import app
from faultgen.operation import faults
from faultgen.runs import sweep
from faultgen.runs.fleet import Fleet

ROOT = Path(__file__).resolve().parents[1]
runner = CliRunner()


def invoke(*args: str):
    return runner.invoke(app, [*args, "--no-progress"] if args[0] in ("simulate", "sweep", "fleet", "detect")
                         else list(args))


# -- item 6: the distribution name ----------------------------------------------------------------


def test_the_distribution_is_not_named_like_the_unrelated_project_on_pypi():
    """``faultgen`` on PyPI is someone else's 0.1.0 (2026-01): the project installs as
    ``faultgen-robots``, its import name and command stay ``faultgen``, and the README's
    commands install from the clone."""
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    assert project["name"] == faultgen.DISTRIBUTION == "faultgen-robots"
    assert project["scripts"] == {"faultgen": "faultgen.cli:app"}
    readme = (ROOT / "README.md").read_text()
    assert "pip install faultgen-robots" in readme and "Do not `pip install faultgen`" in readme
    commands = re.findall(r"```bash\n(.*?)\n```", readme, re.S)
    installs = [re.search(r"pip install (.*?) &&", c).group(1) for c in commands if "pip install" in c]
    assert installs == [".", '-e ".[test]"']  # from the clone, whatever the index holds
    for text in [readme, *(p.read_text() for p in (ROOT / "docs").glob("*.md"))]:
        assert "pip install 'faultgen[" not in text and "pip install faultgen " not in text


# -- item 3: defaults that follow the data ------------------------------------------------------


def test_the_failing_robots_follow_the_fleet_size():
    assert Fleet(size=8, days=20).failing == 4
    assert Fleet(size=5, days=20).failing == 2
    assert Fleet().failing == 13  # the thesis's 13 of 26
    assert Fleet(size=8, failing=3, days=20).failing == 3


def test_a_small_fleet_and_the_detect_it_suggests_run_and_say_their_protocol(shared_fleet_command, tmp_path):
    """`faultgen fleet --robots N --days D` (on 41791db: --failing 13 refused any fleet under 14
    robots) and then the `faultgen detect` it suggests (on 41791db: "protocol same-run needs the
    run without wear" on a fleet of 20 days or fewer): auto picks first-cycles, fits --first to
    the fleet's days and says so."""
    made, printed = shared_fleet_command("--robots", "4", "--days", "12", "--cycles-per-day", "1")  # --jobs 1
    assert f"faultgen detect {made}" in printed
    out = tmp_path / "f.h5"  # detect writes beside the fleet: a copy
    shutil.copy(made, out)
    result = invoke("detect", str(out))
    assert result.exit_code == 0, result.output
    assert ("protocol auto -> first-cycles: a fleet: each robot is a unit of its own and learns its first 6 days"
            in result.output)
    table = (tmp_path / "f-detection.csv").read_text()
    assert "samples 1-6 of the run" in table


def test_a_first_cycles_limit_over_more_folds_than_samples_is_fitted_or_names_the_option():
    from analysis import benchmark

    assert benchmark.fitted_first(None, 40) == 20
    assert benchmark.fitted_first(None, 20) == 10
    assert benchmark.fitted_first(7, 20) == 7


# -- item 3: one fault text ---------------------------------------------------------------------


@pytest.mark.parametrize("text", ["backlash:2:width:0.01", "cogging:3:amplitude:0.05:poles=8",
                                  "torque_offset:1:offset:20:kind=exp4,onset=3", "backlash:each:width:0.01"])
def test_the_fault_text_is_parsed_once_and_written_back_the_same(text):
    spec = faults.FaultSpec.parse(text)
    assert str(spec) == text
    fault = spec.fault(10, axis=spec.axis or 2)
    assert fault.axis == (spec.axis or 2)
    if spec.axis is not None:
        assert fault == faults.parse_fault(text, 10)
        assert fault.text() == text


def test_the_fault_without_an_axis_is_refused_with_the_form_that_works():
    with pytest.raises(ValueError) as err:
        faults.FaultSpec.parse("backlash:width:0.01")
    assert "'backlash:each:width:0.01'" in str(err.value)
    grid = sweep.Grid(robots=["irb6700"], tasks=["pick_place"], axes=[0, 2, 3], cycles=2,
                      fault="backlash:each:width:0.01")  # the recommended form works
    assert [run_id for run_id, _ in grid.runs()] == [
        "irb6700-pick_place-nowear-seed0", "irb6700-pick_place-axis2-backlash0.01-seed0",
        "irb6700-pick_place-axis3-backlash0.01-seed0"]
    with pytest.raises(ValueError, match=r"is on axis 2 but the grid wears axes 2, 3: give --axis 0 --axis 2, or "
                                         r"write 'backlash:each:width:0.01'"):
        sweep.Grid(robots=["irb6700"], tasks=["pick_place"], axes=[0, 2, 3], cycles=2, fault="backlash:2:width:0.01")
    with pytest.raises(ValueError, match="AXIS 'each' stands for a sweep's or a fleet's worn axis"):
        faults.parse_fault("backlash:each:width:0.01", 10)
    with pytest.raises(ValueError, match="the fleet sets the kind"):
        Fleet(size=4, days=12, fault="backlash:2:width:0.01")


def test_the_readmes_fault_runs_in_a_sweep_and_shows_in_simulate_and_info(tmp_path):
    """The README's `--fault backlash:2:width:0.01`: refused by `sweep` on 41791db with an error
    recommending a form it also refused; now one text for simulate, sweep and fleet, printed by
    `simulate` and `faultgen info`."""
    out = tmp_path / "s.h5"
    result = invoke("sweep", "--fault", "backlash:2:width:0.01", "--cycles", "2", "--jobs", "1", "-o", str(out))
    assert result.exit_code == 0, result.output
    with h5py.File(out) as f:
        assert sorted(f["runs"]) == ["irb6700-pick_place-axis2-backlash0.01-seed0", "irb6700-pick_place-nowear-seed0"]
    result = invoke("info", str(out))
    assert result.exit_code == 0, result.output
    assert "faults:        backlash:2:width:0.01 (1 run)" in result.output
    one = tmp_path / "one.h5"
    result = invoke("simulate", "--fault", "cogging:3:amplitude:0.05:poles=8", "--temperature", "--cycles", "2",
                    "-o", str(one))
    assert result.exit_code == 0, result.output
    assert "fault cogging:3:amplitude:0.05:poles=8: cogging amplitude on axis 3 grows linear from 0 to 0.05" \
        in result.output
    result = invoke("info", str(one))
    assert "faults:        cogging:3:amplitude:0.05:poles=8 (1 run)" in result.output
    assert "CONDITION_ARRAYS" not in result.output and "operating conditions: thermal" in result.output


# -- item 5: the command list -------------------------------------------------------------------


def test_the_command_list_gives_each_command_its_whole_first_sentence():
    """`faultgen --help` cut every description with "..." (click's 45-character short help)."""
    group = get_command(app)
    listing = runner.invoke(app, ["--help"], terminal_width=80).output
    block = listing[listing.index("Commands:"):]
    for name in group.commands:
        # the command's lines: its name, then the wrapped rest of its summary
        match = re.search(rf"^  {re.escape(name)} +(.*?)(?=^  \S|\Z)", block, re.S | re.M)
        summary = " ".join(match.group(1).split())
        assert summary.endswith(".") and not summary.endswith("..."), summary


# -- item 5: the docs' snippets run and print what they say -------------------------------------


def test_the_dataset_docs_snippets_run_and_their_shapes_are_right(shared_sweep, tmp_path, monkeypatch):
    """docs/dataset.md's Python blocks on the quick preset's pick and place runs (without wear and
    axis 1): every line runs (a name used before it is defined fails), and each expression whose
    comment starts with a shape or a value gives it (on 41791db: run_id undefined, 1712 samples)."""
    import ast

    quick = shared_sweep("docs-quick", **{**sweep.PRESETS["quick"], "tasks": ["pick_place"], "axes": [0, 1]})
    shutil.copy(quick, tmp_path / "quick.h5")
    monkeypatch.chdir(tmp_path)
    text = (ROOT / "docs/dataset.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, re.S)
    assert len(blocks) >= 3
    checked = 0

    def run(statements, names, source):
        nonlocal checked
        for node in statements:
            comment = source[node.lineno - 1].partition("#")[2]
            shape = re.match(r"\s*(\([\d, ]+\))", comment)
            if isinstance(node, ast.Expr) and shape:
                assert eval(ast.unparse(node.value), names) == ast.literal_eval(shape.group(1)), \
                    source[node.lineno - 1]  # noqa: S307
                checked += 1
            elif isinstance(node, ast.With):  # the with-block's statements one by one, its file open
                with eval(ast.unparse(node.items[0].context_expr), names) as opened:  # noqa: S307
                    run(node.body, {**names, node.items[0].optional_vars.id: opened}, source)
            else:
                exec(compile(ast.Module([node], []), "dataset.md", "exec"), names)  # noqa: S102 - the docs' code

    for block in blocks:
        run(ast.parse(block).body, {}, block.splitlines())
    assert checked >= 3


def test_the_sysid_refit_prints_nothing_to_the_console(capfd):
    """`calibrate` passed mujoco.sysid's absl warnings and its optimiser's raw "iter:" lines to
    the user (41791db); the refit now runs quietly and its outcome is reported by the calibration."""
    import numpy as np
    from mujoco import sysid

    from faultgen.calibrate import refit

    def residual(x):
        return np.array([x[0] - 0.3, x[1] - 0.7, 0.1 * (x[0] + x[1] - 1.0)])

    start = np.array([0.0, 0.0])  # at the lower bound: sysid warns through absl
    x, half, _ = refit._optimize(sysid, residual, start, np.zeros(2), np.ones(2), 30)
    np.testing.assert_allclose(x, [0.3, 0.7], atol=1e-6)
    printed = capfd.readouterr()
    assert "iter:" not in printed.out and "box bound" not in printed.err and printed.out == ""


def test_the_detection_figure_shows_every_worn_run_below_its_title(tmp_path, figures):
    """j2's 18 worn runs: the PNG showed 12 (spot weld missing) and its title overlapped the first
    row (41791db)."""
    import numpy as np

    from analysis import benchmark

    n = 12
    charts = {f"irb6700-{task}-axis{axis}-exp420-seed0": {
        "sample": np.arange(n), "cycle": np.arange(1, n + 1), "wear_pct": np.linspace(0, 20, n),
        "alarm": np.arange(n) > 8, "q": np.linspace(1, 5, n), "t2": np.linspace(1, 3, n), "q_limit": 4.0,
        "t2_limit": 2.5, "trained": 0, "onset": 9, "begins": 1, "protocol": "same-run (in-sample)",
        "robot": "irb6700", "task": task, "worn_axis": axis}
        for task in ("pick_place", "spot_weld", "arc_weld") for axis in range(1, 7)}
    benchmark.detection_figure(charts, tmp_path / "d.png")
    (fig,) = figures
    titles = {ax.get_title() for ax in fig.axes}
    assert len(fig.axes) == 36 and all(any(run in t for t in titles) for run in charts)
    assert "all 18 worn runs" in fig._suptitle.get_text()
    fig.canvas.draw()
    title_bottom = fig._suptitle.get_window_extent().y0
    assert all(ax.get_tightbbox().y1 <= title_bottom + 1 for ax in fig.axes)


def test_the_fleet_plot_draws_no_trend_from_a_partial_week_and_marks_the_parts(tmp_path, monkeypatch):
    """A healthy robot read -33 % on the last day of a 20-day fleet: the running median at the
    record's end was the median of four days, most of them carrying the lighter part."""
    import numpy as np

    from faultgen import plot

    change = np.zeros((20, 2))
    change[-3:, 0] = -33.0  # the last days: the lighter part
    trend = plot.running_median(change)
    assert np.all(np.isnan(trend[:3])) and np.all(np.isnan(trend[-3:]))
    np.testing.assert_array_equal(trend[3:-3], 0.0)
    assert plot.TREND_DAYS == 7


def test_a_sweep_in_the_background_terminated_with_its_group_says_how_to_resume(tmp_path):
    """`timeout`, a process manager or a closed terminal sends SIGTERM to the whole process group,
    and a sweep started in the background has SIGINT ignored: on 41791db it died on the SIGTERM
    without a word while loky's resource tracker reported leaked semaphores. Now it stops its
    workers and says what is kept and how to resume, and nothing else."""
    import os
    import signal
    import subprocess

    from test_reliability import CLI, GRID_ARGS, marked, wait_for, workers

    out = tmp_path / "killed.h5"
    parts = sweep.parts_folder(out)
    mark = str(tmp_path)
    proc = subprocess.Popen([*CLI, "sweep", *GRID_ARGS, "--jobs", "2", "-o", str(out)], cwd=tmp_path,
                            env={**os.environ, "FAULTGEN_TEST_MARK": mark}, start_new_session=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_IGN),  # a background job
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        wait_for(lambda: (parts / "sweep.json").exists() and len(workers(mark)) >= 2, "two workers")
        os.killpg(proc.pid, signal.SIGTERM)  # the sweep, its workers and loky's resource tracker
        stdout, stderr = proc.communicate(timeout=120)
        wait_for(lambda: not marked(mark), "every process of the sweep to end")  # a deadline, not a delay
    finally:
        for p in marked(mark):
            p.kill()
    # counted once nothing of the sweep runs: equal to the message's count, counted after it stopped its
    # workers, only if no worker went on to finish a run (no fixed wait for them)
    kept = len(list(parts.glob("*.h5")))
    assert proc.returncode == 143, stdout + stderr
    assert stderr.strip() == (f"terminated (SIGTERM): {kept} of 4 runs kept in {parts}; run the same command to "
                              "resume" if kept else "terminated (SIGTERM): none of the 4 runs had finished; run the "
                              "same command to start again")


def test_the_quick_sweeps_time_is_given_in_one_place():
    """It was given four ways (13 s, 23 s, 24 s, "under a minute"): now only docs/performance.md
    gives it, and the README, the dataset docs and `sweep --help` point there."""
    duration = re.compile(r"\b\d+(\.\d+)? ?s\b|minute")
    texts = {p.name: p.read_text() for p in [ROOT / "README.md", *(ROOT / "docs").glob("*.md")]}
    texts["sweep --help"] = runner.invoke(app, ["sweep", "--help"], terminal_width=1000).output
    places = [name for name, text in texts.items() for line in text.splitlines()
              if re.search(r"(--preset quick|quick \(a first look|`quick` wear sweep)", line)
              and duration.search(line) and "classify" not in line]
    assert set(places) == {"performance.md"}, places  # its table, and the baseline of its ratio tables


def test_the_calibration_example_writes_only_into_its_out_folder(tmp_path, monkeypatch, capfd):
    """`benchmarks/calibration_example.py --out DIR` overwrote the tracked
    docs/images/calibration_example.png (41791db); with a one-cycle log it runs and leaves the
    checkout as it was. The script runs in this process, as `python SCRIPT` runs it (its own
    `faultgen calibrate` child is a process of its own, as before)."""
    import os
    import runpy
    import subprocess
    import sys

    def status():
        return subprocess.run(["git", "-C", str(ROOT), "status", "--porcelain", "--untracked-files=all"],
                              capture_output=True, text=True, check=True).stdout

    image = ROOT / "docs/images/calibration_example.png"
    before, stamp = status(), image.stat().st_mtime_ns
    script = ROOT / "benchmarks/calibration_example.py"
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(sys, "argv", [str(script), "--out", "ex", "--cycles", "1"])
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]))
    capfd.readouterr()
    runpy.run_path(str(script), run_name="__main__")  # raises if the script or its calibrate fails
    assert "figure: ex/calibration/calibration.png" in capfd.readouterr().out
    assert (tmp_path / "ex/calibration/report.json").is_file()
    assert image.stat().st_mtime_ns == stamp and status() == before
