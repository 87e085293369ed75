"""`faultgen monitor`'s options default to the library's own defaults.

The command line repeats the monitor's defaults (`faultgen.monitor.scoring.Settings`,
`faultgen.monitor.run.MonitorRun`) and bounds in its option table, so that `faultgen --help`
loads without the monitor (tests/test_cli_lazy.py). A default changed on one side only would make
the command and the library disagree silently (issue 90 moved `wear_limit` 10 -> 8 in both places by
hand); these tests fail when they do.
"""

from __future__ import annotations

import dataclasses
import inspect

from faultgen.cli import monitoring
from faultgen.monitor import run as monitor_run
from faultgen.monitor import scoring


def _cli_defaults() -> dict:
    return {name: p.default for name, p in inspect.signature(monitoring.monitor_command).parameters.items()}


def test_every_setting_the_command_takes_defaults_to_the_monitors_own():
    cli = _cli_defaults()
    settings = {f.name: f.default for f in dataclasses.fields(scoring.Settings)}
    shared = sorted(set(cli) & set(settings))
    # the command names every setting a user may change but the PCA's variance (fixed)
    assert shared == ["alpha", "persistence", "protocol", "train", "wear_limit"]
    assert {name: cli[name] for name in shared} == {name: settings[name] for name in shared}


def test_the_runs_own_defaults_agree_too():
    cli = _cli_defaults()
    run = {f.name: f.default for f in dataclasses.fields(monitor_run.MonitorRun)
           if f.default is not dataclasses.MISSING}
    for name in ("calibrate", "twin_temperature", "failure_wear", "hours_per_day", "progress"):
        assert cli[name] == run[name], name


def test_the_commands_bounds_on_logs_are_the_monitors():
    assert (monitoring.MIN_TRAIN, monitoring.MAX_LOGS) == (scoring.MIN_TRAIN, scoring.MAX_LOGS)
