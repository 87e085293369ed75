"""docs/tutorial.py runs as it is, on a tiny grid, so it cannot rot (issue 40)."""

import runpy
from pathlib import Path

import pandas as pd

TUTORIAL = Path(__file__).resolve().parent.parent / "docs" / "tutorial.py"


def test_the_tutorial_runs_and_writes_what_it_says(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("FAULTGEN_TUTORIAL_TINY", "1")
    names = runpy.run_path(str(TUTORIAL), run_name="__main__")
    assert (tmp_path / "tutorial.h5").exists() and (tmp_path / "tutorial-detection.png").stat().st_size > 0
    assert set(names["detected"]["protocol"]) == {"other-seeds"}  # two seeds: a monitor of the other unit
    assert names["table"].attrs["chance"]["cell"] == "lr control"
    back = pd.read_csv(tmp_path / "tutorial-features.csv.gz")
    assert len(back) == len(names["features"]) and set(back["axis"]) == set(range(1, 7))
