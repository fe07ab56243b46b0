"""MotionTree: every layer partitions the frames, routing reproduces the build, node statistics."""

import inspect
from dataclasses import fields

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from skmotion.datasets import make_motions
from skmotion.tree import MotionTree, MotionTreeEncoder, MotionTreeHMM
from skmotion.tree._params import PAPER_TREE, TREE_CONSTRAINTS, TreeParams
from skmotion.tree._split import SPLIT_CRITERIA


def blobs(rng, sizes=(120, 80, 60), d=5):
    centres = rng.normal(0, 10, size=(len(sizes), d))
    return np.vstack([c + rng.normal(size=(n, d)) for c, n in zip(centres, sizes)])


@pytest.fixture(scope="module")
def motion_frames():
    data = make_motions(n_clips_per_class=2, random_state=0)
    return np.vstack([c[:, 6:] for c in data.clips])


def check_partition(tree, frames):
    """Every layer holds every frame once; routed frames give the stored statistics."""
    n = len(frames)
    previous = None  # the labels of the layer above (the root layer has none)
    for layer, labels in enumerate(tree.iter_apply(frames)):
        counts = np.bincount(labels, minlength=tree.n_nodes[layer])
        np.testing.assert_array_equal(counts, tree.counts(layer))
        assert counts.sum() == n
        sums = np.zeros((tree.n_nodes[layer], frames.shape[1]))
        np.add.at(sums, labels, frames)
        np.testing.assert_allclose(
            sums / counts[:, None], tree.means(layer), atol=1e-9 * (1 + np.abs(frames).max())
        )
        if layer:
            parents = tree.parents(layer)
            np.testing.assert_array_equal(
                np.bincount(parents, weights=counts), tree.counts(layer - 1)
            )
            np.testing.assert_array_equal(parents[labels], previous)
        previous = labels


@pytest.mark.parametrize("split", SPLIT_CRITERIA)
@pytest.mark.parametrize("covariance_type", ["diag", "full", "spherical"])
def test_layers_partition_the_frames(split, covariance_type, motion_frames):
    tree = MotionTree.build(
        motion_frames, split=split, covariance_type=covariance_type, max_depth=6
    )
    check_partition(tree, motion_frames)
    assert tree.n_layers <= 7


@settings(max_examples=40)
@given(
    n=st.integers(1, 120),
    d=st.integers(1, 6),
    duplicates=st.integers(0, 3),
    leaf=st.integers(1, 8),
    split=st.sampled_from(SPLIT_CRITERIA),
    seed=st.integers(0, 2**16),
)
def test_routing_reproduces_the_build(n, d, duplicates, leaf, split, seed):
    rng = np.random.default_rng(seed)
    frames = np.round(rng.normal(size=(n, d)), 1)  # coarse values: many ties
    frames = np.vstack([frames] * (duplicates + 1))
    tree = MotionTree.build(frames, min_samples_leaf=leaf, split=split)
    check_partition(tree, frames)
    bottom = tree.apply(frames)
    # identical frames share their node in every layer
    first = {}
    for row, node in zip(map(bytes, frames), bottom):
        assert first.setdefault(row, node) == node
    # no node, copies included, is smaller than min_samples_leaf (unless the root is)
    if n * (duplicates + 1) >= leaf:
        assert tree.count.min() >= leaf


def test_separated_blobs_split_exactly(rng):
    frames = np.r_[rng.normal(0, 1, (150, 3)), rng.normal(30, 1, (50, 3))]
    tree = MotionTree.build(frames, max_depth=1, min_samples_leaf=10)
    np.testing.assert_array_equal(tree.apply(frames, 1), np.r_[np.zeros(150), np.ones(50)])


def test_leaves_are_copied_down(rng):
    frames = blobs(rng)
    tree = MotionTree.build(frames, min_samples_leaf=30, split="median")
    bottom = set(tree.node_ids(-1))
    for layer in range(tree.n_layers - 1):
        ids, kids = tree.node_ids(layer), tree.children(layer)
        for k, node in enumerate(ids):
            if tree.left[node] < 0:  # a leaf: one child, itself
                assert kids[k, 1] == -1 and tree.node_ids(layer + 1)[kids[k, 0]] == node
                assert node in bottom
            else:
                assert list(tree.node_ids(layer + 1)[kids[k]]) == [
                    tree.left[node],
                    tree.right[node],
                ]
    assert (tree.children(-1) == -1).all()
    assert tree.n_tree_nodes == 2 * len(bottom) - 1


def test_max_depth_and_min_samples_split(rng):
    frames = blobs(rng)
    assert MotionTree.build(frames, max_depth=0).n_layers == 1
    assert MotionTree.build(frames, max_depth=3, min_samples_leaf=1).n_layers == 4
    tree = MotionTree.build(frames, min_samples_split=200, min_samples_leaf=1)
    assert tree.count[tree.left >= 0].min() >= 200


