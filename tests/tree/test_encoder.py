"""MotionTreeEncoder: routing against the tree's own splits, histograms against a per-clip loop."""

import math
import pickle

import numpy as np
import pandas as pd
import pytest
import scipy.sparse as sp
from hypothesis import given, settings
from hypothesis import strategies as st
from sklearn.linear_model import LogisticRegression
from sklearn.model_selection import GroupKFold, cross_val_score
from sklearn.pipeline import make_pipeline

from skmotion.datasets import make_motions
from skmotion.tree import MotionTree, MotionTreeEncoder
from skmotion.tree._encoding import TreeRouter
from tests.clip_conformance import ClipCase, parametrize_with_clip_checks


def small_motions():
    data = make_motions(
        n_clips_per_class=3, classes=["walk", "jump", "wave"], duration=(1.0, 1.5), random_state=1
    )
    return [c[:, 6:] for c in data.clips], data.target_names[data.target]


@pytest.fixture(scope="module")
def motions():
    data = make_motions(n_clips_per_class=8, random_state=0)
    return [c[:, 6:] for c in data.clips], data.target_names[data.target], data.groups


@parametrize_with_clip_checks(
    [
        ClipCase(
            MotionTreeEncoder(max_depth=3, layers="all", sparse_output=False),
            small_motions,
            param_grid={"max_depth": [2, 3], "power": [0.5, 1.0]},
        )
    ]
)
def test_conformance(check):
    check()


@pytest.mark.parametrize("split", ["median", "min_error"])
def test_routing_matches_the_trees_splits_at_every_layer(split, rng):
    # 7 layers of median splits, the compiled walk against MotionTree.apply at every layer
    frames = rng.normal(size=(3000, 6)) * [1, 2, 3, 4, 5, 6] + 10
    center, scale = frames.mean(0), frames.std(0)
    tree = MotionTree.build((frames - center) / scale, max_depth=7, split=split, min_samples_leaf=4)
    routed = TreeRouter(tree, center, scale).route(frames)
    for layer in range(tree.n_layers):
        expected = tree.apply((frames - center) / scale, layer)
        np.testing.assert_array_equal(routed[:, layer], expected)
    some = TreeRouter(tree, center, scale).route(frames, [2, 5])
    np.testing.assert_array_equal(some, routed[:, [2, 5]])


def _walk_reference(tree, z, layers):
    """Each standardised frame walked down ``tree`` one node at a time, the projection summed
    exactly (``math.fsum`` of the products); also whether the frame ever came within
    rounding of a threshold, where any summation order may send it either way."""
    out = np.empty((len(z), len(layers)), dtype=np.intp)
    close = np.zeros(len(z), dtype=bool)
    for i, frame in enumerate(z):
        node = 0
        for layer in range(max(layers) + 1):
            if layer in layers:
                out[i, layers.index(layer)] = list(tree.layers[layer]).index(node)
            if tree.left[node] >= 0:
                products = frame * tree.axis[node]
                value, threshold = math.fsum(products), tree.threshold[node]
                close[i] |= abs(value - threshold) <= 1e-9 * (np.abs(products).sum() + 1.0)
                node = tree.right[node] if value > threshold else tree.left[node]
    return out, close


@settings(max_examples=40, deadline=None)
@given(
    d=st.integers(1, 9),
    depth=st.integers(1, 6),
    split=st.sampled_from(["median", "two_means", "min_error"]),
    seed=st.integers(0, 2**32 - 1),
    data=st.data(),
)
def test_the_compiled_walk_matches_a_frame_by_frame_walk(d, depth, split, seed, data):
    # any number of channels (the dot product's four accumulators and its tail), any depth,
    # leaves above the bottom (copied down); the training frames and new ones
    rng = np.random.default_rng(seed)
    train = rng.normal(size=(200, d)) * rng.uniform(0.5, 3.0, d)
    tree = MotionTree.build(train, max_depth=depth, split=split, min_samples_leaf=4)
    layers = sorted(data.draw(st.sets(st.integers(0, tree.n_layers - 1), min_size=1)))
    new = rng.normal(size=(100, d)) * 2.0
    router = TreeRouter(tree)
    for frames, may_be_close in ((train, False), (new, True)):
        expected, close = _walk_reference(tree, frames, layers)
        routed = router.route(frames, layers)
        assert may_be_close or not close.any()  # the gap rule: training frames are clear
        np.testing.assert_array_equal(routed[~close], expected[~close])


def reference_variances(encoder, train):
    """Each residual node's per-channel variance of its training frames, by a loop over nodes."""
    if encoder.residual_order == 1:
        return []
    z = (np.vstack(train) - encoder.center_) / encoder.scale_
    variances = []
    for layer in encoder.residual_layers_:
        nodes = encoder.tree_.apply(z, layer)
        variance = np.ones((encoder.tree_.n_nodes[layer], z.shape[1]))
        for k in range(len(variance)):
            if (nodes == k).sum() > 1:
                variance[k] = np.maximum(z[nodes == k].var(axis=0), 1e-3)
        variances.append(variance)
    return variances


