"""A baseline added in one file reaches `bench score`, `detect`, `bench-isolators`, `bench score
prognostics` and the leaderboard (issue 57, item 3).

tests/baseline_example.py registers ``zmean`` (a detector), ``rise`` (an isolator) and ``doubling``
(a prognoser) and nothing else: `faultgen bench score --baseline zmean` scores it on the test-sized
thesis track, `faultgen detect --baseline zmean` runs it on a dataset as the same class given as a
plug-in does, and benchmarks/bench_all.py lists it; `faultgen bench-isolators` runs ``rise`` beside
the built-in isolators, whose rows stay those of analysis.benchmark.default_isolators; `faultgen
bench score prognostics --prognoser doubling` scores ``doubling`` as the class itself is scored.
The monitor model ``pca_monitor`` (analysis.registry, the same registry) is what the monitor,
detect's default and training-source make, and classify makes its classifiers by the registry. Every built-in name still makes the
estimator the if-chain of faultgen/bench/baselines.py made before the registry (type and
parameters), the registry lists every role (the twin with the context
it runs on, refused by the commands that cannot run it), and an unknown name's error lists the
registered names.
"""

from __future__ import annotations

import dataclasses
import importlib.util
import json
import re
from pathlib import Path

import baseline_example
import bench_plugins
import numpy as np
import pandas as pd
import pytest
from sklearn.base import is_classifier
from typer.testing import CliRunner

from faultgen.bench import baselines, score
from faultgen.cli import app

ROOT = Path(__file__).resolve().parents[1]
runner = CliRunner()
BUILTIN = ("pca", "lr", "svm", "rf", "stacking", "iforest", "ecod",
           "transfer_entropy", "cross_correlation", "granger", "trend", "pca_contribution")
PROGNOSERS = ("linear", "exponential", "mean_life")


def _before(name: str):
    """What ``baselines.make(name)`` returned before the registry (main 752a608's if-chain)."""
    if name == "pca":
        from faultgen.bench.pca_detector import PCADetector

        return "detector", PCADetector()
    if name in ("lr", "svm", "rf", "stacking"):
        from analysis.classify import CLASSIFIERS

        if name == "stacking":
            return "detector", CLASSIFIERS[name](random_state=0, inner_cv="sample")
        return "detector", CLASSIFIERS[name](random_state=0)
    if name == "iforest":
        from pyod.models.iforest import IForest

        return "detector", IForest(random_state=0)
    if name == "ecod":
        from pyod.models.ecod import ECOD

        return "detector", ECOD()
    from analysis import isolation

    return "isolator", isolation.make(name)


def _params(estimator) -> dict:
    return {key: repr(value) for key, value in estimator.get_params(deep=True).items()}


@pytest.mark.parametrize("name", BUILTIN)
def test_every_builtin_name_makes_the_estimator_it_made_before(name):
    if name in ("iforest", "ecod") and importlib.util.find_spec("pyod") is None:
        with pytest.raises(ValueError, match=re.escape(f"baseline {name!r} needs pyod: pip install "
                                                       "'faultgen-robots[bench]' (or pyod)")):
            baselines.make(name)
        return
    role, made = baselines.make(name)
    old_role, old = _before(name)
    assert role == old_role and type(made) is type(old) and _params(made) == _params(old)
    assert baselines.make(name)[1] is not made  # a new estimator on every call
    assert baselines.REGISTRY[name].labels == is_classifier(made)  # the declared field says what the estimator is


def test_the_example_is_one_registered_entry_and_an_unknown_name_lists_them():
    entry = baselines.REGISTRY["zmean"]
    assert entry.factory is baseline_example.zmean and entry.role == "detector"
    assert baselines.names() == (*BUILTIN[:7], "twin", "zmean", *BUILTIN[7:], "rise", *PROGNOSERS, "doubling",
                                 "pca_monitor")
    assert "zmean" in baselines.DETECTORS and "zmean" not in baselines.ISOLATORS
    assert "zmean" in baselines.healthy_detectors() and "lr" not in baselines.healthy_detectors()
    expected = "unknown baseline 'nope'; expected one of: " + ", ".join(baselines.names())
    with pytest.raises(ValueError, match=re.escape(expected)):
        baselines.make("nope")
    with pytest.raises(ValueError, match="already registered"):
        baselines.register("zmean", "detector", "another")(lambda: None)
    with pytest.raises(ValueError, match="expected one of: detector, isolator, prognoser, monitor"):
        baselines.register("x", "nope", "no such role")
    result = runner.invoke(app, ["bench", "baselines"])
    assert result.exit_code == 0 and "zmean: detector; z-score of the mean" in result.output


