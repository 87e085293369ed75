"""A fleet's scale prior (``faultgen monitor --scale-prior OTHER``, :mod:`faultgen.monitor.scale_prior`):
the prediction interval against tabulated values and a Monte Carlo of its coverage, the factors it keeps
from another run's wear.csv, and the refusals that name what to do."""

import csv
import math

import numpy as np
import pytest

from faultgen.monitor import run_settings, scale_prior, state
from faultgen.monitor.scoring import Settings


def test_the_prior_keeps_the_normal_prediction_intervals_one_sided_bound():
    """Eight factors (the 1.5 % fleet's first informative ones, /tmp/P/015, 2026-11-29): mean 0.961556, sample
    standard deviation 0.141339; the prediction interval's half-width t(0.9, 7) s sqrt(1 + 1/8), t(0.9, 7) =
    1.415 in the tables (Hahn, Meeker & Escobar 2017, ch. 4.6), over z(0.9) = 1.2816: sd 0.1655."""
    factors = np.array([1.16261, 1.05927, 0.906537, 0.708151, 0.895001, 1.05916, 0.885898, 1.01582])
    prior = scale_prior.pooled(factors, "fleet")
    assert prior.mean == pytest.approx(0.961556, abs=1e-6)
    assert prior.spread == pytest.approx(0.141339, abs=1e-6)
    assert prior.sd == pytest.approx(1.415 * 0.141339 * math.sqrt(9 / 8) / 1.2816, rel=2e-4)
    assert prior.sd == pytest.approx(0.1655, abs=1e-4)
    assert (prior.axes, prior.source) == (8, "fleet")


def test_a_new_units_factor_falls_below_the_priors_bound_one_time_in_ten():
    """Monte Carlo (not the formula's own arithmetic): 20 000 fleets of k = 5 factors drawn N(1.1, 0.12^2)
    and one new unit's each; the new factor lies below the prior's one-sided 90 % bound (mean - 1.2816 sd)
    on 10 % of them (within 0.6 point: three binomial standard errors), where the plug-in N(m, s^2) misses
    more often (small k: its bound too high)."""
    rng = np.random.default_rng(7)
    below = plug_in = 0
    for _ in range(20_000):
        factors, new = rng.normal(1.1, 0.12, 5), rng.normal(1.1, 0.12)
        prior = scale_prior.pooled(factors)
        below += new < prior.mean - 1.2816 * prior.sd
        plug_in += new < factors.mean() - 1.2816 * factors.std(ddof=1)
    assert abs(below / 20_000 - 0.10) < 0.006 and plug_in / 20_000 > 0.12


def _write_wear(folder, rows):
    with open(folder / "wear.csv", "w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(["unit", "stamp", "phase", "axis", "wear", "wear_5", "wear_95", "wear_lower",
                         "wear_log", "wear_scale", "scale_factor", "scale_factor_sd"])
        for unit, stamp, axis, scale, factor, sd in rows:
            writer.writerow([unit, stamp, "monitoring", axis, 1, 0, 2, 0, 1, scale, factor, sd])


def test_the_first_informative_factor_of_each_units_axis_is_kept(tmp_path):
    """Each unit's axis its first row on the tests' scale whose factor its tests told (error at most half the
    default prior's); a healthy axis's (at the prior) and twin-scale rows are left out."""
    _write_wear(tmp_path, [("u1", "2026-01-01", 2, "friction test", 1.0, 0.3),
                           ("u1", "2026-02-01", 2, "friction test", 1.3, 0.08),
                           ("u1", "2026-03-01", 2, "friction test", 1.4, 0.05),
                           ("u1", "2026-02-01", 1, "friction test", 1.0, 0.29),
                           ("u2", "2026-02-01", 3, "friction test", 1.1, 0.06),
                           ("u3", "2026-02-01", 5, "friction test", 1.2, 0.1),
                           ("u4", "2026-02-01", 4, "twin", "", "")])
    with open(tmp_path / "wear.csv") as f:
        kept = scale_prior.informative_factors(list(csv.DictReader(f)), "wear.csv")
    assert kept == [("u1", 2, 1.3, 0.08), ("u2", 3, 1.1, 0.06), ("u3", 5, 1.2, 0.1)]
    prior = scale_prior.learn(tmp_path)
    assert prior == scale_prior.pooled(np.array([1.3, 1.1, 1.2]), str(tmp_path))
    assert "3 units' axes" in prior.note()


@pytest.mark.parametrize(("rows", "message"), [
    (None, "no wear.csv there"),
    ([("u1", "2026-01-01", 2, "friction test", 1.3, 0.08)] * 2, "1 units' axes whose friction tests saw"),
    ([("u1", "2026-01-01", 2, "friction test", "many", 0.08)], "line 2: axis '2', scale_factor 'many'"),
])
def test_a_folder_the_prior_cannot_be_learned_from_is_refused_by_name(tmp_path, rows, message):
    if rows is not None:
        _write_wear(tmp_path, rows)
    with pytest.raises(ValueError, match=message):
        scale_prior.learn(tmp_path)


def test_a_wear_table_without_the_factor_is_refused_with_what_to_do(tmp_path):
    (tmp_path / "wear.csv").write_text("unit,stamp,phase,axis,wear,wear_scale\n"
                                       "u1,2026-01-01,monitoring,1,0,twin\n")
    with pytest.raises(ValueError, match="no column scale_factor, scale_factor_sd.*score that fleet again"):
        scale_prior.learn(tmp_path)


@pytest.mark.parametrize(("mean", "sd"), [(0.0, 0.1), (1.2, -0.1), (math.nan, 0.1), (1.2, math.inf)])
def test_a_prior_that_is_no_factor_is_refused(mean, sd):
    with pytest.raises(ValueError, match="expected a finite number above 0"):
        scale_prior.ScalePrior(mean, sd)


def test_the_prior_is_part_of_what_a_state_belongs_to_and_of_the_settings_file():
    """A run with a fleet's prior has another digest (a continued run with another prior is not one run),
    a run without one the digest it had before; settings.json's keys are ones a run writes."""
    before = state.settings_digest(Settings(), "per-unit", False, "abc")
    assert "scale_prior_mean" not in before
    given = state.settings_digest(Settings(), "per-unit", False, "abc", "measured", (1.2, 0.1))
    assert given == {**before, "scale_prior_mean": 1.2, "scale_prior_sd": 0.1}
    assert run_settings.check_settings({"scale_prior_mean": 1.2, "scale_prior_sd": 0.1}, "s.json")
    with pytest.raises(ValueError, match="scale_prior_sd = -1; expected a finite number above 0"):
        run_settings.check_settings({"scale_prior_sd": -1}, "s.json")
