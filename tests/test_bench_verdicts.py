"""Issue 59, part 5: every `faultgen bench score` figure with its verdict against chance, a warning
when a track is too short for a method, and OUT.md a valid Markdown table."""

from __future__ import annotations

import dataclasses
import itertools
import json
import re

import numpy as np
import pytest
from markdown_it import MarkdownIt
from typer.testing import CliRunner

from analysis.isolation import TransferEntropyIsolator
from analysis.monitoring import detect_onset
from faultgen.bench import baselines, files, score, verdicts
from faultgen.cli import app

runner = CliRunner()


@pytest.fixture(scope="module")
def thesis_small(shared_bench):
    """The thesis track's latest version at its test size (12 records a unit; 6 failing, 3 healthy
    test units), made by the command once a session (conftest.py)."""
    return shared_bench("thesis")


def _cells(line: str) -> list[str]:
    """The cells of a Markdown table line (split at pipes that are not escaped)."""
    return [c.strip() for c in re.split(r"(?<!\\)\|", line.strip())[1:-1]]


def _table(text: str) -> list[list[str]]:
    """OUT.md's table as CommonMark with GFM tables parses it: the header's and each row's cells."""
    tokens = MarkdownIt("commonmark").enable("table").parse(text)
    rows, row = [], None
    for token in tokens:
        if token.type == "tr_open":
            row = []
        elif token.type in ("th_open", "td_open"):
            row.append("")
        elif token.type == "inline" and row is not None:
            row[-1] = token.content
        elif token.type == "tr_close":
            rows.append(row)
            row = None
    return rows


def test_the_chance_of_an_onset_is_the_share_of_alarm_sequences_that_hold_one():
    """chance_detected against every one of the 2^8 alarm sequences of 8 records, weighted by its
    probability at rate 0.3, through detect_onset (the onset rule it models)."""
    for n, rate, persistence in ((8, 0.3, 3), (8, 0.7, 3), (5, 0.5, 1), (2, 0.9, 3)):
        exact = sum(rate ** sum(s) * (1 - rate) ** (n - sum(s))
                    for s in itertools.product((0, 1), repeat=n) if detect_onset(np.array(s), persistence) is not None)
        assert verdicts.chance_detected(n, rate, persistence) == pytest.approx(exact, abs=1e-12)
    assert verdicts.chance_detected(12, 1.0, 3) == 1.0 and verdicts.chance_detected(12, 0.0, 3) == 0.0
    np.testing.assert_array_equal(verdicts.chance_detected([8, 2, 8], 0.7, 3), [verdicts.chance_detected(8, 0.7, 3),
                                                                                0.0, verdicts.chance_detected(8, 0.7, 3)])
    with pytest.raises(ValueError, match="probability"):
        verdicts.chance_detected(12, 1.5, 3)


def test_an_always_alarm_detector_reads_at_chance(thesis_small, tmp_path):
    """A plug-in alarming on every record "detects" every failing unit; scored by the command, every
    figure of it says at chance, none above."""
    out = tmp_path / "always"
    result = runner.invoke(app, ["bench", "score", "thesis", "--data", str(thesis_small),
                                 "--detector", "bench_plugins:AlwaysAlarm", "-o", str(out)])
    assert result.exit_code == 0, result.output
    r = json.loads(out.with_name("always.json").read_text())["results"]
    assert r["false_alarm_rate"]["value"] == 1.0 and r["detected_share"]["value"] == 1.0
    assert r["detected_share"]["chance"] == 1.0  # alarms on every record detect every unit by chance
    assert r["detection_at_5pct_far"]["value"] == pytest.approx(0.05)  # no separation: 5 % at 5 % false alarms
    assert r["auroc"]["value"] == pytest.approx(0.5)
    assert "detected 100.0 % of failing units: at chance" in result.output
    assert "detection at 5 % false alarms 5.0 % of worn records [5.0, 5.0]: at chance" in result.output
    assert "AUROC 0.500 [0.500, 0.500]: at chance" in result.output
    assert "delay: no verdict" in result.output and "above chance" not in result.output
    assert "AUROC at chance; at 5 % false alarms at chance; detected at chance" in out.with_name("always.md").read_text()


