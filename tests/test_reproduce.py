"""`faultgen reproduce`'s plumbing (issue 48, item 5): the runner's order, resumption and failures,
combining datasets of other seeds, a table built against the thesis's numbers, the summary, and
the command's refusals. The full run is measured by benchmarks/reproduce_time.py, not here."""

from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np
import pandas as pd
import pytest
from typer.testing import CliRunner

from faultgen.cli import app
from faultgen.data.dataset import combine
from faultgen.reproduce import plan, report, runner, tables, thesis
from faultgen.reproduce.runner import Step, StepFailed

cli = CliRunner()


def _writes(name: str, log: list[str]):
    def call(folder: Path) -> None:
        log.append(name)
        (folder / f"{name}.txt").write_text(name)
    return call


def test_steps_run_after_what_they_need_and_a_second_run_keeps_them(tmp_path):
    log: list[str] = []
    steps = [Step("a", outputs=("a.txt",), call=_writes("a", log), cost=1),
             Step("b", outputs=("b.txt",), needs=("a",), call=_writes("b", log), cost=5),
             Step("c", outputs=("c.txt",), call=_writes("c", log), cost=9)]
    outcomes = runner.execute(steps, tmp_path, jobs=2)
    assert log.index("a") < log.index("b") and sorted(log) == ["a", "b", "c"]
    assert {o.step.name: o.status for o in outcomes} == {"a": "ran", "b": "ran", "c": "ran"}
    seen = []
    again = runner.execute(steps, tmp_path, jobs=2, report=lambda o, done, total: seen.append((o.step.name, done, total)))
    assert {o.status for o in again} == {"kept"} and len(log) == 3  # nothing ran twice
    assert {s[0] for s in seen} == {"a", "b", "c"} and sorted(s[1:] for s in seen) == [(1, 3), (2, 3), (3, 3)]


def test_a_failed_step_is_named_with_its_log_and_what_needs_it_does_not_run(tmp_path):
    log: list[str] = []

    def broken(folder: Path) -> None:
        raise ValueError("no such preset 'x'")

    steps = [Step("make data", outputs=("d.txt",), call=broken),
             Step("analyse", outputs=("e.txt",), needs=("make data",), call=_writes("e", log)),
             Step("other", outputs=("o.txt",), call=_writes("o", log))]
    with pytest.raises(StepFailed, match=r"'make data' failed .*logs/make-data\.log.*resume"):
        runner.execute(steps, tmp_path, jobs=1)
    assert log == ["o"]
    assert "no such preset 'x'" in (tmp_path / "logs" / "make-data.log").read_text()


def test_a_plan_that_needs_a_later_step_is_refused():
    with pytest.raises(ValueError, match="'b' needs 'c'"):
        runner.check_plan([Step("b", needs=("c",)), Step("c")])


def test_a_command_step_runs_faultgen_in_the_folder(tmp_path):
    step = Step("tasks", ("tasks", "export", "irb6700", "pick_place", "-o", "pp.toml"), outputs=("pp.toml",))
    (outcome,) = runner.execute([step], tmp_path, jobs=1)
    assert outcome.status == "ran" and "pick_place" in (tmp_path / "pp.toml").read_text()
    assert (tmp_path / "logs" / "tasks.log").read_text().startswith("faultgen tasks export irb6700 pick_place")


def test_a_full_run_after_a_tiny_one_makes_each_step_again_at_its_scale(tmp_path):
    """A step's outputs are kept only when its record (DIR/.steps) says they were made with the same
    settings: a full run after an interrupted tiny one made the full tables on the tiny grids."""
    tiny, full = ([s for s in plan.steps(scale) if s.name == "c2 grid"] for scale in ("tiny", "full"))
    (outcome,) = runner.execute(tiny, tmp_path, jobs=1)
    assert outcome.status == "ran" and "cycles = 480" in (tmp_path / "c2.toml").read_text()
    (outcome,) = runner.execute(full, tmp_path, jobs=1)
    assert outcome.status == "ran" and (tmp_path / "c2.toml").read_text() == plan.C2_CONFIG
    (outcome,) = runner.execute(full, tmp_path, jobs=1)
    assert outcome.status == "kept"
    assert all(runner.records(plan.steps("tiny"))[s.name] != runner.records(plan.steps("full"))[s.name]
               for s in plan.steps("full"))


