"""The motion tree's figures draw what the tree and its graphs hold."""

import numpy as np
import pytest

from skmotion.datasets import make_motions
from skmotion.tree import MotionTreeHMM

matplotlib = pytest.importorskip("matplotlib")
matplotlib.use("Agg")
plotting = pytest.importorskip("skmotion.plotting")


@pytest.fixture(scope="module")
def model():
    data = make_motions(n_clips_per_class=3, classes=["walk", "jump", "squat"], random_state=0)
    return MotionTreeHMM(max_depth=4, split="median").fit(
        [c[:, 6:] for c in data.clips], data.target
    )


def test_nodes_sit_at_their_projected_means(model):
    tree = model.tree_
    ax = plotting.plot_motion_tree_layer(tree, model.global_graph_, layer=3, axes=(0, 2))
    expected = (tree.means(3) - tree.mean[0]) @ tree.principal_axes[[0, 2]].T
    np.testing.assert_allclose(ax.collections[0].get_offsets(), expected)


def test_edges_are_the_likely_transitions(model):
    graphs, layer = model.graphs_, 4
    ax = plotting.plot_motion_tree_layer(
        model.tree_, graphs, layer=layer, graph=1, min_probability=0.1
    )
    P = graphs.matrix(layer, 1)
    seen = graphs.counts(layer, 1).toarray() > 0
    expected = int(((P >= 0.1) & seen & ~np.eye(len(P), dtype=bool)).sum())
    assert len(ax.get_lines()) == expected > 0


def test_layers_and_profiles(model):
    assert (
        len(plotting.plot_motion_tree_layers(model.tree_, layers=[1, 2]).axes) == 4
    )  # + colour bars
    profile = np.array([[0.2, 0.5, 0.3], [0.1, 0.1, 0.8]])
    ax = plotting.plot_motion_tree_profile(profile, model.classes_, step=4, frame_rate=2.0)
    for column, line in enumerate(ax.get_lines()):
        np.testing.assert_allclose(line.get_xdata(), [0.0, 2.0])
        np.testing.assert_allclose(line.get_ydata(), profile[:, column])


def test_layer_figure_explains_sizes_colours_and_lines(model):
    tree = model.tree_
    ax = plotting.plot_motion_tree_layer(tree, model.global_graph_, layer=3)
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert labels[0].startswith("node, small") and labels[-1] == "transition, p >= 0.05"
    bar = ax.figure.axes[1]
    assert bar.get_ylabel().startswith("node spread (largest std)")
    # the colour scale spans the nodes' spreads
    spreads = ax.collections[0].get_array()
    low, high = ax.collections[0].get_clim()
    assert low == pytest.approx(spreads.min()) and high == pytest.approx(spreads.max())


def _training_frames():
    data = make_motions(n_clips_per_class=3, classes=["walk", "jump", "squat"], random_state=0)
    clips = [c[:, 6:] for c in data.clips]
    labels = np.repeat(data.target_names[data.target], [len(c) for c in clips])
    return clips, labels


def test_nodes_take_the_colour_of_most_of_their_frames(model):
    clips, labels = _training_frames()
    frames = (np.vstack(clips) - model.center_) / model.scale_
    ax = plotting.plot_motion_tree_layer(model.tree_, layer=3, frames=frames, labels=labels)
    legend = [t.get_text() for t in ax.get_legend().get_texts()]
    assert legend[2:5] == ["jump", "squat", "walk"]
    palette = matplotlib.colormaps["tab10"]
    nodes = model.tree_.apply(frames, 3)
    colours = ax.collections[0].get_facecolors()
    for node in range(int(model.n_nodes_[3])):  # the majority label, counted by hand
        mine = labels[nodes == node]
        if len(mine):
            names, counts = np.unique(mine, return_counts=True)
            k = ["jump", "squat", "walk"].index(names[counts.argmax()])
            np.testing.assert_allclose(colours[node][:3], palette(k)[:3])


def test_an_outlying_node_does_not_squash_the_others():
    clips, _ = _training_frames()
    far = clips[0].copy()
    far[:10] += 1e4  # ten frames far from everything: a node of their own
    model = MotionTreeHMM(max_depth=5, min_samples_leaf=2).fit([far, *clips[1:]], np.arange(9) // 3)
    tree = model.tree_
    xy = (tree.means(-1) - tree.mean[0]) @ tree.principal_axes[[0, 1]].T
    ax = plotting.plot_motion_tree_layer(tree, layer=-1)
    low, high = ax.get_xlim()
    inside = (xy[:, 0] >= low) & (xy[:, 0] <= high)
    assert (~inside).sum() >= 1 and "off the view" in ax.get_title()
    # the others spread over the view rather than crowding one end of it
    assert np.ptp(xy[inside, 0]) > 0.1 * (high - low)  # all of them: < 1e-3
