"""The pruning/recall figure draws what it is given."""

import pytest

from skmotion.plotting import plot_pruning_recall


def test_plot_pruning_recall_draws_each_series():
    pytest.importorskip("matplotlib")
    import matplotlib

    matplotlib.use("Agg")
    rows = [
        {
            "dataset": d,
            "features": f,
            "n_levels": 7,
            "epsilon": e,
            "pruning": 0.9 - e / 10,
            "recall": min(1.0, e),
        }
        for d in ("a", "b")
        for f in ("first", "first_two")
        for e in (0.5, 1.0)
    ] + [
        {
            "dataset": "a",
            "features": "first",
            "n_levels": 5,
            "epsilon": 0.5,
            "pruning": 0.1,
            "recall": 0.1,
        }
    ]
    figure = plot_pruning_recall(rows)
    assert len(figure.axes) == 2
    lines = figure.axes[0].get_lines()
    assert len(lines) == 4  # pruning and recall for two feature kinds; 5 levels left out
    assert list(lines[0].get_ydata()) == [0.85, 0.8]
