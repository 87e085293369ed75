"""The `faultgen` command, through its installed entry point and through typer's runner."""

import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from faultgen.cli import app
from faultgen.data import dataset
from faultgen.model import robots
from faultgen.operation.wear import WearPlan
from faultgen.simulation import stepping as sim
from resolved_runs import run_config

runner = CliRunner()


def test_robots_lists_every_robot_with_a_description():
    result = runner.invoke(app, ["robots"])
    assert result.exit_code == 0, result.output
    lines = result.output.strip().splitlines()
    assert [line.split()[0] for line in lines] == list(robots.available())
    for line in lines:
        assert len(line.split(maxsplit=1)[1]) > 20


def test_robots_name_shows_the_parameters_per_axis():
    result = runner.invoke(app, ["robots", "puma560"])
    assert result.exit_code == 0, result.output
    assert "axis 6" in result.output
    assert "gear ratio G [1]" in result.output
    assert "62.611" in result.output  # G1 of the PUMA 560
    assert "friction coulomb_neg [N m]" in result.output


def test_unknown_robot_is_an_error_listing_the_known_ones():
    result = runner.invoke(app, ["robots", "puma"])
    assert result.exit_code == 2
    assert "unknown robot 'puma'" in result.output
    assert "puma560" in result.output and "irb6700" in result.output


def test_help_teaches_the_first_steps():
    result = runner.invoke(app, ["--help"])
    assert result.exit_code == 0
    assert "faultgen robots" in result.output and "faultgen sweep --preset quick" in result.output


def test_console_script_is_installed():
    script = Path(sys.executable).parent / "faultgen"  # installed beside the interpreter
    assert script.is_file(), f"no console script at {script}: install the project with pip"
    out = subprocess.run([str(script), "robots"], capture_output=True, text=True, check=True).stdout
    assert "puma560" in out and "irb6700" in out


def test_simulate_writes_a_file_that_reads_back(tmp_path):
    out = tmp_path / "run.h5"
    result = runner.invoke(app, ["simulate", "--task", "spot_weld", "--wear", "2:exp4:20", "--cycles", "100",
                                 "--record", "1,100", "--seed", "3", "--no-progress", "-o", str(out)])
    assert result.exit_code == 0, result.output
    assert f"wrote {out}" in result.output
    assert "1.2000" in result.output  # axis 2's wear multiplier in the last cycle
    arrays, labels = dataset.read_run(out)
    assert labels["robot"] == "irb6700" and labels["task"] == "spot_weld" and labels["seed"] == 3
    assert list(labels["worn_axes"]) == [2]
    np.testing.assert_array_equal(arrays["cycles"], [1, 100])
    np.testing.assert_allclose(arrays["friction_multiplier"][:, 1], [np.exp(np.log(1.2) / 1e8), 1.2])
    # the file holds exactly what the library returns for the same configuration
    config = run_config(robot="irb6700", task="spot_weld", wear=WearPlan.from_specs(["2:exp4:20"], 100),
                           record=(1, 100), seed=3)
    direct = sim.simulate(config, progress=False)
    for name, (_, axes, _) in dataset.ARRAYS.items():
        expected = direct.features[name] if name in direct.features else getattr(direct, name)
        if axes == dataset.SIGNAL_AXES:  # stored as float32
            expected = expected.astype(np.float32)
        np.testing.assert_array_equal(arrays[name], expected, err_msg=name)
    assert not list(tmp_path.glob("*.part"))


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--task", "welding"], "unknown task 'welding'"),
        (["--wear", "7:exp4:20"], "axis 7 is out of range 1..6"),
        (["--wear", "2:exp4:-10"], "2:exp4:-10"),
        (["--cycles", "0"], "--cycles '0': expected 1..1000000"),  # typer's range, as one line
        (["--friction", "coulomb"], "unknown friction model 'coulomb'"),
        (["--record", "1,x"], "--record part 'x'"),
    ],
)
def test_simulate_refuses_bad_input_before_simulating(tmp_path, args, message):
    out = tmp_path / "run.h5"
    result = runner.invoke(app, ["simulate", *args, "--no-progress", "-o", str(out)])
    assert result.exit_code == 2, result.output
    assert message in result.output
    assert not out.exists() and not list(tmp_path.iterdir())


def test_simulate_refuses_a_robot_file_with_negative_friction(tmp_path):
    source = robots.available()["irb6700"]
    model = tmp_path / "worn_robot.xml"
    model.write_text(source.read_text().replace('<numeric name="friction5" data="0.5 ', '<numeric name="friction5" data="-0.5 '))
    result = runner.invoke(app, ["simulate", "--robot", str(model), "--no-progress", "-o", str(tmp_path / "r.h5")])
    assert result.exit_code == 2
    assert "axis 5: friction coulomb_pos = -0.5" in result.output
    assert not (tmp_path / "r.h5").exists()


