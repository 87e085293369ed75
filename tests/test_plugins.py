"""Issue 50 item 3: a plug-in (``--detector``/``--isolator module:Class``) is executed code held to
its contract: one that fails to import, to build, to fit, or answers outside the contract is
refused with one line naming it, exit 2, nothing written; ``sys.path`` is left as it was."""

import sys

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