def test_a_detector_that_separates_is_above_chance(thesis_small):
    """The logistic regression baseline (learns the worn train records): few false alarms, and each
    detection figure above its chance; its delay is judged as a delay."""
    role, lr = baselines.make("lr")
    results = score.score(thesis_small, lr, "lr", role)
    r = results["results"]
    assert r["detection_at_5pct_far"]["ci95"][0] > 0.05
    assert r["detected_minus_chance"]["ci95"][0] > 0.0 and r["detected_share"]["chance"] < r["detected_share"]["value"]
    lines = verdicts.lines(results)
    assert lines[0].startswith("AUROC ") and lines[0].count("above chance") == 1
    assert "above chance" in lines[1] and re.search(r"detected \d+\.\d % of failing units: above chance", lines[2])
    assert lines[3].startswith("delay after 10 % wear ") and "a detection delay" in lines[3]


def test_transfer_entropy_on_a_short_track_is_warned_about(thesis_small, tmp_path):
    """12 records a unit with 10 bins: transfer entropy leaves most worn units undecided and its
    figure is flagged in the console and OUT.md; on units of 40 records no warning, on 30 one."""
    out = tmp_path / "te"
    result = runner.invoke(app, ["bench", "score", "thesis", "--data", str(thesis_small), "--baseline",
                                 "transfer_entropy", "-o", str(out)])
    assert result.exit_code == 0, result.output
    warning = "WARNING: the track's units have 12 records; transfer_entropy needs at least 31"
    assert warning in result.output and warning in out.with_name("te.md").read_text()
    assert "no verdict: the track is too short for the method" in out.with_name("te.md").read_text()
    r = json.loads(out.with_name("te.json").read_text())["results"]
    assert sum(u["named"] == 0 for u in r["per_unit"] if u["worn_axis"]) >= 4  # ties: undecided
    assert verdicts.records_needed(TransferEntropyIsolator(bins=5, history=2))[0] == 3 * 25 + 2
    assert verdicts.records_needed(baselines.make("trend")[1]) is None
    rng = np.random.default_rng(0)
    units = [files.Unit(id=f"test-{k:03d}", robot="irb6700", task="pick_place", sample="cycle",
                        arrays={"cycles": np.arange(1, 41), "mean_abs_torque": rng.random((40, 6))},
                        fault_level=np.linspace(0, 20, 40), worn_axis=2, fault="friction_wear") for k in range(3)]
    long = score.isolator_results(TransferEntropyIsolator(), "transfer_entropy", units)
    assert "warnings" not in long
    short = [dataclasses.replace(u, arrays={k: v[:30] for k, v in u.arrays.items()}) for u in units]
    assert "30 records; transfer_entropy needs at least 31" in score.isolator_results(
        TransferEntropyIsolator(), "transfer_entropy", short)["warnings"][0]


def test_an_isolator_naming_no_axis_has_no_verdict_not_below_chance(thesis_small, tmp_path):
    """An isolator that leaves every worn unit undecided scores top-1 0 %: an abstention, said as no
    verdict (the twin on the small conditions track read "below chance" from an empty answer set)."""
    out = tmp_path / "never"
    result = runner.invoke(app, ["bench", "score", "thesis", "--data", str(thesis_small),
                                 "--isolator", "bench_plugins:NeverNames", "-o", str(out)])
    assert result.exit_code == 0, result.output
    text = out.with_name("never.md").read_text()
    assert "no verdict (the method named no axis on any of the 6 worn units" in text
    assert "no verdict: the method named no axis on any worn unit" in text  # the row's verdict cell
    assert "below chance" not in text and "below chance" not in result.output
    r = json.loads(out.with_name("never.json").read_text())["results"]
    assert r["top1_accuracy"]["value"] == 0.0 and verdicts.named_none(r)
    # one worn unit named (wrongly) is an answer again, judged against chance
    r["per_unit"][next(i for i, u in enumerate(r["per_unit"]) if u["worn_axis"])]["named"] = 1
    assert not verdicts.named_none(r)