def test_simulate_does_not_overwrite_without_asking(tmp_path):
    out = tmp_path / "run.h5"
    out.write_text("precious")
    result = runner.invoke(app, ["simulate", "--no-progress", "-o", str(out)])
    assert result.exit_code == 2 and "--overwrite" in result.output
    assert out.read_text() == "precious"


def test_written_file_has_normal_permissions(tmp_path):
    import os

    out = tmp_path / "run.h5"
    result = runner.invoke(app, ["simulate", "--record", "1", "--cycles", "2", "--no-progress", "-o", str(out)])
    assert result.exit_code == 0, result.output
    mask = os.umask(0)
    os.umask(mask)
    assert out.stat().st_mode & 0o777 == 0o666 & ~mask


def _toolbox_free_log(tmp_path, seconds=6.0, nan_row=None, degrees=False, drop=None):
    """A short measured log along our PUMA path (nominal torque), optionally broken."""
    from faultgen.calibrate import synth
    from faultgen.data import logfiles

    robot = robots.load("puma560")
    motion, tau = synth.nominal_motion(robot, "pick_place", 1)
    n = int(seconds / 0.004)
    t, q, tau = motion.t[:n], motion.q[:n].copy(), tau[:n].copy()
    if nan_row is not None:
        tau[nan_row, 1] = np.nan
    if degrees:
        q = np.degrees(q)
    path = logfiles.write_csv(tmp_path / "log.csv", t, q, tau)
    if drop:
        import pandas as pd

        pd.read_csv(path).drop(columns=[drop]).to_csv(path, index=False)
    return path


def test_calibrate_prints_the_summary_and_writes_outputs(tmp_path):
    log = _toolbox_free_log(tmp_path)
    result = runner.invoke(app, ["calibrate", "--robot", "puma560", "--measured", str(log), "--out",
                                 str(tmp_path / "cal")])
    assert result.exit_code == 0, result.output
    assert "no significant missing effect found" in result.output
    assert "gap" in result.output and "report.json" in result.output
    for name in ("report.json", "calibration.png", "model/puma560_calibrated.xml", "model/tasks.toml"):
        assert (tmp_path / "cal" / name).is_file(), name


@pytest.mark.parametrize("broken, match", [
    ({"drop": "tau3"}, "tau3"),
    ({"nan_row": 7}, "row 8"),
    ({"degrees": True}, "degrees"),
    ({"seconds": 1.0}, "2 s"),
])
def test_calibrate_refuses_bad_measured_data(tmp_path, broken, match):
    log = _toolbox_free_log(tmp_path, **broken)
    result = runner.invoke(app, ["calibrate", "--robot", "puma560", "--measured", str(log), "--out",
                                 str(tmp_path / "cal")])
    assert result.exit_code == 2
    assert "error:" in result.output and match in result.output, result.output
    assert not (tmp_path / "cal" / "report.json").exists()


def test_calibrate_refuses_an_unknown_robot(tmp_path):
    log = _toolbox_free_log(tmp_path)
    result = runner.invoke(app, ["calibrate", "--robot", "kuka", "--measured", str(log), "--out", str(tmp_path / "c")])
    assert result.exit_code == 2
    assert "unknown robot 'kuka'" in result.output and "puma560" in result.output


def test_simulate_accepts_a_model_file(tmp_path):
    spec_path = robots.load("puma560").path
    result = runner.invoke(app, ["simulate", "--model", str(spec_path), "--cycles", "1", "--no-progress",
                                 "--out", str(tmp_path / "r.h5")])
    assert result.exit_code == 0, result.output


# --------------------------------------------------------------------------------------------
# Every option honoured or refused, one --overwrite behaviour, plain help (issue 20 items 1, 4, 5, 8)

ONE_RUN = ["--robot", "irb6700", "--task", "pick_place", "--axis", "0", "--no-progress"]


@pytest.mark.parametrize(("args", "message"), [
    (["--cycles", "0", "--record", "1"], "--cycles '0': expected 1..1000000"),
    (["--cycles", "2", "--record", ""], "--record part ''"),
    (["--cycles", "2", "--record", "1", "--friction", ""], "unknown friction model ''"),
])
def test_sweep_refuses_a_falsy_option_instead_of_dropping_it(tmp_path, args, message):
    out = tmp_path / "x.h5"
    result = runner.invoke(app, ["sweep", *ONE_RUN, *args, "-o", str(out)])
    assert result.exit_code == 2, result.output
    assert "error:" in result.output and message in result.output
    assert sorted(p.name for p in tmp_path.iterdir()) == []  # nothing simulated, nothing written


def test_simulate_refuses_an_empty_record_instead_of_recording_all(tmp_path):
    result = runner.invoke(app, ["simulate", "--record", "", "--cycles", "2", "--no-progress",
                                 "-o", str(tmp_path / "r.h5")])
    assert result.exit_code == 2 and "--record part ''" in result.output