def reference_features(encoder, clips, train=None):
    """The encoding by a loop over clips, frames and cells (an independent computation)."""
    rows = []
    tree = encoder.tree_
    variances = reference_variances(encoder, clips if train is None else train)
    for clip in clips:
        z = (clip - encoder.center_) / encoder.scale_
        n = len(clip)
        parts_out = []
        for layer in encoder.layers_:
            nodes = tree.apply(z, layer)
            k = tree.n_nodes[layer]
            for parts in encoder.pyramid:
                for c in range(parts):
                    members = [t for t in range(n) if c * n <= t * parts < (c + 1) * n]
                    hist = np.zeros(k)
                    for t in members:
                        hist[nodes[t]] += 1.0 / len(members)
                    parts_out.append(hist)
        for layer in encoder.transition_layers_:
            nodes = tree.apply(z, layer)
            k = tree.n_nodes[layer]
            table = np.zeros((k, k))
            for t in range(n - 1):
                if nodes[t] != nodes[t + 1]:
                    table[nodes[t], nodes[t + 1]] += 1.0 / (n - 1)
            parts_out.append(table.ravel())
        hist = np.concatenate(parts_out) ** encoder.power
        residuals = []
        for layer in encoder.residual_layers_:
            nodes = tree.apply(z, layer)
            means = tree.means(layer)
            block = np.zeros_like(means)
            for t in range(n):
                block[nodes[t]] += (z[t] - means[nodes[t]]) / n
            block = np.sign(block) * np.abs(block) ** encoder.power
            residuals.append(block.ravel() / np.linalg.norm(block))
        for layer, variance in zip(encoder.residual_layers_, variances):
            nodes = tree.apply(z, layer)
            means = tree.means(layer)
            block = np.zeros_like(means)
            for t in range(n):
                block[nodes[t]] += ((z[t] - means[nodes[t]]) ** 2 / variance[nodes[t]] - 1) / n
            block = np.sign(block) * np.abs(block) ** encoder.power
            residuals.append(block.ravel() / np.linalg.norm(block))
        # moments: a loop over the clip's frames in units of the training frames
        moments = []
        if encoder.moments:
            total, squares = np.zeros(clip.shape[1]), np.zeros(clip.shape[1])
            for frame in clip:
                u = (frame - encoder.moment_center_) / encoder.moment_scale_
                total += u
                squares += u * u
            moments = [total / n, np.sqrt(squares / n) - 1][: encoder.moments]
        rows.append(np.concatenate([hist, *residuals, *moments]))
    return np.array(rows)


@pytest.mark.parametrize("moments, residual_order", [(0, 1), (1, 1), (2, 1), (2, 2)])
def test_features_match_a_per_clip_loop(motions, moments, residual_order):
    X = motions[0][:12]
    X = X + [X[0][:2], X[1][:1]]  # clips shorter than the pyramid's cells
    encoder = MotionTreeEncoder(
        max_depth=4,
        layers="all",
        pyramid=[1, 2, 3],
        transition_layers=[2],
        residual_layers=[1, 3],
        residual_order=residual_order,
        moments=moments,
        power=0.5,
        sparse_output=False,
    ).fit(X)
    features = encoder.transform(X)
    np.testing.assert_allclose(features, reference_features(encoder, X), atol=1e-12)
    names = encoder.get_feature_names_out()
    assert len(names) == features.shape[1] == encoder.n_features_out_
    last = {0: "layer3_node7_channel_59", 1: "mean_channel_59", 2: "rms_channel_59"}[moments]
    assert names[-1] == last
    if residual_order == 2:
        assert "layer3_node7_var_channel_59" in names


@pytest.mark.parametrize("standardize", [True, False])
def test_moments_by_hand(standardize):
    # Training frames 0, 2, 4, 6 and 1, 1, 1, 1: means 3 and 1, deviations sqrt(5) and 0 (taken
    # as 1). The clip's first channel at 3 and 3 + sqrt(5) is at 0 and 1 in those units: mean
    # 0.5, mean square 0.5, rms minus 1: sqrt(0.5) - 1; its second at 1 and 3 is at 0 and 2:
    # mean 1, mean square 2, rms minus 1: sqrt(2) - 1.
    train = [np.array([[0.0, 1.0], [2.0, 1.0]]), np.array([[4.0, 1.0], [6.0, 1.0]])]
    encoder = MotionTreeEncoder(
        residual_layers=(), moments=2, standardize=standardize, min_samples_leaf=1
    ).fit(train, None)
    clip = np.array([[3.0, 1.0], [3.0 + np.sqrt(5.0), 3.0]])
    expected = [[0.5, 1.0, np.sqrt(0.5) - 1, np.sqrt(2.0) - 1]]
    np.testing.assert_allclose(encoder.transform([clip]), expected, atol=1e-12)
    names = encoder.get_feature_names_out(["a", "b"]).tolist()
    assert names == ["mean_a", "mean_b", "rms_a", "rms_b"]