@pytest.mark.parametrize("method", ["pca", "trend"])
def test_out_md_is_a_markdown_table_with_a_verdict_line_per_figure(thesis_small, tmp_path, method):
    role, estimator = baselines.make(method)
    results = score.score(thesis_small, estimator, method, role)
    _, md = score.write(results, tmp_path / method, "faultgen bench score thesis --data 'a|b' --baseline " + method)
    text = md.read_text()
    table = [line for line in text.splitlines() if line.startswith("|")]
    assert len(table) == 3 and set(_cells(table[1])) == {"---"}
    assert len({len(_cells(line)) for line in table}) == 1  # header, separator and row: one number of cells
    parsed = _table(text)
    assert len(parsed) == 2 and len(parsed[0]) == len(parsed[1]) == len(_cells(table[0]))
    assert parsed[0][:3] == ["track", "method", "AUROC [95 % CI]"] and parsed[1][1] == method
    assert "a|b" in parsed[1][-2]  # the pipe of the command escaped, not a cell of its own
    verdict_lines = [line for line in text.splitlines() if line.startswith("- ")]
    assert verdict_lines == [f"- {line}" for line in verdicts.lines(results)]
    figures = 4 if role == "detector" else 1
    assert len(verdict_lines) == figures and all(
        re.search(r": (above|at|below) chance|no verdict", line) for line in verdict_lines)


def test_without_healthy_test_units_the_detection_figures_have_no_verdict():
    """Two failing test units and no healthy one: no false-alarm rate, so the detected share and the
    detection at 5 % false alarms get "no verdict", never a chance level made up."""
    rng = np.random.default_rng(0)

    def unit(k, fault, axis):
        return files.Unit(id=f"u{k}", robot="irb6700", task="pick_place", sample="cycle",
                          arrays={"cycles": np.arange(1, 21), **{f: rng.random((20, 6)) for f in files.FEATURES}},
                          fault_level=np.linspace(0, 20, 20) if axis else np.zeros(20), worn_axis=axis, fault=fault)

    r = score.detector_results(baselines.PCADetector(), "pca", [unit(0, "none", 0), unit(1, "friction_wear", 2)],
                               [unit(2, "friction_wear", 2), unit(3, "friction_wear", 3)])
    assert np.isnan(r["detected_share"]["chance"]) and np.isnan(r["detection_at_5pct_far"]["value"])
    lines = verdicts.detector_lines(r)
    assert lines[1].startswith("detection at 5 % false alarms: no verdict")
    assert "no verdict (no healthy test unit" in lines[2] and lines[3].startswith("delay: no verdict")
    assert verdicts.summary({"role": "detector", "results": r}).endswith("at 5 % false alarms no verdict; "
                                                                         "detected no verdict")


def test_no_unit_detected_is_below_chance_only_where_chance_would_detect_some():
    """0 of 18 failing units detected where chance detects each with 4.7 %: 0 is what chance gives on
    18 units 42 % of the time (binomial), so at chance, though the bootstrap interval of the difference
    lies below 0; on 200 units chance detects at least 4 (2.5 % quantile), so 0 is below chance."""
    difference = {"value": -0.047, "ci95": [-0.1, -0.03]}
    for units, expected in ((18, "at chance"), (200, "below chance")):
        detected = {"value": 0.0, "chance": 0.047, "chance_range95": verdicts.chance_range(units, 0.047)}
        assert verdicts.detected_word(detected, difference) == expected
    assert verdicts.chance_range(200, 0.047)[0] * 200 >= 4
    assert verdicts.detected_word({"value": 0.6, "chance_range95": verdicts.chance_range(6, 0.0)},
                                  {"ci95": [0.3, 0.9]}) == "above chance"
