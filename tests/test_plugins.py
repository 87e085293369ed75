"""Issue 50 item 3: a plug-in (``--detector``/``--isolator module:Class``) is executed code held to
its contract: one that fails to import, to build, to fit, or answers outside the contract is
refused with one line naming it, exit 2, nothing written; ``sys.path`` is left as it was."""

import sys

import numpy as np
import pytest
from typer.testing import CliRunner

from analysis import plugins
from faultgen.cli import app

runner = CliRunner()

BAD = '''
import numpy as np
from sklearn.base import BaseEstimator


class Isolator9(BaseEstimator):
    def fit(self, X, y=None):
        self.source_axis_ = 9
        return self


class IsolatorText(BaseEstimator):
    def fit(self, X, y=None):
        self.source_axis_ = "2"
        return self


class IsolatorCrash(BaseEstimator):
    def fit(self, X, y=None):
        return {}[X.shape]


class BrokenInit(BaseEstimator):
    def __init__(self):
        raise RuntimeError("no licence server")


class ShortAlarms(BaseEstimator):
    def fit(self, X, y=None):
        return self

    def predict(self, X):
        return np.zeros(len(X) - 1, dtype=bool)


class NanAlarms(BaseEstimator):
    def fit(self, X, y=None):
        return self

    def predict(self, X):
        return np.full(len(X), np.nan)


class FitCrash(BaseEstimator):
    def fit(self, X, y=None):
        raise ValueError("singular matrix")

    def predict(self, X):
        return np.zeros(len(X), dtype=bool)
'''


@pytest.fixture(scope="module")
def small(shared_sweep):
    return shared_sweep("analysis-small", robots=["irb6700"], tasks=["pick_place"], axes=[0, 1, 5], cycles=40)


@pytest.fixture
def folder(tmp_path, monkeypatch):
    (tmp_path / "bad_plugins.py").write_text(BAD)
    (tmp_path / "raises_on_import.py").write_text("raise RuntimeError('import-time side effect')\n")
    (tmp_path / "syntax_error.py").write_text("def f(:\n")
    monkeypatch.chdir(tmp_path)
    yield tmp_path
    for name in ("bad_plugins", "raises_on_import", "syntax_error"):
        sys.modules.pop(name, None)


def _refused(result, spec: str, message: str, folder) -> None:
    assert result.exit_code == 2, result.output
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"error: plug-in {spec!r}"), result.output
    assert message in lines[0], result.output
    assert not list(folder.glob("out*")), list(folder.iterdir())


@pytest.mark.parametrize(("spec", "message"), [
    ("raises_on_import:X", "importing 'raises_on_import' failed: RuntimeError: import-time side effect"),
    ("syntax_error:X", "importing 'syntax_error' failed: SyntaxError"),
    ("bad_plugins:BrokenInit", "BrokenInit() failed: RuntimeError: no licence server"),
    ("bad_plugins:Isolator9", "source_axis_ = 9; the isolator contract is a whole number 1..6"),
    ("bad_plugins:IsolatorText", "source_axis_ = '2'"),
    ("bad_plugins:IsolatorCrash", "fit(X) of X (200, 6) failed: KeyError"),
])
def test_a_failing_or_lying_isolator_is_refused_in_one_line(small, folder, spec, message):
    result = runner.invoke(app, ["bench-isolators", str(small), "--isolator", spec, "--bins", "5", "--levels", "5",
                                 "--no-progress", "-o", str(folder / "out")])
    _refused(result, spec, message, folder)


@pytest.mark.parametrize(("spec", "message"), [
    ("bad_plugins:ShortAlarms", "predict(X) gave shape (39,), dtype bool for X (40,"),
    ("bad_plugins:NanAlarms", "with NaN or inf"),
    ("bad_plugins:FitCrash", "fit(X) of X"),
])
def test_a_detector_breaking_its_contract_is_refused_in_one_line(small, folder, spec, message):
    result = runner.invoke(app, ["detect", str(small), "--detector", spec, "--protocol", "same-run",
                                 "--no-progress", "-o", str(folder / "out")])
    _refused(result, spec, message, folder)


def test_loading_a_plug_in_leaves_sys_path_as_it_was(folder):
    before = list(sys.path)
    plugin = plugins.load("bad_plugins:Isolator9", "isolator")
    assert sys.path == before  # the current folder was searched for this import only
    assert plugin.spec == "bad_plugins:Isolator9"


def test_a_detectors_own_control_charts_are_passed_through(small):
    # issue 50: a plug-in detector's Q/T2 charts were hidden by the guard. faultgen's own PCA
    # monitor named as a plug-in now gives the charts the built-in monitor draws, to the bit
    from analysis import benchmark

    plugin = plugins.load("analysis.monitoring:PCAMonitor", "detector")
    options = dict(protocol="same-run", progress=False, return_charts=True, variance=0.85, limit_folds=None)
    _, charts = benchmark.detection_table(small, detector=plugin, **options)
    _, builtin = benchmark.detection_table(small, **options)
    worn = [key for key in charts if not key.startswith("_")]
    assert worn and worn == [key for key in builtin if not key.startswith("_")]
    for key in worn:
        for name in ("t2", "q", "t2_limit", "q_limit"):  # (alarms: the built-in one judges Q alone)
            np.testing.assert_array_equal(charts[key][name], builtin[key][name])


def test_a_detector_with_lying_charts_is_refused(folder):
    (folder / "chart_plugins.py").write_text(
        "import numpy as np\nfrom analysis.monitoring import PCAMonitor\n\n"
        "class NanCharts(PCAMonitor):\n"
        "    def score_samples(self, X):\n"
        "        t2, q = super().score_samples(X)\n"
        "        return t2, q * np.nan\n\n"
        "class AlarmsOnly(PCAMonitor):\n"
        "    def score_samples(self, X):\n"
        "        raise AssertionError('not called: this detector has no limits')\n"
        "    def fit(self, X, y=None):\n"
        "        super().fit(X)\n"
        "        del self.t2_limit_\n"
        "        return self\n"
        "    def predict(self, X):\n"
        "        return np.zeros(len(X), dtype=bool)\n\n"
        "class BadLimit(PCAMonitor):\n"
        "    def fit(self, X, y=None):\n"
        "        super().fit(X)\n"
        "        self.q_limit_ = -1.0\n"
        "        return self\n")
    X = np.random.default_rng(0).normal(size=(60, 6))
    with pytest.raises(plugins.PluginError, match="score_samples\\(X\\) gave q of shape \\(60,\\), dtype float64, with NaN"):
        plugins.load("chart_plugins:NanCharts", "detector").fit(X).score_samples(X)
    with pytest.raises(plugins.PluginError, match="q_limit_ = -1.0; a control limit is a finite number > 0"):
        plugins.load("chart_plugins:BadLimit", "detector").fit(X)
    alarms_only = plugins.load("chart_plugins:AlarmsOnly", "detector").fit(X)
    assert not hasattr(alarms_only, "q_limit_")  # drawn as alarms, as before
    with pytest.raises(AttributeError, match="has no control charts"):
        alarms_only.score_samples(X)
    sys.modules.pop("chart_plugins", None)
