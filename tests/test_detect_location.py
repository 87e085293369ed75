"""`faultgen detect --locate contribution` (issue 88, item 4): the onset located at the axis with the
largest reconstruction-based contribution to the PCA monitor's combined index, where the thesis's
cross-correlation rule (ch. 3.4.2) needs the fault to travel from the worn axis to the others and so
located none of 12 worn runs of the first-look preset. The location is printed against chance."""

import numpy as np
import pandas as pd
import pytest

from analysis import benchmark, registry
from analysis.benchmark import detection
from analysis.benchmark.detection_report import location_verdict
from analysis.benchmark.tables import UNDECIDED
from analysis.monitoring import fit_q_monitor


def monitor_and_features(k: int, seed: int = 0):
    """A Q monitor (75 % of the variance) fitted on 60 samples of six independent features, and 10
    test samples whose feature ``k`` (1-based) steps up by 6 standard deviations from sample 4."""
    rng = np.random.default_rng(seed)
    made = registry.make("pca_monitor", variance=0.75, alpha=0.05, statistic="q", cv=None)[1]
    monitor = fit_q_monitor(rng.standard_normal((60, 6)), made)
    test = rng.standard_normal((10, 6))
    test[4:, k - 1] += 6.0
    return monitor, test


@pytest.mark.parametrize("k", range(1, 7))
def test_a_step_on_one_feature_is_located_at_its_axis(k):
    monitor, test = monitor_and_features(k, seed=k)
    used = np.arange(6)
    assert detection.locate_by_contribution(test, used, monitor, onset=4, persistence=3) == k
    assert detection.locate_by_contribution(test, used, monitor, onset=None) == UNDECIDED


def test_the_axis_number_follows_the_features_the_monitor_used():
    rng = np.random.default_rng(7)
    made = registry.make("pca_monitor", variance=0.75, alpha=0.05, statistic="q", cv=None)[1]
    monitor = fit_q_monitor(rng.standard_normal((60, 5)), made)  # learned features of axes 1-3, 5, 6
    features = np.column_stack([rng.standard_normal((10, 3)), np.zeros(10), rng.standard_normal((10, 2))])
    features[5:, 4] += 8.0  # axis 5: the monitor's fourth feature
    assert detection.locate_by_contribution(features, np.array([0, 1, 2, 4, 5]), monitor, onset=5, persistence=2) == 5


def test_location_by_contribution_on_a_sweep_and_its_refusals(shared_sweep):
    two_seeds = shared_sweep("analysis-seeds", robots=["irb6700"], tasks=["pick_place"], axes=[0, 5], cycles=20,
                             seeds=[0, 1])
    table = benchmark.detection_table(two_seeds, progress=False, persistence=3, locate="contribution")
    assert table.attrs["locate"] == "contribution" and table.attrs["n_axes"] == 6
    plain = benchmark.detection_table(two_seeds, progress=False, persistence=3)  # the detection is the same
    pd.testing.assert_frame_equal(table.drop(columns=["located_axis", "located"]),
                                  plain.drop(columns=["located_axis", "located"]))
    detected = table[table["detected"]]
    assert len(detected) and (detected["located_axis"] == 5).all(), table[["run", "onset", "located_axis"]]
    with pytest.raises(ValueError, match="unknown location method 'largest'; expected one of: cross-correlation"):
        benchmark.detection_table(two_seeds, progress=False, locate="largest")
    from sklearn.covariance import EllipticEnvelope

    with pytest.raises(ValueError, match="--locate contribution .* use --locate cross-correlation"):
        benchmark.detection_table(two_seeds, progress=False, locate="contribution", detector=EllipticEnvelope())


def test_the_location_is_judged_against_naming_an_axis_at_random():
    rows = pd.DataFrame({"worn_axis": [1, 2, 3, 4, 5, 6] * 2, "detected": True, "trained_on_fault": False,
                         "located": [True] * 12})
    rows.attrs.update(n_axes=6, locate="contribution")
    text = location_verdict(rows)
    assert "12 of 12 detected runs located" in text and "16.7 %" in text and text.endswith(": above chance")
    assert "p = 4.6e-10" in text  # (1/6)^12, the binomial tail written out: 4.59e-10
    assert (1 / 6) ** 12 == pytest.approx(4.59e-10, rel=1e-3)
    rows["located"] = [True, True] + [False] * 10  # 2 of 12 = 16.7 %: chance itself
    assert location_verdict(rows).endswith(": not above chance")
    rows.attrs["locate"] = "cross-correlation"
    assert location_verdict(rows).startswith("location (cross-correlation): 2 of 12")
