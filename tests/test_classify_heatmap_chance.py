"""The classification heat map colours each cell by its AUC against its own row's chance level, and
greys out the cells judged not above chance (issue 88, item 6: at-chance cells were red, the map
being white at the mean chance level 0.89)."""

import matplotlib.axes
import numpy as np
import pandas as pd

from analysis import benchmark
from analysis.benchmark.figures import heat_values


def _judged():
    """Row "+diff": chance 0.89, AUC 0.90 (not above it); row "control": chance 0.5, AUC 0.95 (above)."""
    columns = pd.MultiIndex.from_product([["lr"], ["mean", "std"]], names=["classifier", "statistic"])
    table = pd.DataFrame([[0.95, 0.02], [0.90, 0.05]], columns=columns,
                         index=pd.Index(["control", "+diff"], name="preprocessing"))
    rng = np.random.default_rng(0)
    return benchmark.with_verdict(table, {"lr control": 0.5 + 0.02 * rng.normal(size=19),
                                          "lr +diff": 0.89 + 0.02 * rng.normal(size=19)})


def _drawn_colours(monkeypatch, table, tmp_path):
    images = []
    imshow = matplotlib.axes.Axes.imshow

    def keep(self, *args, **kwargs):
        images.append(imshow(self, *args, **kwargs))
        return images[-1]

    monkeypatch.setattr(matplotlib.axes.Axes, "imshow", keep)
    benchmark.classification_heatmap(table, tmp_path / "h.png")
    (image,) = images
    return image.to_rgba(image.get_array())  # (rows, classifiers, 4)


def test_an_at_chance_cell_is_grey_and_an_above_chance_cell_red(monkeypatch, tmp_path):
    judged = _judged()
    assert list(judged[("lr", "above")]) == [True, False]
    colours = _drawn_colours(monkeypatch, judged, tmp_path)
    control, diff = colours[0, 0], colours[1, 0]
    assert control[0] > control[2] + 0.2  # red: above its chance
    np.testing.assert_allclose(diff[:3], [0.827, 0.827, 0.827], atol=0.01)  # lightgrey: not above chance


def test_the_colour_is_the_auc_minus_the_rows_chance():
    judged = _judged()
    delta, grey, what = heat_values(judged)
    null = judged[("lr", "null")].to_numpy()
    np.testing.assert_allclose(delta[:, 0], [0.95 - null[0], 0.90 - null[1]])
    assert grey.tolist() == [[False], [True]] and what == "the row's measured chance level"
    unmeasured = judged.drop(columns=[("lr", "null"), ("lr", "p"), ("lr", "above")])
    delta, grey, what = heat_values(unmeasured)
    np.testing.assert_allclose(delta[:, 0], [0.45, 0.40])
    assert not grey.any()
    assert what == "0.5, chance not measured"
