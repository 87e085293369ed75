"""The reproduction reads its steps' CSV outputs through faultgen.inputs' bounded reader (issue 86
leftover): a table larger than the bound, a link to something that is not a regular file or text
that is not UTF-8 is refused naming the file before pandas parses it; a step's table reads as
pandas reads it."""

from __future__ import annotations

import os

import pandas as pd
import pytest

from faultgen import inputs
from faultgen.reproduce import tables

ISOLATION = ("task,wear_pct,worn_axis,isolator,correct,predicted\n"
             "pick_place,1.0,1,te10,True,1\npick_place,1.0,0,te10,False,2\n")


def test_a_steps_csv_reads_as_pandas_reads_it(tmp_path):
    path = tmp_path / "j2-isolation.csv"
    path.write_text(ISOLATION)
    pd.testing.assert_frame_equal(tables._csv(path), pd.read_csv(path))


def test_a_csv_past_the_bound_or_not_text_is_refused_naming_it(tmp_path, monkeypatch):
    path = tmp_path / "j2-isolation.csv"
    path.write_text(ISOLATION)
    monkeypatch.setattr(tables, "CSV_MAX_BYTES", len(ISOLATION) - 1)
    with pytest.raises(inputs.InputError, match=f"{path}.*{len(ISOLATION)}"):
        tables.table_6_2(tmp_path)  # the builder itself reads through the bound
    monkeypatch.setattr(tables, "CSV_MAX_BYTES", 2**20)
    path.write_bytes(b"task,wear_pct\n\xff\xfe,1\n")
    with pytest.raises(inputs.InputError, match="byte 14 is not UTF-8"):
        tables._csv(path)
    path.unlink()
    os.mkfifo(path)  # a FIFO would block an unbounded reader for ever
    with pytest.raises(inputs.InputError, match=str(path)):
        tables._csv(path)
    path.unlink()
    path.write_text("")
    with pytest.raises(inputs.InputError, match="not a CSV table"):
        tables._csv(path)
