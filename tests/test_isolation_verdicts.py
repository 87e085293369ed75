"""`faultgen bench-isolators` judges each isolator against chance (issue 88, item 4): its accuracy over
the worn cases it ran on, against naming one of N axes at random, by a one-sided binomial test."""

import pandas as pd
import pytest
from scipy.stats import binom

from analysis.benchmark.isolation_scores import isolation_verdicts


def cases(name: str, right: int, wrong: int, short: int = 0, healthy: int = 3) -> list[dict]:
    rows = [dict(isolator=name, worn_axis=2, predicted=2, correct=True, n_axes=6)] * right
    rows += [dict(isolator=name, worn_axis=2, predicted=3, correct=False, n_axes=6)] * wrong
    rows += [dict(isolator=name, worn_axis=2, predicted=-1, correct=False, n_axes=6)] * short  # too few cycles
    rows += [dict(isolator=name, worn_axis=0, predicted=0, correct=True, n_axes=6)] * healthy  # no fault: not counted
    return rows


def test_each_isolator_is_judged_on_its_worn_cases_against_one_in_n():
    table = pd.DataFrame(cases("good", 10, 2, short=5) + cases("poor", 2, 10) + cases("starved", 0, 0, short=4))
    lines = isolation_verdicts(table).splitlines()
    assert "16.7 % (one of 6 axes at random" in lines[0]
    p_good = binom.sf(9, 12, 1 / 6)  # P(X >= 10), X ~ B(12, 1/6): the test written out
    assert lines[1] == f"  good: 10 of 12 (83.3 %), p = {p_good:.2g}: above chance"
    assert lines[2].startswith("  poor: 2 of 12 (16.7 %)") and lines[2].endswith(": not above chance")
    assert binom.sf(1, 12, 1 / 6) == pytest.approx(float(lines[2].split("p = ")[1].split(":")[0]), rel=0.05)
    assert lines[3] == "  starved: no worn case with enough cycles: not judged"
