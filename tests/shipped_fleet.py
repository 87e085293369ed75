"""A fleet of faultgen's own shipped robots as a service team's log folder (issue 60): each unit one
faultgen run of a thesis task, one recorded cycle a day written as that day's log
(``LOGS/<unit>/<date>.csv``: ``t, q1..qN, tau1..tauN`` arm side, ``temperature1..N``, ``payload``),
with the operating conditions switched on as a user would (joint temperature over the season, the
unit-to-unit spread, faultgen's default encoder noise, a part on some days) and, on the worn units,
one axis's dry friction growing by thesis eq. 6.6 from an onset day. One unit's logs have no
``payload`` column (a controller that does not log it).

This is faultgen's own simulator, so the check is of the monitor's robustness on the robots faultgen
ships (the README's example), not an independent one: that is ``independent_fleet.py``.
"""

from __future__ import annotations

import datetime
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from faultgen.model import robots
from faultgen.operation import conditions, wear
from faultgen.simulation import sensors
from faultgen.simulation import stepping as sim
from resolved_runs import run_config


@dataclass(frozen=True)
class ShippedFleet:
    """``units`` units of ``robot`` doing ``task`` for ``days`` days from ``start`` (day of year
    ``start_day``); ``worn`` maps a unit's number (1-based) to its worn axis, wearing by
    ``final_wear`` % from day ``onset`` (eq. 6.6, exp4, reached on the last day); parts of
    ``parts`` kg in blocks of ``block`` days; unit ``no_payload`` logs no payload column."""

    robot: str = "irb6700"
    task: str = "pick_place"
    units: int = 3
    days: int = 36
    worn: dict = field(default_factory=lambda: {2: 2})
    onset: int = 14
    final_wear: float = 60.0
    parts: tuple = (15.0, 35.0)
    block: int = 4
    no_payload: int = 3
    start: str = "2026-04-01"
    start_day: float = 91.0
    seed: int = 0


def unit_name(i: int) -> str:
    return f"{i:02d}"


def write_fleet(root: Path, spec: ShippedFleet = ShippedFleet()) -> tuple[Path, dict[str, dict]]:
    """Write the fleet's logs under ``root/logs``; returns (logs folder, truth per unit: ``axis``
    worn (0 healthy) and ``wear`` per day, %)."""
    robot = robots.load(spec.robot)
    n = robot.n_axes
    logs = Path(root) / "logs"
    truth = {}
    first = datetime.date.fromisoformat(spec.start)
    sizes = tuple(round((m / 2700.0) ** (1 / 3), 3) for m in spec.parts)
    for i in range(1, spec.units + 1):
        axis = spec.worn.get(i, 0)
        plan = (wear.WearPlan.from_specs([f"{axis}:exp4:{spec.final_wear:g}:onset={spec.onset}"], last_cycle=spec.days)
                if axis else wear.WearPlan({}))
        held = conditions.Conditions(thermal=conditions.Temperature(),
                                     payloads=conditions.Payloads(spec.parts, sizes, "blocks", spec.block),
                                     spread=conditions.UnitSpread(), cycles_per_day=1, start_day=spec.start_day)
        config = run_config(robot=spec.robot, task=spec.task, friction="stribeck", wear=plan, cycles=spec.days,
                               seed=spec.seed * 1000 + i, noise=sensors.NoiseConfig(), nthread=1, conditions=held,
                               signals=True)
        result = sim.simulate(config, progress=False)
        assert result.saturated.size == 0, (i, result.saturated)
        folder = logs / unit_name(i)
        folder.mkdir(parents=True)
        names = ["t", *(f"q{k}" for k in range(1, n + 1)), *(f"tau{k}" for k in range(1, n + 1)),
                 *(f"temperature{k}" for k in range(1, n + 1))]
        payload = i != spec.no_payload
        if payload:
            names.append("payload")
        for c in range(spec.days):
            columns = [result.t, result.q_a[c], result.tau_m[c] * robot.gear_ratio,
                       np.repeat(result.conditions.joint_temperature[c][None], len(result.t), axis=0)]
            if payload:
                columns.append(np.full(len(result.t), result.conditions.payload_mass[c]))
            np.savetxt(folder / f"{first + datetime.timedelta(days=c)}.csv", np.column_stack(columns),
                       delimiter=",", header=",".join(names), comments="", fmt="%.9g")
        multiplier = result.friction_multiplier[:, axis - 1] if axis else np.ones(spec.days)
        truth[unit_name(i)] = {"axis": axis, "wear": 100.0 * (np.asarray(multiplier) - 1.0)}
    return logs, truth
