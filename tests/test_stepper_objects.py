"""Steppers travel as objects, not names (issue 74, item 1): a stepper is a frozen, picklable value;
:class:`faultgen.runs.context.ExecutionContext` carries it with ``jobs`` and ``scheduler``; the
CLI's ``--backend NAME`` is resolved to an object once, at the CLI boundary; and a Dask task key
keeps the text it had when the stepper travelled by name (reference: the key computed here from
that text)."""

import dataclasses
import hashlib
import pickle

import pytest
from typer.testing import CliRunner

from faultgen.cli import app
from faultgen.data import dataset
from faultgen.operation.wear import WearPlan
from faultgen.runs import cluster
from faultgen.runs.context import LOCAL, ExecutionContext
from faultgen.simulation import backends
from faultgen.simulation.resolve import Run
from resolved_runs import run_config


def test_a_stepper_is_a_frozen_picklable_value():
    assert backends.get("batch") == backends.BatchStepper() == backends.DEFAULT_STEPPER != backends.BatchStepper(2)
    assert backends.get("loop") == backends.LoopStepper()
    for stepper in (backends.BatchStepper(3), backends.LoopStepper()):
        assert pickle.loads(pickle.dumps(stepper)) == stepper
    with pytest.raises(dataclasses.FrozenInstanceError):
        backends.BatchStepper().nthread = 2
    with pytest.raises(ValueError, match="is not a stepping backend"):
        backends.register(backends.LoopStepper())  # a class is registered, not an instance


def test_a_task_key_keeps_the_text_it_had_with_names():
    config = run_config(robot="puma560", task="pick_place", wear=WearPlan({}), cycles=1, seed=0)

    def key(extra: str) -> str:  # main's task_key: the config key, then "backend=NAME" unless the default
        return "faultgen-r1-" + hashlib.sha256((dataset.config_key(config) + extra).encode()).hexdigest()[:16]

    assert cluster.task_key("r1", Run(config, backends.DEFAULT_STEPPER)) == key("")
    assert cluster.task_key("r1", Run(config, backends.BatchStepper())) == key("")
    assert cluster.task_key("r1", Run(config, backends.LoopStepper())) == key("\nbackend=loop")
    assert cluster.task_key("r1", Run(config, backends.BatchStepper(2))) == key("\nbackend=batch BatchStepper(nthread=2)")


def test_an_execution_context_checks_its_values_and_names_them():
    assert LOCAL == ExecutionContext(1, None, backends.BatchStepper())
    assert pickle.loads(pickle.dumps(ExecutionContext(2, None, backends.LoopStepper()))).stepper == backends.LoopStepper()
    for bad, said in [({"jobs": 0}, "jobs 0: expected a whole number >= 1"),
                      ({"jobs": True}, "jobs True"),
                      ({"scheduler": ""}, "scheduler '': expected None or an address"),
                      ({"stepper": "loop"}, "'loop' is not a stepper")]:
        with pytest.raises(ValueError, match=said):
            ExecutionContext(**bad)


@pytest.mark.parametrize("command", ["sweep", "fleet"])
def test_the_cli_resolves_backend_to_a_stepper_once(command, tmp_path, monkeypatch):
    from faultgen.cli import runs as run_commands

    contexts = []
    monkeypatch.setattr(run_commands, "run_sweep", lambda plan, out, context, **kwargs: contexts.append(context))
    for name, expected in [(None, backends.BatchStepper()), ("loop", backends.LoopStepper())]:
        args = [command, "-o", str(tmp_path / f"{name}.h5"), "--jobs", "2"] + (["--backend", name] if name else [])
        result = CliRunner().invoke(app, args)
        assert result.exit_code == 0, result.output
        assert contexts[-1] == ExecutionContext(2, None, expected)
    result = CliRunner().invoke(app, [command, "-o", str(tmp_path / "gpu.h5"), "--backend", "gpu"])
    assert result.exit_code == 2 and "unknown stepping backend 'gpu'; expected one of batch, loop" in result.output
