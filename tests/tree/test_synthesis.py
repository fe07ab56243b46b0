"""MotionTreeHMM.sample: node chains with the graph's statistics, frames its model recognises."""

import numpy as np
import pytest
from scipy.stats import chisquare

from skmotion.datasets import make_motions, make_walks
from skmotion.io import as_motions, read_bvh, write_bvh
from skmotion.preprocessing import VirtualMarkerTransform
from skmotion.tree import MotionTreeHMM
from skmotion.tree._synthesis import sample_nodes

CLASSES = ["walk", "jog", "jump", "kick", "squat"]


@pytest.fixture(scope="module")
def model():
    data = make_motions(n_clips_per_class=6, classes=CLASSES, random_state=0)
    X = [c[:, 6:] for c in data.clips]
    return MotionTreeHMM(covariance_type="full").fit(X, data.target_names[data.target])


@pytest.mark.parametrize("smoothness", [0.0, 2.0])
def test_sampled_clips_are_recognised_as_their_class(model, smoothness):
    for label in model.classes_:
        clips = [
            model.sample(90, y=label, random_state=seed, smoothness=smoothness).frames
            for seed in range(8)
        ]
        # chance is 1 / 5
        assert (model.predict(clips) == label).mean() >= 0.75


def test_node_chains_have_the_graph_transition_probabilities(model):
    graphs, layer = model.graphs_, 3
    rng = np.random.default_rng(0)
    for graph in range(graphs.n_graphs):
        nodes = sample_nodes(graphs, layer, graph, 40_000, rng)
        k = graphs.n_nodes(layer)
        observed = np.zeros((k, k))
        np.add.at(observed, (nodes[:-1], nodes[1:]), 1)
        expected = graphs.matrix(layer, graph)
        for m in np.flatnonzero(observed.sum(axis=1) >= 500):
            exp = expected[m] * observed[m].sum()
            # pool the cells expected below 5 (the unseen transitions' smoothing mass)
            small = exp < 5
            obs_cells = np.r_[observed[m][~small], observed[m][small].sum()]
            exp_cells = np.r_[exp[~small], exp[small].sum()]
            if exp_cells[-1] == 0:
                obs_cells, exp_cells = obs_cells[:-1], exp_cells[:-1]
            assert chisquare(obs_cells, exp_cells).pvalue > 1e-4


def test_smoothed_frames_keep_the_node_covariance():
    rng = np.random.default_rng(1)
    X = [rng.normal([0.0, 5.0], [1.0, 3.0], size=(200, 2)) for _ in range(3)]
    root_only = MotionTreeHMM(max_depth=0, standardize=False).fit(X, [0, 0, 0])
    frames = root_only.sample(50_000, random_state=0, smoothness=3.0).frames
    var = root_only.tree_.covariance[0]
    np.testing.assert_allclose(frames.var(axis=0), var, rtol=0.06)
    np.testing.assert_allclose(frames.mean(axis=0), root_only.tree_.mean[0], atol=0.1)
    # and consecutive frames are close: the lag-1 correlation of a 3-frame kernel is high
    assert np.corrcoef(frames[:-1, 0], frames[1:, 0])[0, 1] > 0.9


def test_a_sample_exports_joint_angles_to_bvh(tmp_path):
    walks = make_walks(2, directions=["forward", "left"], random_state=0)
    X = VirtualMarkerTransform().fit_transform(
        as_motions(walks.clips, walks.skeletons, walks.frame_rate)
    )
    transformer = VirtualMarkerTransform(walks.skeleton, frame_rate=walks.frame_rate).fit(
        walks.clips[:1]
    )
    model = MotionTreeHMM(max_depth=5, split="median").fit(X, walks.target)
    clip = model.sample(12, y=walks.target[0], random_state=0, transformer=transformer,
                        frame_rate=walks.frame_rate)  # fmt: skip
    # body sizes: the sampled markers carry per-channel noise no pose fits exactly, yet
    # stay within a few centimetres of a pose
    assert np.median(clip.ik_rms) < 0.03 and clip.ik_rms.max() < 0.1
    write_bvh(clip.motion, tmp_path / "sample.bvh")
    back = read_bvh(tmp_path / "sample.bvh")
    markers = transformer.marker_set(back.skeleton)
    solved = markers.positions(clip.motion.skeleton, clip.motion.channels)
    reread = markers.positions(back.skeleton, back.channels)
    np.testing.assert_allclose(reread, solved, atol=1e-3 * np.abs(solved).max())


def test_bad_arguments(model):
    with pytest.raises(ValueError, match="not a class"):
        model.sample(10, y="fly")
    with pytest.raises(ValueError, match="n_frames"):
        model.sample(0)
    with pytest.raises(ValueError, match="smoothness"):
        model.sample(5, smoothness=-1)
