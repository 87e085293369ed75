"""The `first-look` preset carries the README's first analyses (issue 88, item 4): two seeds, so
`detect`'s default protocol judges each monitor on another unit's healthy run; recorded cycles
before each wear level of `bench-isolators`' default table enough for every isolator from 5 %
(at 1 %, pca_contribution's 21 are not there, as docs/performance.md says); and `sweep` names
the analyses when done. The analyses' results and times are benchmarks/first_look.py's
(docs/performance.md, "A first look"): a sweep takes minutes of CPU, past a test's share."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from analysis import benchmark, isolation
from faultgen.cli import runs as cli_runs
from faultgen.runs.grid import Grid


def _cycles_up_to(grid: Grid, level: float) -> int:
    """Recorded cycles up to the first whose true wear reaches ``level`` % (bench-isolators' cases)."""
    recorded = np.asarray(grid.recorded_cycles())
    wear = 100.0 * (np.asarray([grid.wear_schedules[0].multiplier(c) for c in recorded]) - 1.0)
    return int(np.flatnonzero(wear >= level)[0]) + 1


def test_the_first_look_grid_has_two_seeds_and_the_cycles_each_isolator_needs():
    grid = Grid.from_preset("first-look")
    assert len(grid.seeds) >= 2 and 0 in grid.axes and not grid.signals
    needs = {name: isolation.min_rows(iso) for name, iso in benchmark.default_isolators().items()}
    counts = {level: _cycles_up_to(grid, level) for level in (1, 5, 10, 15)}
    assert counts[1] == 9 and counts[5] == 32, counts  # cycles 41-49 and 41-72 (exp4: 20 (c/100)^4 %)
    assert all(need <= counts[5] for need in needs.values()), (needs, counts)
    assert needs["pca_contribution"] > counts[1]  # as the table says: not applicable at 1 %
    quick = Grid.from_preset("quick")  # the main job's dataset: pca_contribution never runs (issue 88)
    assert needs["pca_contribution"] > _cycles_up_to(quick, 15)


def test_the_sweep_names_the_analyses_of_the_first_look_and_points_quick_to_it():
    out = Path("first-look.h5")
    text = cli_runs.next_steps("first-look", out)
    assert all(f"faultgen {c} first-look.h5" in text for c in ("bench-isolators", "detect", "classify")), text
    assert "faultgen detect first-look.h5 --locate contribution" in text  # cross-correlation locates none there
    assert "faultgen sweep --preset first-look" in cli_runs.next_steps("quick", Path("quick.h5"))
    other = Path("j2.h5")
    assert "analyse" not in cli_runs.next_steps(None, other) and "first-look" not in cli_runs.next_steps("j2", other)
