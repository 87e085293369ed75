"""Measured data spoken of as measured (issue 58, items 3 and 4): on a fleet of logs imported with
`faultgen logs import` (labels from events.csv: worn, healthy and unknown logs) classify, detect,
bench-isolators, info, info --card and plot run and none of their outputs names a wear percentage,
a truth or a simulation's options; classify's heatmap stars only the cells judged above chance."""

from __future__ import annotations

import re
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from matplotlib.figure import Figure
from matplotlib.text import Text
from typer.testing import CliRunner

from analysis import benchmark
from faultgen.cli import app
from faultgen.data import fleetlogs
from faultgen.model import robots

sys.path.insert(0, str(Path(__file__).parent))
import fleetlog_folder  # noqa: E402

runner = CliRunner()

#: What a simulation says and measured data cannot: a wear in percent, the true wear, simulation options.
FORBIDDEN = re.compile(r"\d+(\.\d+)? ?% (true )?wear|wear %|wear_pct|true wear|truth|--preset|--record|\bsweep\b",
                       re.IGNORECASE)


@pytest.fixture(scope="module")
def imported(tmp_path_factory):
    """5 units x 14 daily logs of irb6700: u1 and u2 wear axis 2 and 3 (events.csv: onset on day 9),
    u3 and u4 inspected healthy on the last day, u5 without an event (unknown); u1's third log,
    one of the logs its monitor learns from, is an outlier (3 times the Coulomb friction)."""
    folder = tmp_path_factory.mktemp("measured")
    robot = robots.load("irb6700")
    worn = {0: (2, 8, 0.3), 1: (3, 8, 0.3)}
    logs = fleetlog_folder.write_fleet(folder / "LOGS", robot, units=5, days=14, worn=worn)
    fleetlog_folder.write_log(logs / "u1" / "2026-03-03.csv", robot, 2, 0, np.full(robot.n_axes, 3.0))
    rows = [f"u{u + 1},2026-03-09,onset,{axis}" for u, (axis, _, _) in worn.items()]
    rows += [f"u{u},2026-03-14,healthy," for u in (3, 4)]
    (logs / "events.csv").write_text("unit,stamp,event,axis\n" + "\n".join(rows) + "\n")
    summary = fleetlogs.import_logs(logs, folder / "fleet.h5", robot="irb6700", progress=False)
    assert summary.labels == {"worn": 12, "healthy": 28, "unknown": 30}
    return folder / "fleet.h5"


def _texts(monkeypatch) -> list[str]:
    """Every text drawn on the figures saved from now on (titles, labels, cells)."""
    drawn: list[str] = []
    save = Figure.savefig

    def saving(fig, *args, **kwargs):
        drawn.extend(t.get_text() for t in fig.findobj(Text))
        return save(fig, *args, **kwargs)

    monkeypatch.setattr(Figure, "savefig", saving)
    return drawn


def _said(result, written: list[Path], drawn: list[str]) -> str:
    text = result.output + "".join(p.read_text() for p in written if p.suffix in (".csv", ".md"))
    return text + "\n".join(drawn)


@pytest.mark.parametrize("args", [
    ["classify", "--no-progress", "--jobs", "1", "--pairs", "4", "--preprocessing", "control"],
    ["detect", "--no-progress"],
    ["bench-isolators", "--no-progress"],
    ["info", "--card"],
    ["info"],
    ["plot"],
], ids=lambda a: a[0] + ("-card" if "--card" in a else ""))
def test_measured_data_is_spoken_of_as_measured(imported, tmp_path, monkeypatch, args):
    drawn = _texts(monkeypatch)
    out = ["-o", str(tmp_path / ("out.png" if args[0] == "plot" else "out"))] if args[0] not in ("info",) else []
    result = runner.invoke(app, [args[0], str(imported), *args[1:], *out])
    assert result.exit_code == 0, result.output
    written = sorted(tmp_path.iterdir())
    said = _said(result, written, drawn)
    found = sorted({m.group(0) for m in FORBIDDEN.finditer(said)})
    assert not found, (found, said)
    if args[0] == "classify":  # two worn units: stacking's inner folds by unit would hold one class
        assert "stacking left out" in said.lower() and "events.csv" in said
        assert "12 logs worn in 2 unit(s) (u1, u2), 28 healthy, 30 unknown" in said
    if args[0] == "detect":  # u1's outlying learning log sets its Q limit decades above its data
        assert re.search(r"the Q limit of u1 \(\S+, learned from samples 1-7 of the run\) lies \d+\.\d decades above",
                         said), said
        assert "onset_wear_pct" not in said and "the first log labelled worn by events.csv" in said
    if args[0] == "bench-isolators":
        assert "to first worn" in said and "| measured | 1 |" not in said
    if args[0] == "info" and "--card" in args:
        assert "12 worn (in 2 unit(s): u1, u2), 28 healthy, 30 unknown" in said
    if args[0] == "plot":
        assert "u5\nirb6700: logs 0 worn, 0 healthy, 14 unknown" in said and "lighter part" not in said


def test_classify_names_the_labels_events_csv_lacks(imported, tmp_path):
    result = runner.invoke(app, ["classify", str(imported), "--classifier", "stacking", "--preprocessing", "control",
                                 "--no-progress", "--jobs", "1", "-o", str(tmp_path / "c")])
    assert result.exit_code == 2, result.output
    said = " ".join(result.output.split())
    assert "needs samples of at least 2 classes" not in said
    assert "an `onset` or `failure` row for the worn axis of at least 3 units" in said, said
    assert "12 logs worn in 2 unit(s) (u1, u2), 28 healthy, 30 unknown" in said


def test_the_heatmap_stars_only_cells_judged_above_chance(tmp_path, monkeypatch):
    """lr judged (one cell above chance, one not), svm and rf not judged (NaN p): one star, and p only on lr."""
    columns = pd.MultiIndex.from_product([["lr", "svm", "rf"], ["mean", "std"]], names=["classifier", "statistic"])
    table = pd.DataFrame([[0.9, 0.1, 0.8, 0.1, 0.7, 0.1], [0.5, 0.1, 0.6, 0.2, 0.6, 0.1]], columns=columns,
                         index=pd.Index(["control", "+diff"], name="preprocessing"))
    judged = benchmark.with_verdict(table, {"lr control": np.full(19, 0.5), "lr +diff": np.full(19, 0.55)})
    assert judged[("svm", "above")].isna().all() and judged[("svm", "p")].isna().all()
    drawn = _texts(monkeypatch)
    benchmark.classification_heatmap(judged, tmp_path / "h.png")
    cells = [t for t in drawn if re.fullmatch(r"\d\.\d\d(\np \S+( \*)?)?", t)]
    assert len(cells) == 6, drawn
    assert [c for c in cells if c.endswith("*")] == ["0.90\np 0.05 *"], cells
    assert not any("nan" in c for c in cells), cells
    assert "1 cells" in next(t for t in drawn if "above chance" in t)
