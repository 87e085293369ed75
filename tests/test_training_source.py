"""The training-source study of thesis ch. 4: signals and descriptors by hand, the ANOVA against
hand sums of squares, Tukey's HSD against SciPy's, and `faultgen training-source` on a small fleet."""

import errno
import shutil

import numpy as np
import pandas as pd
import pytest
from scipy import stats
from typer.testing import CliRunner

from analysis import training_source as ts
from faultgen.cli import app
from faultgen.data import dataset


def test_descriptors_by_hand():
    q = np.array([1.0, 2.0, 5.0, 1.0, 6.0])
    d = ts.descriptors(q, limit=4.0)
    assert d["nsat"] == 2
    assert d["lead_time_days"] == 3  # first above the limit on test day 3 of 5: days 3, 4, 5 left
    assert d["cov_q"] == pytest.approx(np.std(q, ddof=1) / 3.0)
    assert ts.descriptors(q, limit=10.0)["lead_time_days"] == 0
    assert not d["saturated"] and d["test_days"] == 5 and ts.descriptors(q, limit=0.5)["saturated"]


def test_signals_by_hand():
    rng = np.random.default_rng(0)
    n, window = 12, ts.Window(training_days=4, test_days=3, gap_days=2)  # the last 9 days
    arrays = {name: rng.uniform(1.0, 2.0, size=(n, 6)) for name in ts.SCALARS}
    for name in ts.HISTOGRAMS:  # no empty bin, so the smoothing of kl_divergence changes ~1e-5
        h = rng.uniform(0.5, 1.5, size=(n, 6, 12))
        arrays[name] = h / h.sum(axis=-1, keepdims=True)
    made = ts.signals(arrays, window)
    raw, names = made["raw"]
    difference, _ = made["difference"]
    assert raw.shape == (8, 30) and made["combined"][0].shape == (8, 60)
    x = arrays["rms_torque"][-9:]
    j = names.index("rms_torque_1")
    np.testing.assert_array_equal(raw[:, j], x[1:, 0])
    np.testing.assert_array_equal(difference[:, j], np.abs(np.diff(x[:, 0])))
    h = arrays["torque_hist"][-9:, 2]  # axis 3
    j = names.index("kl_torque_hist_3")
    expected_raw = [stats.entropy(h[d], h[0], base=2) for d in range(1, 9)]
    expected_difference = [stats.entropy(h[d], h[d - 1], base=2) for d in range(1, 9)]
    np.testing.assert_allclose(raw[:, j], expected_raw, rtol=1e-3)
    np.testing.assert_allclose(difference[:, j], expected_difference, rtol=1e-3)
    with pytest.raises(ValueError, match="12 records, the study needs 55"):
        ts.signals(arrays, ts.Window(40, 10, 5))
    with pytest.raises(ValueError, match="training_days = 2"):
        ts.Window(training_days=2)


def test_anova_equals_hand_sums_of_squares_on_a_balanced_design():
    rng = np.random.default_rng(1)
    cells = [(s, k, c) for s in ts.SOURCES for k in ts.SIGNAL_TYPES for c in ts.CONDITIONS]
    rows = []
    for i, (s, k, c) in enumerate(cells):
        for _ in range(5):
            shift = 2.0 * (c == "failure") + 0.5 * ts.SIGNAL_TYPES.index(k) + 0.1 * i
            rows.append(dict(source=s, signal=k, condition=c, cov_q=rng.normal(shift), nsat=rng.normal(),
                             lead_time_days=rng.normal()))
    cases = pd.DataFrame(rows)
    table = ts.anova(cases).set_index(["descriptor", "term"])
    y = cases["cov_q"]
    grand = y.mean()
    for factor in ("source", "signal", "condition"):  # balanced: SS = sum over levels n_level (mean - grand)^2
        means = y.groupby(cases[factor]).agg(["mean", "size"])
        ss = float((means["size"] * (means["mean"] - grand) ** 2).sum())
        assert table.loc[("cov_q", factor), "sum_sq"] == pytest.approx(ss, rel=1e-9)
    residual = float(((y - y.groupby([cases.source, cases.signal, cases.condition]).transform("mean")) ** 2).sum())
    assert table.loc[("cov_q", "Error"), "sum_sq"] == pytest.approx(residual, rel=1e-9)
    assert table.loc[("cov_q", "Error"), "df"] == 60 - 12
    f = table.loc[("cov_q", "condition"), "F"]
    assert f == pytest.approx(table.loc[("cov_q", "condition"), "mean_sq"] / (residual / 48))
    assert table.loc[("cov_q", "condition"), "p"] == pytest.approx(stats.f.sf(f, 1, 48))
    assert set(table.loc["nsat"].index) == {"source", "signal", "condition", "source*signal", "source*condition",
                                             "signal*condition", "source*signal*condition", "Error"}


def test_anova_refuses_a_design_with_an_empty_cell():
    rows = [dict(source=s, signal=k, condition=c, cov_q=float(i), nsat=i % 3, lead_time_days=i % 2)
            for i, (s, k, c) in enumerate((s, k, c) for s in ts.SOURCES for k in ts.SIGNAL_TYPES
                                          for c in ts.CONDITIONS for _ in range(3))
            if not (s == "OTM" and c == "failure")]
    with pytest.raises(ValueError, match="none in OTM/raw/failure, OTM/difference/failure, OTM/combined/failure"):
        ts.anova(pd.DataFrame(rows))