def _bench_all():
    spec = importlib.util.spec_from_file_location("bench_all", ROOT / "benchmarks/bench_all.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def thesis_small(shared_bench):
    return shared_bench("thesis")


def test_bench_score_and_the_leaderboard_reach_the_example(thesis_small, tmp_path, monkeypatch):
    monkeypatch.setattr(score, "RESAMPLES", bench_plugins.FEW_RESAMPLES)  # the command's and the class's: equal
    out = tmp_path / "zmean"
    result = runner.invoke(app, ["bench", "score", "thesis", "--data", str(thesis_small), "--baseline", "zmean",
                                 "-o", str(out)])
    assert result.exit_code == 0, result.output
    written = json.loads(out.with_suffix(".json").read_text())
    assert written["method"] == "zmean" and written["role"] == "detector"
    direct = score.score(thesis_small, baseline_example.ZScoreOfMean(), "zmean", "detector")
    assert written["results"]["auroc"] == direct["results"]["auroc"]
    # the leaderboard: bench_all scores every registered name and keeps the third line of OUT.md
    assert "zmean" in _bench_all().methods()
    row = out.with_suffix(".md").read_text().splitlines()[2]
    assert row.startswith("| thesis v2 (small) | zmean | ")
    result = runner.invoke(app, ["bench", "score", "thesis", "--data", str(thesis_small), "--baseline", "nope"])
    assert result.exit_code == 2 and "expected one of: pca, lr, svm, rf, stacking, iforest, ecod, twin, zmean," in result.output


@pytest.fixture(scope="module")
def small(shared_sweep):
    return shared_sweep("analysis-small", robots=["irb6700"], tasks=["pick_place"], axes=[0, 1, 5], cycles=40)


def detect_twice(dataset, tmp_path, baseline: str, plugin: str) -> dict:
    """``faultgen detect`` of ``dataset`` with ``--baseline baseline`` and with ``--detector plugin``:
    ``{"baseline": its CSV, "plugin": its CSV}`` (paths in ``tmp_path``)."""
    for name, option in (("baseline", ["--baseline", baseline]), ("plugin", ["--detector", plugin])):
        result = runner.invoke(app, ["detect", str(dataset), "--no-progress", *option, "-o", str(tmp_path / name)])
        assert result.exit_code == 0, result.output
    return {name: tmp_path / f"{name}.csv" for name in ("baseline", "plugin")}


def test_detect_reaches_the_example_as_the_plug_in_of_the_same_class(small, tmp_path):
    tables = {name: pd.read_csv(path)
              for name, path in detect_twice(small, tmp_path, "zmean", "baseline_example:ZScoreOfMean").items()}
    pd.testing.assert_frame_equal(tables["baseline"], tables["plugin"])
    assert len(tables["baseline"]) == 2 and np.isin(tables["baseline"]["detected"], [True, False]).all()


def test_detect_takes_the_pca_baseline_as_its_plug_in_and_refuses_what_learns_labels(small, tmp_path):
    outputs = {name: path.read_bytes()
               for name, path in detect_twice(small, tmp_path, "pca", "faultgen.bench.baselines:PCADetector").items()}
    assert outputs["baseline"] == outputs["plugin"]
    for name, message in (("lr", "is a classifier"), ("trend", "is an isolator"), ("nope", "unknown baseline"),
                          ("linear", "is a prognoser"), ("twin", "runs on the test split as raw logs"),
                          ("pca_monitor", "is a monitor model")):
        result = runner.invoke(app, ["detect", str(small), "--no-progress", "--baseline", name,
                                     "-o", str(tmp_path / name)])
        assert result.exit_code == 2 and message in result.output, result.output
        if name != "nope":
            assert "detect takes a detector that learns healthy samples: pca, iforest, ecod, zmean" in result.output
        assert not (tmp_path / f"{name}.csv").exists()
    result = runner.invoke(app, ["detect", str(small), "--baseline", "pca", "--detector", "baseline_example:ZScoreOfMean"])
    assert result.exit_code == 2 and "give one of --detector MODULE:CLASS or --baseline NAME" in result.output


def test_the_registry_lists_every_role_and_the_twin_with_its_context(thesis_small):
    assert {baselines.REGISTRY[n].role for n in baselines.names()} == set(baselines.ROLES)
    assert baselines.PROGNOSERS == (*PROGNOSERS, "doubling") and "rise" in baselines.ISOLATORS
    listed = runner.invoke(app, ["bench", "baselines"])
    assert listed.exit_code == 0
    for name in baselines.names():
        assert f"\n{name}: {baselines.REGISTRY[name].role}" in "\n" + listed.output
    assert "twin: detector and isolator; " in listed.output and "benchmarks/twin_baseline.py" in listed.output
    # the prognosers the registry makes are the classes `--baseline` made before it (seed 0)
    from faultgen.bench.degradation import ExponentialDegradation, LinearDegradation
    from faultgen.bench.prognosers import MeanLife

    for name, cls in zip(PROGNOSERS, (LinearDegradation, ExponentialDegradation, MeanLife), strict=True):
        made = baselines.prognoser(name)
        assert type(made) is cls and vars(made) == vars(cls())
    # the twin runs on the monitor's outputs: the commands that take a track's files refuse it, named
    with pytest.raises(ValueError, match="baseline 'twin' runs on the test split as raw logs"):
        baselines.make("twin")
    assert "twin" not in baselines.scorable() and "twin" not in _bench_all().methods()
    assert "linear" not in _bench_all().methods()
    for name, message in (("twin", "baseline 'twin' runs on the test split"), ("linear", "baseline 'linear' is a prognoser")):
        result = runner.invoke(app, ["bench", "score", "thesis", "--data", str(thesis_small), "--baseline", name])
        assert result.exit_code == 2 and message in result.output, result.output
        assert "bench score on this track takes: pca, lr," in result.output


def test_bench_isolators_runs_a_registered_isolator_beside_the_built_in_ones(small, tmp_path):
    from analysis import benchmark

    result = runner.invoke(app, ["bench-isolators", str(small), "--no-progress", "-o", str(tmp_path / "iso")])
    assert result.exit_code == 0, result.output
    table = pd.read_csv(tmp_path / "iso.csv")
    assert list(dict.fromkeys(table["isolator"])) == [*benchmark.default_isolators(), "rise"]
    assert "accuracy rise (%)" in (tmp_path / "iso.md").read_text()
    # the built-in isolators' rows: what analysis.benchmark gives with its own isolators
    direct = benchmark.isolation_table(small, benchmark.default_isolators(), [1.0, 5.0, 10.0, 15.0], progress=False)
    benchmark.write_outputs(benchmark.isolation_csv(direct), tmp_path / "direct")
    expected = pd.read_csv(tmp_path / "direct.csv")
    # (needed: NaN for the registered isolator, whose need is unknown, makes the column float)
    pd.testing.assert_frame_equal(table[table["isolator"] != "rise"].reset_index(drop=True), expected, check_dtype=False)


@pytest.fixture(scope="module")
def prognostics_small(shared_bench):
    return shared_bench("prognostics")


def test_bench_score_prognostics_takes_a_registered_prognoser_by_name(prognostics_small, tmp_path):
    from faultgen.bench import prognostics

    out = tmp_path / "doubling"
    result = runner.invoke(app, ["bench", "score", "prognostics", "--data", str(prognostics_small),
                                 "--prognoser", "doubling", "-o", str(out)])
    assert result.exit_code == 0, result.output
    assert "| prognostics v2 (small) | doubling |" in result.output
    written = json.loads(out.with_suffix(".json").read_text())
    direct = prognostics.score(prognostics_small, baseline_example.Doubling(), "doubling")
    assert written["method"] == "doubling"
    assert json.dumps(written["results"], sort_keys=True) == json.dumps(direct["results"], sort_keys=True)
    # a built-in prognoser by --prognoser NAME is the one --baseline NAME scores
    rows = {}
    for option in ("--prognoser", "--baseline"):
        result = runner.invoke(app, ["bench", "score", "prognostics", "--data", str(prognostics_small), option,
                                     "mean_life", "-o", str(tmp_path / option.strip("-"))])
        assert result.exit_code == 0, result.output
        rows[option] = json.dumps(json.loads((tmp_path / f"{option.strip('-')}.json").read_text())["results"])
    assert rows["--prognoser"] == rows["--baseline"]
    help_text = runner.invoke(app, ["bench", "score", "--help"], terminal_width=400).output
    assert "linear, exponential, mean_life, doubling (prognosers)" in " ".join(help_text.split())
    result = runner.invoke(app, ["bench", "score", "prognostics", "--data", str(prognostics_small), "--prognoser", "pca"])
    assert result.exit_code == 2 and "expected one of: linear, exponential, mean_life, doubling" in result.output


def test_the_monitor_model_is_made_through_the_one_registry_by_every_layer_that_uses_it(small, tmp_path,
                                                                                         monkeypatch):
    """``pca_monitor`` (analysis.registry, whose REGISTRY faultgen.bench.baselines re-exports) is the
    PCAMonitor the monitor, detect's default Q monitor and training-source fit: each asks the
    registry for it (a spy on its factory sees every call); the pca baseline fits the same one;
    bench score, detect --baseline and bench_all leave it out (a monitor model is not a detector)."""
    from analysis import registry, training_source
    from analysis.monitoring import PCAMonitor
    from faultgen.bench.pca_detector import PCADetector
    from faultgen.monitor import scoring, steps

    assert baselines.REGISTRY is registry.REGISTRY and baselines.make is registry.make
    role, made = baselines.make("pca_monitor", variance=0.8, alpha=0.01, cv=5)
    assert role == "monitor" and type(made) is PCAMonitor
    assert made.get_params() == PCAMonitor(variance=0.8, alpha=0.01, cv=5).get_params()
    assert "pca_monitor" not in baselines.scorable() and "pca_monitor" not in _bench_all().methods()
    calls = []
    entry = registry.REGISTRY["pca_monitor"]
    spy = dataclasses.replace(entry, factory=lambda **params: calls.append(params) or entry.factory(**params))
    monkeypatch.setitem(registry.REGISTRY, "pca_monitor", spy)
    rng = np.random.default_rng(0)
    # the pca baseline is itself an entry: it fits the same PCAMonitor (the registry imports it, so it
    # does not ask the registry back)
    fitted = PCADetector().fit(rng.normal(size=(60, 5))).monitor_
    assert fitted.get_params() == entry.factory(variance=0.75, alpha=0.05).get_params() and not calls
    unit = steps.start("u", scoring.Settings(protocol="own", train=10), n_axes=1)
    for i in range(10):
        steps.add(unit, f"{i:02d}", rng.normal() * np.ones(4) + 0.1 * rng.normal(size=4), 20.0 + i % 3, 100.0)
    assert calls[-1] == {"variance": unit.stages.settings.variance, "alpha": unit.stages.settings.alpha, "cv": 5}
    assert isinstance(unit.stages.baseline.pca, PCAMonitor)
    training_source._fit(rng.normal(size=(40, 4)), 0.85, 0.05, None)
    assert calls[-1] == {"variance": 0.85, "alpha": 0.05, "statistic": "q", "cv": None}
    n = len(calls)
    result = runner.invoke(app, ["detect", str(small), "--no-progress", "-o", str(tmp_path / "det")])
    assert result.exit_code == 0, result.output
    assert len(calls) > n and all(c["statistic"] == "q" for c in calls[n:])  # detect's default Q monitor


def test_classify_makes_its_classifiers_through_the_registry(monkeypatch):
    """`faultgen classify` (thesis Table 5.2, which `reproduce` runs) builds each classifier by
    ``analysis.registry.make`` with its seed, stacking with inner folds by run: the estimator the
    classifier's own factory makes (``CLASSIFIERS[name](random_state=...)``), whereas `bench score
    --baseline stacking` keeps its folds by sample."""
    from analysis import registry
    from analysis.classify import CLASSIFIERS
    from analysis.classify.preprocessing import make_pipeline

    asked = []
    make = registry.make
    monkeypatch.setattr(registry, "make", lambda name, **params: asked.append((name, params)) or make(name, **params))
    for name in CLASSIFIERS:
        made = make_pipeline(name, "control", random_state=7)
        direct = CLASSIFIERS[name](random_state=7)
        tail = [est for _, est in made.steps[-len(direct.steps):]] if hasattr(direct, "steps") else [made.steps[-1][1]]
        expected = [est for _, est in direct.steps] if hasattr(direct, "steps") else [direct]
        assert [_params(a) for a in tail] == [_params(b) for b in expected]
    assert asked == [("lr", {"random_state": 7}), ("svm", {"random_state": 7}), ("rf", {"random_state": 7}),
                     ("stacking", {"random_state": 7, "inner_cv": "run"})]
    assert baselines.make("stacking")[1].get_params()["stacking__cv"].__class__.__name__ == "StratifiedKFold"
