import numpy as np
import pytest

from skmotion.decomposition import EigenMovementPCA
from skmotion.plotting import plot_eigenmovements
from tests.decomposition.test_eigenmovements import stroke_clips

matplotlib = pytest.importorskip("matplotlib")
matplotlib.use("Agg")


def test_each_panel_is_one_channel_of_one_eigenmovement():
    pca = EigenMovementPCA(5, n_samples=30).fit(stroke_clips(8))
    fig = plot_eigenmovements(pca, 3, channels=[2, 0])
    axes = np.array(fig.axes).reshape(3, 2)
    movements = pca.components_.reshape(5, 3, 30)
    for i in range(3):
        for k, c in enumerate([2, 0]):
            np.testing.assert_array_equal(axes[i, k].lines[0].get_ydata(), movements[i, c])
    assert axes[0, 0].get_title() == "channel 2"
    matplotlib.pyplot.close(fig)


def test_plot_errors():
    pca = EigenMovementPCA(2, n_samples=30).fit(stroke_clips(8))
    with pytest.raises(ValueError, match=r"n_components must be in \[1, 2\]"):
        plot_eigenmovements(pca, 4)
    with pytest.raises(ValueError, match="channel_names has 1 names for 3 channels"):
        plot_eigenmovements(pca, 2, channel_names=["a"])