def test_each_cell_is_a_distribution_and_names_follow_the_columns(motions):
    X = motions[0][:10]
    encoder = MotionTreeEncoder(
        max_depth=3,
        layers="all",
        pyramid=[1, 2],
        residual_layers=[],
        power=1.0,
        sparse_output=False,
    )
    features = encoder.fit_transform(X)
    names = encoder.get_feature_names_out()
    assert len(names) == features.shape[1] == encoder.n_features_out_
    for layer in encoder.layers_:
        for parts in (1, 2):
            for c in range(parts):
                cols = [
                    i
                    for i, name in enumerate(names)
                    if name.startswith(f"layer{layer}_") and name.endswith(f"_part{c + 1}of{parts}")
                ]
                assert len(cols) == encoder.tree_.n_nodes[layer]
                np.testing.assert_allclose(features[:, cols].sum(axis=1), 1.0)
    # "layer1_node1_part1of1" is the share of a clip's frames in layer 1's second node
    share = np.mean(encoder.tree_.apply((X[0] - encoder.center_) / encoder.scale_, 1) == 1)
    assert features[0, list(names).index("layer1_node1_part1of1")] == pytest.approx(share)


def test_sparse_and_pandas_output(motions):
    X = motions[0][:10]
    big = MotionTreeEncoder(max_depth=8, min_samples_leaf=1, layers="all").fit(X)
    assert big.n_features_out_ >= 1024 and sp.issparse(big.transform(X))
    dense = MotionTreeEncoder(
        max_depth=8, min_samples_leaf=1, layers="all", sparse_output=False
    ).fit(X)
    assert not sp.issparse(MotionTreeEncoder().fit(X).transform(X))  # residuals: dense
    np.testing.assert_array_equal(big.transform(X).toarray(), dense.transform(X))
    big.set_output(transform="pandas")
    with pytest.raises(ValueError, match="sparse_output=False"):
        big.transform(X)
    frame = dense.set_output(transform="pandas").transform(X)
    assert isinstance(frame, pd.DataFrame)
    assert list(frame.columns) == list(dense.get_feature_names_out())


def test_pipeline_recognises_held_out_subjects(motions):
    X, y, groups = motions
    model = make_pipeline(MotionTreeEncoder(), LogisticRegression(max_iter=2000))
    scores = cross_val_score(model, X, y, groups=groups, cv=GroupKFold(4))
    assert scores.mean() >= 0.9  # measured 0.98 (docs/motion-database.md)


def test_pickled_encoder_gives_identical_features(motions):
    X = motions[0][:10]
    for encoder in (MotionTreeEncoder().fit(X), MotionTreeEncoder(residual_order=2).fit(X)):
        again = pickle.loads(pickle.dumps(encoder))
        np.testing.assert_array_equal(encoder.transform(X), again.transform(X))
    sparse = MotionTreeEncoder(layers="all", sparse_output=True).fit(X)
    assert (sparse.transform(X) != pickle.loads(pickle.dumps(sparse)).transform(X)).nnz == 0


@given(st.lists(st.integers(1, 60), min_size=1, max_size=6), st.integers(1, 5))
def test_cells_partition_every_clip(lengths, parts):
    rng = np.random.default_rng(len(lengths) * 7 + parts)
    train = [rng.normal(size=(50, 3)) for _ in range(3)]
    encoder = MotionTreeEncoder(
        max_depth=2,
        layers="all",
        pyramid=[parts],
        residual_layers=[],
        moments=0,
        power=1.0,
        sparse_output=False,
    )
    encoder.fit(train)
    clips = [rng.normal(size=(n, 3)) for n in lengths]
    features = encoder.transform(clips)
    filled = np.minimum(np.array(lengths), parts)  # a clip of n < parts frames fills n cells
    np.testing.assert_allclose(features.sum(axis=1), filled * len(encoder.layers_))


@pytest.mark.parametrize(
    "params, match",
    [
        ({"pyramid": []}, "pyramid must name"),
        ({"pyramid": [0]}, "pyramid must hold ints >= 1"),
        ({"layers": [9], "residual_layers": [], "moments": 0}, "nothing to encode"),
        ({"layers": [], "residual_layers": [], "moments": 0}, "nothing to encode"),
        ({"moments": 3}, "moments"),
    ],
)
def test_bad_parameters_are_named(params, match, motions):
    with pytest.raises(ValueError, match=match):
        MotionTreeEncoder(max_depth=2, **params).fit(motions[0][:5])
