"""A sweep's worker imports what a run needs (issue 87 item 4): a fresh worker process's ``import
faultgen.runs.worker`` and a thesis task's run in it import neither scipy's signal, optimize, stats
and interpolate (the log reader's derivatives, the Stribeck fit, a Cartesian path's spline) nor
pandas (the log formats) nor mink (the planner's inverse kinematics): each worker of a ``--jobs 2``
sweep paid about 3 s of CPU for them at its start (docs/performance.md, "Sweeps")."""

from __future__ import annotations

import json
import pickle
import subprocess

import faultgen
from faultgen import children
from faultgen.logs import formats
from faultgen.operation import programs
from faultgen.runs.grid import Grid

#: What neither a worker's import nor a thesis task's run needs.
NOT_NEEDED = {"scipy.signal", "scipy.optimize", "scipy.stats", "scipy.interpolate", "pandas", "mink"}

#: In a fresh interpreter, as a worker: import the worker module, run the pickled runs (argv[1]) into
#: part files in argv[2], then import the log reader; print ``sys.modules`` after each step.
WORKER = r"""
import json, pickle, sys
from pathlib import Path
import faultgen.runs.worker as worker
seen = [sorted(sys.modules)]
for run_id, config in pickle.loads(Path(sys.argv[1]).read_bytes()):
    worker.simulate_and_write(run_id, worker.Run(config, worker.sim.backends.DEFAULT_STEPPER),
                              Path(sys.argv[2]) / f"{run_id}.h5")
seen.append(sorted(sys.modules))
import faultgen.logs.formats
seen.append(sorted(sys.modules))
print(json.dumps(seen))
"""


def test_a_worker_imports_and_runs_a_thesis_task_without_scipy_pandas_or_mink(tmp_path):
    runs = Grid(robots=["irb6700"], tasks=["pick_place"], axes=[1], cycles=1, seeds=[0]).runs()
    (tmp_path / "runs.pkl").write_bytes(pickle.dumps(runs))
    done = subprocess.run(children.command("-c", WORKER, str(tmp_path / "runs.pkl"), str(tmp_path)),
                          capture_output=True, text=True, env=children.environment(), check=True)
    imported, ran, reader = (set(modules) for modules in json.loads(done.stdout.splitlines()[-1]))
    assert {"faultgen.runs.worker", "h5py", "mujoco"} <= imported
    assert not imported & NOT_NEEDED, sorted(imported & NOT_NEEDED)
    assert not ran & NOT_NEEDED, sorted(ran & NOT_NEEDED)
    # the check sees these imports where they are made: the log reader's
    assert {"pandas", "scipy.signal"} <= reader - ran
    ((run_id, _),) = runs
    with faultgen.open(tmp_path / f"{run_id}.h5") as dataset:  # the run written, as the sweep reads it
        (run,) = dataset.runs
        assert (run.id, run.robot, run.task, run.seed, list(run.worn_axes)) == (run_id, "irb6700", "pick_place", 0, [1])


def test_a_log_task_in_the_default_format_is_the_task_itself(tmp_path):
    log = tmp_path / "log.csv"
    assert programs.log_task(str(log), formats.MEASURED) == str(log)
    assert programs.log_task("pick_place", formats.MEASURED) == "pick_place"
    other = programs.log_task(str(log), formats.make("ur-rtde"))
    assert isinstance(other, programs.LogTask) and other.adapter.name == "ur-rtde"
