"""A detector baseline added in one file reaches `bench score`, `detect` and the leaderboard (issue
57, item 3).

tests/baseline_example.py registers ``zmean`` and nothing else: `faultgen bench score --baseline
zmean` scores it on the test-sized thesis track, `faultgen detect --baseline zmean` runs it on a
dataset as the same class given as a plug-in does, and benchmarks/bench_all.py lists it. Every
built-in name still makes the estimator the if-chain of faultgen/bench/baselines.py made before the
registry (type and parameters), and an unknown name's error lists the registered names.
"""

from __future__ import annotations

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
    assert baselines.names()[: len(BUILTIN) + 1] == (*BUILTIN[:7], "zmean", *BUILTIN[7:])
    assert "zmean" in baselines.DETECTORS and "zmean" not in baselines.ISOLATORS
    assert "zmean" in baselines.healthy_detectors() and "lr" not in baselines.healthy_detectors()
    expected = "unknown baseline 'nope'; expected one of: " + ", ".join(baselines.names())
    with pytest.raises(ValueError, match=re.escape(expected)):
        baselines.make("nope")
    with pytest.raises(ValueError, match="already registered"):
        baselines.register("zmean", "detector", "another")(lambda: None)
    with pytest.raises(ValueError, match="expected one of: detector, isolator"):
        baselines.register("x", "prognoser", "no such role")
    result = runner.invoke(app, ["bench", "baselines"])
    assert result.exit_code == 0 and "zmean: detector; z-score of the mean" in result.output


def _bench_all():
    spec = importlib.util.spec_from_file_location("bench_all", ROOT / "benchmarks/bench_all.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def thesis_small(tmp_path_factory):
    folder = tmp_path_factory.mktemp("registry") / "thesis"
    bench_plugins.make_small("thesis", folder)
    return folder


def test_bench_score_and_the_leaderboard_reach_the_example(thesis_small, tmp_path):
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
    assert result.exit_code == 2 and "expected one of: pca, lr, svm, rf, stacking, iforest, ecod, zmean," in result.output


@pytest.fixture(scope="module")
def small(shared_sweep):
    return shared_sweep("analysis-small", robots=["irb6700"], tasks=["pick_place"], axes=[0, 1, 5], cycles=40)


def test_detect_reaches_the_example_as_the_plug_in_of_the_same_class(small, tmp_path):
    tables = {}
    for name, option in (("baseline", ["--baseline", "zmean"]),
                         ("plugin", ["--detector", "baseline_example:ZScoreOfMean"])):
        result = runner.invoke(app, ["detect", str(small), "--no-progress", *option, "-o", str(tmp_path / name)])
        assert result.exit_code == 0, result.output
        tables[name] = pd.read_csv(tmp_path / f"{name}.csv")
    pd.testing.assert_frame_equal(tables["baseline"], tables["plugin"])
    assert len(tables["baseline"]) == 2 and np.isin(tables["baseline"]["detected"], [True, False]).all()


def test_detect_takes_the_pca_baseline_as_its_plug_in_and_refuses_what_learns_labels(small, tmp_path):
    outputs = {}
    for name, option in (("baseline", ["--baseline", "pca"]),
                         ("plugin", ["--detector", "faultgen.bench.baselines:PCADetector"])):
        result = runner.invoke(app, ["detect", str(small), "--no-progress", *option, "-o", str(tmp_path / name)])
        assert result.exit_code == 0, result.output
        outputs[name] = (tmp_path / f"{name}.csv").read_bytes()
    assert outputs["baseline"] == outputs["plugin"]
    for name, message in (("lr", "is a classifier"), ("trend", "is an isolator"), ("nope", "unknown baseline")):
        result = runner.invoke(app, ["detect", str(small), "--no-progress", "--baseline", name,
                                     "-o", str(tmp_path / name)])
        assert result.exit_code == 2 and message in result.output, result.output
        if name != "nope":
            assert "detect takes a detector that learns healthy samples: pca, iforest, ecod, zmean" in result.output
        assert not (tmp_path / f"{name}.csv").exists()
    result = runner.invoke(app, ["detect", str(small), "--baseline", "pca", "--detector", "baseline_example:ZScoreOfMean"])
    assert result.exit_code == 2 and "give one of --detector MODULE:CLASS or --baseline NAME" in result.output