def test_tukey_agrees_with_scipy():
    rng = np.random.default_rng(2)
    rows = [dict(source=s, signal=k, condition=c, cov_q=rng.normal(1.0 * (c == "failure") * (k == "raw")),
                 nsat=rng.normal(), lead_time_days=rng.normal())
            for s in ts.SOURCES for k in ts.SIGNAL_TYPES for c in ts.CONDITIONS for _ in range(6)]
    cases = pd.DataFrame(rows)
    pairs = ts.failure_vs_normal(ts.tukey(cases))
    cell = cases["source"] + "/" + cases["signal"] + "/" + cases["condition"]
    names = sorted(set(cell))
    reference = stats.tukey_hsd(*[cases.loc[cell == n, "cov_q"].to_numpy() for n in names])
    for row in pairs[pairs["descriptor"] == "cov_q"].itertuples():
        i, j = names.index(f"{row.source}/{row.signal}/failure"), names.index(f"{row.source}/{row.signal}/normal")
        assert row.p_adj == pytest.approx(reference.pvalue[i, j], abs=2e-3)
        assert row.failure_minus_normal == pytest.approx(reference.statistic[i, j])
    assert len(pairs) == 3 * 6


def test_training_source_command_on_a_small_fleet(tmp_path, shared_fleet_command):
    runner = CliRunner()
    fleet = tmp_path / "fleet.h5"
    # the docs' small fleet (`faultgen fleet --robots 6 --days 16 --cycles-per-day 1`, made once a session
    # for this test and tests/test_help_examples.py's fleet.h5), seed 0: one IRB and two PUMA robots fail,
    # two IRB robots and one PUMA stay normal, so every cell has cases
    shutil.copy(shared_fleet_command("--robots", "6", "--days", "16", "--cycles-per-day", "1")[0], fleet)
    stem = tmp_path / "ch4"
    refused = runner.invoke(app, ["training-source", str(fleet), "-o", str(stem), "--no-progress"])
    assert refused.exit_code == 2
    assert "has 16 records, the study needs 60" in refused.output and "faultgen fleet" in refused.output
    assert not list(tmp_path.glob("ch4*"))
    args = ["training-source", str(fleet), "-o", str(stem), "--training-days", "6", "--test-days", "3", "--gap-days",
            "1", "--no-progress"]

    def disk_full(cases, out, marked=None):  # the last of the five writes fails as on a full disk
        raise OSError(errno.ENOSPC, "No space left on device")

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(ts, "figure", disk_full)
        failed = runner.invoke(app, args)
    assert failed.exit_code == 1 and "No space left on device" in failed.output, failed.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fleet.h5"]  # none of the outputs (issue 50 item 6)
    result = runner.invoke(app, args)
    assert result.exit_code == 0, result.output
    for suffix in ("-cases.csv", "-anova.csv", "-tukey.csv", ".md", ".png"):
        assert stem.with_name("ch4" + suffix).stat().st_size > 0
    cases = pd.read_csv(stem.with_name("ch4-cases.csv"))
    labels = dataset.labels(fleet)
    failing = {row["run"]: len(row["worn_axes"]) > 0 for row in labels}
    model = {row["run"]: row["robot"] for row in labels}
    expected = {("OTO", "failure"): 3, ("OTO", "normal"): 3, ("OTM", "failure"): 0, ("OTM", "normal"): 0}
    for reference in (r for r in failing if not failing[r]):  # every normal robot models the others of its model
        for robot in (r for r in failing if r != reference and model[r] == model[reference]):
            expected[("OTM", "failure" if failing[robot] else "normal")] += 1
    for signal in ts.SIGNAL_TYPES:
        counts = cases[cases["signal"] == signal].groupby(["source", "condition"]).size().to_dict()
        assert counts == expected
    assert expected[("OTM", "failure")] == 4 and expected[("OTM", "normal")] == 2
    assert cases["nsat"].between(0, 3).all() and cases["lead_time_days"].between(0, 3).all()
    oto = cases[cases["source"] == "OTO"]
    assert (oto["robot"] == oto["reference"]).all()
    assert "Tukey HSD" in result.output and "Three-way ANOVA" in result.output
    # issue 40: a normal robot's days above the limit are reported as false alarms, a saturated limit flagged
    assert "Normal robots never fail: their days above the limit are false alarms" in result.output
    table = ts.normal_false_alarms(cases)
    normal = cases[cases["condition"] == "normal"]
    for (source, signal), row in table.iterrows():
        mine = normal[(normal["source"] == source) & (normal["signal"] == signal)]
        assert row["false_alarm_pct"] == pytest.approx((100 * mine["nsat"] / 3).mean(), abs=0.05)
        assert row["saturated"] == (mine["nsat"] == 3).sum()
    assert ("the limit is saturated in" in result.output) == bool((normal["nsat"] == 3).any())