def test_output_that_is_a_folder_or_a_file_of_the_wrong_kind_is_an_error_line(tmp_path):
    (tmp_path / "folder.h5").mkdir()
    result = runner.invoke(app, ["simulate", "--overwrite", "--cycles", "1", "--no-progress",
                                 "-o", str(tmp_path / "folder.h5")])
    assert result.exit_code == 2, result.output
    assert "error:" in result.output and "folder.h5 is a folder" in result.output
    assert result.exception is None or isinstance(result.exception, SystemExit)

    (tmp_path / "results").write_text("not a folder")
    log = _toolbox_free_log(tmp_path)
    result = runner.invoke(app, ["calibrate", "--robot", "puma560", "--measured", str(log),
                                 "--out", str(tmp_path / "results")])
    assert result.exit_code == 2, result.output
    assert "error:" in result.output and "results is a file" in result.output
    assert (tmp_path / "results").read_text() == "not a folder"


def test_sweep_refuses_an_existing_output_unless_overwrite(tmp_path):
    out = tmp_path / "s.h5"
    out.write_text("precious")
    args = ["sweep", *ONE_RUN, "--cycles", "2", "--record", "1", "-o", str(out)]
    result = runner.invoke(app, args)
    assert result.exit_code == 2 and "--overwrite" in result.output
    assert out.read_text() == "precious"
    result = runner.invoke(app, [*args, "--overwrite"])
    assert result.exit_code == 0, result.output
    assert dataset.validate(out) == []


def test_calibrate_and_plot_refuse_to_replace_earlier_results_unless_overwrite(tmp_path):
    log = _toolbox_free_log(tmp_path)
    results = tmp_path / "cal"
    results.mkdir()
    (results / "report.json").write_text("earlier")
    args = ["calibrate", "--robot", "puma560", "--measured", str(log), "--out", str(results)]
    result = runner.invoke(app, args)
    assert result.exit_code == 2 and "--overwrite" in result.output
    assert (results / "report.json").read_text() == "earlier"
    result = runner.invoke(app, [*args, "--overwrite"])
    assert result.exit_code == 0, result.output
    assert (results / "report.json").read_text() != "earlier"

    data = tmp_path / "r.h5"
    assert runner.invoke(app, ["simulate", "--cycles", "2", "--no-progress", "-o", str(data)]).exit_code == 0
    png = tmp_path / "r.png"
    png.write_text("earlier")
    result = runner.invoke(app, ["plot", str(data)])
    assert result.exit_code == 2 and "--overwrite" in result.output and png.read_text() == "earlier"
    assert runner.invoke(app, ["plot", str(data), "--overwrite"]).exit_code == 0
    assert png.read_bytes().startswith(b"\x89PNG")


@pytest.mark.parametrize("command", ["bench-isolators", "detect", "classify"])
def test_analysis_commands_refuse_existing_outputs_before_computing(tmp_path, command):
    data = tmp_path / "r.h5"
    assert runner.invoke(app, ["simulate", "--cycles", "2", "--no-progress", "-o", str(data)]).exit_code == 0
    stem = tmp_path / "table"
    stem.with_suffix(".md").write_text("earlier")
    result = runner.invoke(app, [command, str(data), "-o", str(stem)])
    assert result.exit_code == 2, result.output
    assert "table.md exists; pass --overwrite" in result.output
    assert stem.with_suffix(".md").read_text() == "earlier" and not stem.with_suffix(".csv").exists()


@pytest.mark.parametrize("command", [[], ["robots"], ["simulate"], ["calibrate"], ["sweep"], ["info"], ["validate"], ["export"],
                                     ["plot"], ["bench-isolators"], ["detect"], ["classify"]])
def test_help_has_no_type_tags(command):
    result = runner.invoke(app, [*command, "--help"], terminal_width=100)
    assert result.exit_code == 0, result.output
    tags = re.findall(r"<(?:bool|int|float|str|path|list\[[a-z]+\])>", result.output)
    assert tags == [], tags
    assert "--help" in result.output


@pytest.mark.parametrize("width", [60, 80, 100])
def test_help_reflows_to_any_width_and_keeps_every_example_on_one_line(width):
    """Every command's help fits the terminal: paragraphs reflow to its width, nothing is cut
    with an ellipsis, and each example (a line of the docstring's \\b block) is printed whole
    on one line, so it can be pasted."""
    import typer.main

    group = typer.main.get_command(app)
    for name, command in group.commands.items():
        result = runner.invoke(app, [name, "--help"], terminal_width=width)
        assert result.exit_code == 0, result.output
        assert "\u2026" not in result.output, name
        examples = [line.strip() for line in (command.callback.__doc__ or "").splitlines()
                    if line.strip().startswith("faultgen ")]
        assert examples, f"{name} --help shows no example"
        printed = [line.strip() for line in result.output.splitlines()]
        for example in examples:
            assert example in printed, f"{name}: example not on one line at width {width}: {example}"
        too_long = [line for line in result.output.splitlines()
                    if len(line) > width and line.strip() not in examples]
        assert too_long == [], (name, too_long)
