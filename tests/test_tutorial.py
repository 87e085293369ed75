"""docs/tutorial.py runs as it is, on a tiny grid, so it cannot rot (issue 40); run as a script,
every cell prints, and what it prints carries its verdict (issue 51)."""

import re
from pathlib import Path

import pandas as pd

TUTORIAL = Path(__file__).resolve().parent.parent / "docs" / "tutorial.py"


def test_the_tutorial_runs_every_cell_prints_and_says_what_its_numbers_rest_on(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("FAULTGEN_TUTORIAL_TINY", "1")
    cells = [c for c in re.split(r"^# %%.*$", TUTORIAL.read_text(), flags=re.M)
             if c.strip() and not c.lstrip().startswith("# ---") and
             any(line.strip() and not line.lstrip().startswith("#") for line in c.splitlines())]
    names: dict = {"__name__": "__main__"}
    printed = []
    for cell in cells:  # as `python docs/tutorial.py` runs them, one after the other
        exec(compile(cell, str(TUTORIAL), "exec"), names)
        printed.append(capsys.readouterr().out)
    silent = [cell.strip().splitlines()[-1] for cell, out in zip(cells, printed, strict=True) if not out.strip()]
    assert not silent, f"cells that print nothing as a script: {silent}"
    text = "".join(printed)
    assert "trend: names an axis on every healthy run: its accuracy on worn runs is no finding" in text
    assert "verdict:" in text and "above_chance" in text and "| chance |" in text
    assert (tmp_path / "tutorial.h5").exists() and (tmp_path / "tutorial-detection.png").stat().st_size > 0
    assert set(names["detected"]["protocol"]) == {"other-seeds"}  # two seeds: a monitor of the other unit
    assert names["table"].attrs["chance_source"] == "lr" and names["table"].attrs["permutations"] == 19
    back = pd.read_csv(tmp_path / "tutorial-features.csv.gz")
    assert len(back) == len(names["features"]) and set(back["axis"]) == set(range(1, 7))