def test_a_step_whose_need_was_made_again_is_made_again(tmp_path):
    log: list[str] = []

    def steps(settings: str) -> list[Step]:
        return [Step("a", outputs=("a.txt",), call=_writes("a", log), settings=settings),
                Step("b", outputs=("b.txt",), needs=("a",), call=_writes("b", log))]

    runner.execute(steps("one"), tmp_path, jobs=1)
    outcomes = runner.execute(steps("two"), tmp_path, jobs=1)  # b's own settings are the same: its need's are not
    assert {o.step.name: o.status for o in outcomes} == {"a": "ran", "b": "ran"} and log == ["a", "b", "a", "b"]
    (tmp_path / ".steps" / "b.json").write_text((tmp_path / ".steps" / "b.json").read_text().replace('"done"', '"running"'))
    outcomes = runner.execute(steps("two"), tmp_path, jobs=1)  # killed after its record said it started: again
    assert {o.step.name: o.status for o in outcomes} == {"a": "kept", "b": "ran"}


def test_a_resumed_run_makes_the_steps_a_kept_step_made_ready(tmp_path):
    log: list[str] = []
    steps = [Step("a", outputs=("a.txt",), call=_writes("a", log)),
             Step("b", outputs=("b.txt",), needs=("a",), call=_writes("b", log))]
    runner.execute(steps, tmp_path, jobs=1)
    (tmp_path / "b.txt").unlink()  # killed before b wrote it
    outcomes = runner.execute(steps, tmp_path, jobs=1)
    assert {o.step.name: o.status for o in outcomes} == {"a": "kept", "b": "ran"} and (tmp_path / "b.txt").exists()


def test_an_output_no_run_made_is_refused_before_anything_runs(tmp_path):
    log: list[str] = []
    (tmp_path / "b.txt").write_text("the user's own\n")
    steps = [Step("a", outputs=("a.txt",), call=_writes("a", log)), Step("b", outputs=("b.txt",), call=_writes("b", log))]
    with pytest.raises(ValueError, match=r"b\.txt is there, and no record .* says a reproduction made it \(step 'b'"):
        runner.execute(steps, tmp_path, jobs=1)
    assert log == [] and (tmp_path / "b.txt").read_text() == "the user's own\n"


def test_a_command_step_made_again_replaces_its_output(tmp_path):
    old = Step("tasks", ("tasks", "export", "irb6700", "pick_place", "-o", "t.toml"), outputs=("t.toml",), settings="x")
    runner.execute([old], tmp_path, jobs=1)
    new = Step("tasks", ("tasks", "export", "irb6700", "spot_weld", "-o", "t.toml"), outputs=("t.toml",), settings="x")
    (outcome,) = runner.execute([new], tmp_path, jobs=1)
    assert outcome.status == "ran" and "spot_weld" in (tmp_path / "t.toml").read_text()
    assert "--overwrite" in (tmp_path / "logs" / "tasks.log").read_text()


def test_every_command_step_can_replace_its_outputs():
    import typer.main

    command = typer.main.get_command(app)
    for scale in plan.SCALES:
        for step in plan.steps(scale):
            if not step.args:
                continue
            sub = command.commands[step.args[0]]
            options = {o for p in sub.params for o in getattr(p, "opts", [])}
            assert "--overwrite" in options, step.name


def test_every_plan_is_valid_and_shares_its_datasets():
    for scale in plan.SCALES:
        steps = plan.steps(scale)
        runner.check_plan(steps)
        data = [s for s in steps if s.makes_data]
        outputs = [o for s in data for o in s.outputs]
        assert len(outputs) == len(set(outputs)) == 5  # each dataset made once
        assert any(s.name == "combine j2s3" for s in steps)
    with pytest.raises(ValueError, match="scale 'huge'"):
        plan.steps("huge")


