"""A name that reaches a figure is drawn as it is written, never parsed as mathtext (issue 86,
item 5): a unit folder named ``u$\\foo$`` (legal on every file system) stopped every unit's
outputs of ``faultgen monitor`` and ``faultgen plot`` ("Unknown symbol: \\foo")."""

from __future__ import annotations

import csv
import shutil
import sys
from pathlib import Path

import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from typer.testing import CliRunner

sys.path.insert(0, str(Path(__file__).parent))
import fleetlog_folder

from faultgen.cli import app
from faultgen.data import reader
from faultgen.figure_text import plain
from faultgen.model import robots

NAME = "u$\\foo$"
runner = CliRunner()


@pytest.fixture(scope="module")
def fleet(tmp_path_factory) -> Path:
    logs = fleetlog_folder.write_fleet(tmp_path_factory.mktemp("fleet") / "LOGS", robots.load("puma560"), units=2,
                                       days=4)
    shutil.move(logs / "u1", logs / NAME)
    return logs


def test_plain_text_is_drawn_as_written_where_the_raw_name_is_refused_by_mathtext():
    fig = Figure()
    FigureCanvasAgg(fig)
    ax = fig.subplots()
    title = ax.set_title(plain(f"{NAME}: PCA monitor"))
    fig.canvas.draw()  # lays the text out: mathtext would parse it here
    assert title._preprocess_math(title.get_text()) == (f"{NAME}: PCA monitor", False)
    assert plain("a\\$b") == "a\\\\$b" and Figure().text(0, 0, plain("a\\$b"))._preprocess_math(plain("a\\$b")) == (
        "a\\$b", False)  # an escaped dollar in a name stays as written too
    ax.set_title(f"{NAME}: PCA monitor")
    with pytest.raises(ValueError, match="foo"):
        fig.canvas.draw()


def test_the_monitor_charts_a_unit_whose_name_holds_dollars_and_a_backslash(fleet, tmp_path):
    out = tmp_path / "out"
    result = runner.invoke(app, ["monitor", str(fleet), "--robot", "puma560", "-o", str(out), "--protocol", "own",
                                 "--no-progress"])
    assert result.exit_code == 0, result.output
    assert (out / f"{NAME}.png").stat().st_size > 1000 and (out / "u2.png").is_file()
    with open(out / "units.csv", newline="") as f:
        units = {row["unit"]: row["status"] for row in csv.DictReader(f)}
    assert units == {NAME: "learning", "u2": "learning"}


def test_plot_draws_a_fleet_imported_from_a_unit_whose_name_holds_dollars(fleet, tmp_path):
    data = tmp_path / "fleet.h5"
    imported = runner.invoke(app, ["logs", "import", str(fleet), "--robot", "puma560", "-o", str(data),
                                   "--no-progress"])
    assert imported.exit_code == 0, imported.output
    assert NAME in {run.id for run in reader.open(data).runs}
    figure = tmp_path / "fleet.png"
    result = runner.invoke(app, ["plot", str(data), "-o", str(figure)])
    assert result.exit_code == 0, result.output
    assert figure.stat().st_size > 1000
