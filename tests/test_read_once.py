"""``faultgen monitor`` opens each log file once (issue 57, item 2: "each command reads a log file
once; parsed data is passed on, hashed from what was parsed").

Measured with tests/open_counter.py on the fleet of tests/test_monitor.py (tests/independent_fleet.py:
3 KR210 units x 40 daily CSV logs, all three running one program) before the change (main f7f253d):

=====================================  ==============  ==============
opens of a log file                    ``--no-calibrate``  calibrated
=====================================  ==============  ==============
first log of unit01 (everyone's program)          53              59
first log of unit02, unit03                        14              20
every later log                                     7               7
=====================================  ==============  ==============

A measured CSV read took 6 opens (the header and its gzip sniff, the row bound's gzip sniff, the
parser's two sniffs and its read) plus one for the SHA-256; the first log was parsed by the
program's identification, the calibration, each unit's twin and its scoring (8 parses of unit01's).
Now each log is read once into memory (:func:`faultgen.inputs.hold`), hashed and parsed from those
bytes (:class:`faultgen.monitor.logs.Source`), and the parsed log is passed on: 1 open per log, with
the outputs of before byte for byte (the SHA-256 keys of the state and caches are the file's).
"""

from pathlib import Path

import fleetlog_folder
import numpy as np
import open_counter
import pandas as pd
import pytest

from faultgen import inputs
from faultgen.logs import formats, measured
from faultgen.model import robots
from faultgen.monitor import logs as fleet_logs

# The calibrated monitor run that opens every log once is tests/test_resolve_once.py's
# test_a_calibrating_monitor_resolves_its_robot_once (one calibrating run counts both).


@pytest.mark.parametrize("suffix", [".csv", ".csv.gz", ".h5"])
def test_a_held_log_parses_as_its_file_and_is_opened_once(tmp_path, suffix):
    puma = robots.load("puma560")
    path = fleetlog_folder.write_log(tmp_path / f"log{suffix}", puma, 0, 1, np.zeros(puma.n_axes))
    with open_counter.opens_under(tmp_path) as counts:
        parsed = fleet_logs.parse(path, puma)
    assert dict(counts) == {path.name: 1}
    by_path = measured.read(path, puma)
    assert parsed.sha256 == inputs.hold(path, "log", 2**30).sha256
    assert parsed.data.source == by_path.source == path
    for name in ("t", "q", "qd", "tau"):
        assert np.array_equal(getattr(parsed.data, name), getattr(by_path, name))
    assert parsed.data.notes == by_path.notes


def test_a_held_log_is_refused_with_the_message_of_its_file(tmp_path):
    path = tmp_path / "bad.csv"
    path.write_text("t,q1\n0,1\n")
    with pytest.raises(measured.MeasuredDataError) as from_file:
        measured.read(path, robots.load("puma560"))
    parsed = fleet_logs.parse(path, robots.load("puma560"))
    assert isinstance(parsed.error, measured.MeasuredDataError)
    assert str(parsed.error) == str(from_file.value)
    with pytest.raises(measured.MeasuredDataError):
        parsed.checked()
    assert Path(str(inputs.hold(path, "log", 100))) == path


@pytest.mark.parametrize("name", ["ur-rtde", "voraus"])
def test_the_built_in_adapters_parse_a_held_log_as_their_file_and_open_it_once(tmp_path, name):
    """ur-rtde (space-separated RTDE recorder CSV) and voraus (Parquet) read the held bytes
    (``reads_held``): the monitor's :class:`faultgen.monitor.logs.Source` opens their logs once."""
    puma = robots.load("puma560")
    t, q, qd, tau, cycle = fleetlog_folder.log_signals(puma, 3, 0, np.zeros(6))
    if name == "ur-rtde":
        path = tmp_path / "2026-03-01.csv"
        columns = {"timestamp": t, **{f"actual_q_{k}": q[:, k] for k in range(6)},
                   **{f"target_moment_{k}": tau[:, k] for k in range(6)}}
        pd.DataFrame(columns).to_csv(path, sep=" ", index=False)
    else:
        path = tmp_path / "1.parquet"
        table = {"time": t, "sample": cycle, **{f"joint_position_{k + 1}": q[:, k] for k in range(6)},
                 **{f"motor_torque_{k + 1}": tau[:, k] / puma.gear_ratio[k] for k in range(6)}}
        pd.DataFrame(table).to_parquet(path)
    adapter = formats.make(name)
    with open_counter.opens_under(tmp_path) as counts:
        parsed = fleet_logs.Source(puma, adapter).get(fleet_logs.Log("u1", path.stem, 0.0, "sequence", path, path.name))
    assert dict(counts) == {path.name: 1}
    by_path = adapter.read(path, puma)  # the monitor reads with the accelerations its calibration needs (issue 72)
    assert parsed.data.source == path and parsed.data.notes == by_path.notes
    for field in ("t", "q", "qd", "tau"):
        assert np.array_equal(getattr(parsed.data, field), getattr(by_path, field))