def _tiny_sweep(folder: Path, seed: int) -> Path:
    out = folder / f"s{seed}.h5"
    result = cli.invoke(app, ["sweep", "--robot", "puma560", "--task", "pick_place", "--axis", "0", "--axis", "1",
                              "--cycles", "2", "--seed", str(seed), "--no-progress", "--jobs", "1", "-o", str(out)])
    assert result.exit_code == 0, result.output
    return out


def test_combined_seeds_hold_every_run_bit_for_bit(tmp_path):
    a, b = _tiny_sweep(tmp_path, 0), _tiny_sweep(tmp_path, 1)
    out = combine([a, b], tmp_path / "both.h5")
    result = cli.invoke(app, ["validate", str(out)])
    assert result.exit_code == 0, result.output
    with h5py.File(out) as f, h5py.File(a) as fa, h5py.File(b) as fb:
        assert f.attrs["n_runs"] == 4 and sorted(f["runs"]) == sorted([*fa["runs"], *fb["runs"]])
        for src in (fa, fb):
            for run_id in src["runs"]:
                for name, array in src["runs"][run_id].items():
                    if isinstance(array, h5py.Dataset):
                        assert np.array_equal(array[()], f["runs"][run_id][name][()], equal_nan=True), (run_id, name)
    with pytest.raises(ValueError, match="is in both"):
        combine([a, a], tmp_path / "twice.h5")


def _isolation_csv(folder: Path, te10_right: bool) -> None:
    rows = []
    for label, task in thesis.TASKS.items():
        for level in (1.0, 5.0, 10.0, 15.0):
            for axis in range(0, 7):
                for isolator in ("te5", "te10", "cross_correlation", "trend"):
                    right = axis > 0 and (isolator == "te10" and te10_right)
                    rows.append({"task": task, "worn_axis": axis, "wear_pct": level, "isolator": isolator,
                                 "predicted": axis if right else 0, "correct": right})
    pd.DataFrame(rows).to_csv(folder / "j2-isolation.csv", index=False)


@pytest.mark.parametrize(("te10_right", "word"), [(True, "agrees:"), (False, "differs:")])
def test_table_6_2_is_judged_against_the_thesis(tmp_path, te10_right, word):
    _isolation_csv(tmp_path, te10_right)
    part = tables.table_6_2(tmp_path)
    assert part.verdict.startswith(word)
    assert ("at 10 % wear 100.0 %" if te10_right else "at 10 % wear 0.0 %") in part.verdict
    ours = "✓✓✓✓✓✓" if te10_right else "××××××"
    assert f"| T1 pick_place | 1 | {ours} | ✓×✓××✓ |" in part.body


def test_the_summary_lists_every_table_with_its_verdict_and_what_is_left_out(tmp_path):
    _isolation_csv(tmp_path, True)
    part = tables.table_6_2(tmp_path)
    outcome = runner.Outcome(Step("isolation j2", ("bench-isolators", "j2.h5")), "ran", 12.0)
    path = report.write(tmp_path, [part], [outcome], "tiny", 60.0)
    text = path.read_text()
    assert part.verdict in text and "tables/table-6.2.md" in text and "Not regenerated" in text
    assert "`faultgen bench-isolators j2.h5`" in (tmp_path / "tables" / "table-6.2.md").read_text()
    assert pd.read_csv(tmp_path / "times.csv")["seconds"].tolist() == [12.0]


def test_the_command_refuses_a_file_or_a_missing_folder_in_one_line(tmp_path):
    (tmp_path / "f").write_text("")
    for out, message in ((tmp_path / "f", "is a file"), (tmp_path / "no" / "r", "does not exist")):
        result = cli.invoke(app, ["reproduce", "--tiny", "-o", str(out)])
        assert result.exit_code == 2 and result.output.startswith("error: ") and message in result.output
        assert len(result.output.strip().splitlines()) == 1


def test_the_plan_is_printed_without_running_anything(tmp_path):
    result = cli.invoke(app, ["reproduce", "--plan", "-o", str(tmp_path / "repro")])
    assert result.exit_code == 0, result.output
    assert "sweep j2: faultgen sweep --preset j2" in result.output and "c2:" in result.output
    assert "detect j2s3 other-seeds: faultgen detect j2s3.h5" in result.output and "[after: combine j2s3]" in result.output
    assert not (tmp_path / "repro").exists()