def test_split_axis_is_the_first_principal_axis(rng):
    frames = rng.normal(size=(300, 4)) @ np.diag([5.0, 1.0, 0.5, 0.1])
    tree = MotionTree.build(frames, max_depth=1)
    centred = frames - frames.mean(0)
    _, _, vt = np.linalg.svd(centred, full_matrices=False)
    assert abs(tree.axis[0] @ vt[0]) == pytest.approx(1.0)
    assert abs(tree.principal_axes[0] @ vt[0]) == pytest.approx(1.0)


def test_fewer_frames_than_channels_uses_the_small_problem(rng):
    frames = rng.normal(size=(12, 40)) * np.linspace(1, 3, 40)
    tree = MotionTree.build(frames, max_depth=1, min_samples_leaf=2)
    centred = frames - frames.mean(0)
    _, _, vt = np.linalg.svd(centred, full_matrices=False)
    assert abs(tree.axis[0] @ vt[0]) == pytest.approx(1.0)
    for kind in ("full", "diag"):
        cov = MotionTree.build(frames, min_samples_leaf=2, covariance_type=kind).covariances(-1)
        if kind == "full":
            assert np.linalg.eigvalsh(cov).min() > 0
        else:
            assert cov.min() > 0


def test_constant_and_duplicated_frames():
    constant = np.ones((50, 3))
    tree = MotionTree.build(constant, min_samples_leaf=1)
    assert tree.n_layers == 1 and np.isfinite(tree.log_likelihood(constant, 0)).all()
    half = np.r_[np.zeros((40, 2)), np.ones((40, 2))]
    tree = MotionTree.build(half, min_samples_leaf=1)
    assert tree.n_nodes[-1] == 2


def test_covariances_carry_the_regularisation(rng):
    frames = blobs(rng)
    frames[:, 2] = 4.0  # constant channel
    tree = MotionTree.build(frames, max_depth=2, reg_covar=1e-3)
    scale = frames.var(axis=0).mean()
    labels = tree.apply(frames, 2)
    for k in range(tree.n_nodes[2]):
        np.testing.assert_allclose(
            tree.covariances(2)[k], frames[labels == k].var(axis=0) + 1e-3 * scale
        )


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"max_depth": -1}, "max_depth must be an int >= 0"),
        ({"min_samples_leaf": 0}, "min_samples_leaf must be an int >= 1"),
        ({"min_samples_split": 1.5}, "min_samples_split must be an int >= 2"),
        ({"split": "gini"}, "split must be one of"),
        ({"covariance_type": "tied"}, "covariance_type must be one of"),
        ({"reg_covar": 0}, "reg_covar must be a positive number"),
    ],
)
def test_bad_parameters(kwargs, message):
    with pytest.raises(ValueError, match=message):
        MotionTree.build(np.zeros((4, 2)), **kwargs)


def test_bad_frames_and_layers(rng):
    frames = rng.normal(size=(10, 2))
    frames[3, 1] = np.nan
    with pytest.raises(ValueError, match="frame 3, channel 1"):
        MotionTree.build(frames)
    tree = MotionTree.build(rng.normal(size=(40, 2)), max_depth=1, min_samples_leaf=5)
    with pytest.raises(ValueError, match="layer 2 does not exist: the tree has 2 layers"):
        tree.counts(2)
    assert tree.check_layer(-1) == 1
    with pytest.raises(ValueError, match=r"frames must have shape \(n_frames, 2\)"):
        tree.apply(np.zeros((3, 5)))


def test_one_description_of_the_build_parameters(rng):
    """TreeParams names, constrains and defaults the build's parameters for every caller."""
    names = [f.name for f in fields(TreeParams)]
    assert set(TREE_CONSTRAINTS) == set(names)
    for name in names:  # the estimators validate with the one table
        assert MotionTreeHMM._parameter_constraints[name] is TREE_CONSTRAINTS[name]
    for name in ("min_samples_leaf", "split"):
        assert MotionTreeEncoder._parameter_constraints[name] is TREE_CONSTRAINTS[name]
    # MotionTreeHMM's defaults are TreeParams'; MotionTree.build declares the paper's tree
    assert TreeParams.of(MotionTreeHMM()) == TreeParams()
    build = inspect.signature(MotionTree.build).parameters
    assert {name: build[name].default for name in names} == PAPER_TREE.as_dict()
    # fit builds its tree with its parameters: the same tree as MotionTree.build's
    frames = rng.normal(size=(300, 3))
    model = MotionTreeHMM(max_depth=3, split="median", calibration_cv=None)
    model.fit([frames[:150], frames[150:]], [0, 1])
    tree = MotionTree.build(
        (frames - model.center_) / model.scale_, **TreeParams.of(model).as_dict()
    )
    np.testing.assert_array_equal(model.tree_.threshold, tree.threshold)
    np.testing.assert_array_equal(model.tree_.count, tree.count)
    with pytest.raises(ValueError, match="split must be one of"):
        TreeParams(split="gini")
