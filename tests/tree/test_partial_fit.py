"""MotionTreeHMM.partial_fit: exact node statistics and graphs against one-shot references."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from skmotion.datasets import make_motions
from skmotion.tree import MotionTree, MotionTreeHMM, TransitionGraphs
from skmotion.tree._gaussian import centred_moments, estimate_covariance
from skmotion.tree._growth._moments import Moments


def _data(n_per_class=4, classes=("walk", "jump", "wave"), seed=0):
    data = make_motions(
        n_clips_per_class=n_per_class, classes=list(classes), duration=(0.8, 1.2), random_state=seed
    )
    return [c[:, 6:18] for c in data.clips], data.target_names[data.target]


CLIPS, LABELS = _data()


def reference_stats(tree, frames):
    """Each node's count, mean and covariance from its frames (routed through the tree's splits)."""
    out = {}
    for layer, labels in enumerate(tree.iter_apply(frames)):
        ids = tree.layers[layer][labels]
        for node in np.unique(ids):
            if tree.depth[node] != layer:
                continue
            mean, scatter, sq = centred_moments(frames[ids == node])
            cov = estimate_covariance(scatter, len(sq), tree.covariance_type, tree.reg, sq)
            out[int(node)] = (int((ids == node).sum()), mean, cov)
    return out


def check_against_one_shot(model, clips, labels):
    """Node statistics and graphs equal those of all clips routed through the model's tree."""
    tree = model.tree_
    std = [(c - model.center_) / model.scale_ for c in clips]
    frames = np.concatenate(std)
    ref = reference_stats(tree, frames)
    assert sorted(ref) == list(range(tree.n_tree_nodes))  # every node holds frames
    for node, (count, mean, cov) in ref.items():
        assert tree.count[node] == count
        np.testing.assert_allclose(tree.mean[node], mean, rtol=1e-9, atol=1e-9)
        np.testing.assert_allclose(tree.covariance[node], cov, rtol=1e-8, atol=1e-10)
    for layer in range(tree.n_layers):  # every layer partitions all frames
        assert tree.counts(layer).sum() == len(frames)
    offsets = np.r_[0, np.cumsum([len(c) for c in clips])]
    y_index = np.searchsorted(model.classes_, np.asarray(labels))
    if model.graph == "clip":
        np.testing.assert_array_equal(model.graph_classes_, y_index)
        y_index = np.arange(len(clips))
    graphs = TransitionGraphs.count(
        list(tree.iter_apply(frames)),
        tree.n_nodes,
        offsets=offsets,
        graph_of_clip=y_index,
        n_graphs=model.graphs_.n_graphs,
    )
    for layer in range(tree.n_layers):
        np.testing.assert_array_equal(graphs.visits(layer), model.graphs_.visits(layer))
        for g in range(graphs.n_graphs):
            assert (graphs.counts(layer, g) != model.graphs_.counts(layer, g)).nnz == 0
    whole = TransitionGraphs.count(
        list(tree.iter_apply(frames)),
        tree.n_nodes,
        offsets=offsets,
        graph_of_clip=np.zeros(len(clips), int),
    )
    for layer in range(tree.n_layers):
        assert (whole.counts(layer, 0) != model.global_graph_.counts(layer, 0)).nnz == 0


def grow(model, clips, labels, batches, **kwargs):
    """partial_fit the clips in the given batches (lists of indices), in order."""
    for batch in batches:
        model.partial_fit([clips[i] for i in batch], [labels[i] for i in batch], **kwargs)
    return model


@pytest.mark.parametrize("covariance_type", ["diag", "spherical", "full"])
def test_clip_by_clip_equals_one_shot_without_splits(covariance_type):
    model = MotionTreeHMM(max_depth=4, min_samples_leaf=8, covariance_type=covariance_type)
    order = np.random.default_rng(1).permutation(len(CLIPS))
    first = list(order[:3])
    grow(
        model,
        CLIPS,
        LABELS,
        [first] + [[i] for i in order[3:]],
        split_growth=None,
        rebuild_growth=None,
    )
    tree_of_first = (
        MotionTreeHMM(**model.get_params()).fit([CLIPS[i] for i in first], LABELS[first]).tree_
    )
    # the structure is the first batch's; the statistics are those of all clips
    np.testing.assert_array_equal(model.tree_.threshold, tree_of_first.threshold)
    check_against_one_shot(model, [CLIPS[i] for i in order], LABELS[order])


@settings(max_examples=15)
@given(
    order=st.permutations(range(len(CLIPS))),
    cuts=st.lists(st.integers(1, len(CLIPS) - 1), max_size=5),
    kind=st.sampled_from(["diag", "spherical", "full"]),
)
def test_any_batching_gives_the_one_shot_statistics(order, cuts, kind):
    bounds = sorted(set(cuts) | {len(CLIPS)})
    batches, start = [], 0
    for stop in bounds:
        batches.append(list(order[start:stop]))
        start = stop
    model = MotionTreeHMM(max_depth=3, min_samples_leaf=8, covariance_type=kind)
    grow(model, CLIPS, LABELS, batches, split_growth=None, rebuild_growth=None)
    check_against_one_shot(model, [CLIPS[i] for i in order], LABELS[list(order)])


def test_moments_merge_exactly():
    rng = np.random.default_rng(0)
    parts = [rng.normal(3.0, 2.0, size=(n, 5)) for n in (1, 4, 9, 2)]
    for kind in ("diag", "spherical", "full"):
        merged = Moments.of(parts[0], [0], kind)
        for p in parts[1:]:
            merged = merged.merged(Moments.of(p, [0], kind))
        mean, scatter, sq = centred_moments(np.concatenate(parts))
        np.testing.assert_allclose(merged.mean[0], mean, rtol=1e-12)
        np.testing.assert_allclose(
            merged.covariances(0.01)[0],
            estimate_covariance(scatter, len(sq), kind, 0.01, sq),
            rtol=1e-10,
        )
        if kind == "full":
            np.testing.assert_allclose(merged.s4[0], sq @ sq, rtol=1e-10)


def test_grown_leaves_split_by_the_build_rule():
    model = MotionTreeHMM(max_depth=5, min_samples_leaf=8)
    order = [0, 4] + [i for i in range(len(CLIPS)) if i not in (0, 4)]
    grow(model, CLIPS, LABELS, [order[:2]], split_growth=1.5, rebuild_growth=None)
    before = model.tree_
    grow(model, CLIPS, LABELS, [order[2:]], split_growth=1.5, rebuild_growth=None)
    tree = model.tree_
    assert tree.n_tree_nodes > before.n_tree_nodes  # leaves grew and split
    check_against_one_shot(model, [CLIPS[i] for i in order], LABELS[order])
    # every split made now is the build's on the node's frames (ids of old nodes are kept)
    frames = np.concatenate([(CLIPS[i] - model.center_) / model.scale_ for i in order])
    paths = list(tree.iter_apply(frames))
    new_splits = [
        v for v in np.flatnonzero(tree.left >= 0) if v >= before.n_tree_nodes or before.left[v] < 0
    ]
    assert new_splits
    for node in new_splits:
        mine = frames[tree.layers[tree.depth[node]][paths[tree.depth[node]]] == node]
        alone = MotionTree.build(mine, max_depth=1, min_samples_leaf=8, split=model.split)
        np.testing.assert_allclose(alone.axis[0], tree.axis[node], rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(alone.threshold[0], tree.threshold[node], rtol=1e-9)


def test_drifted_nodes_are_rebuilt_from_their_frames():
    model = MotionTreeHMM(max_depth=4, min_samples_leaf=8)
    walk = [i for i in range(len(CLIPS)) if LABELS[i] == "walk"]
    rest = [i for i in range(len(CLIPS)) if LABELS[i] != "walk"]
    grow(
        model, CLIPS, LABELS, [walk, rest], split_growth=None, rebuild_growth=None, rebuild_tol=0.5
    )
    tree = model.tree_
    # the root's mean moved far: the whole tree is the build's on all frames
    # (standardised as the first batch was)
    order = walk + rest
    frames = np.concatenate([(CLIPS[i] - model.center_) / model.scale_ for i in order])
    whole = MotionTree.build(frames, max_depth=4, min_samples_leaf=8, split=model.split)
    assert tree.n_tree_nodes == whole.n_tree_nodes
    np.testing.assert_allclose(tree.threshold, whole.threshold, rtol=1e-9)
    check_against_one_shot(model, [CLIPS[i] for i in order], LABELS[order])


def test_new_classes_join_and_are_recognised():
    model = MotionTreeHMM(max_depth=4, min_samples_leaf=8)
    known = [i for i in range(len(CLIPS)) if LABELS[i] != "wave"]
    wave = [i for i in range(len(CLIPS)) if LABELS[i] == "wave"]
    model.partial_fit([CLIPS[i] for i in known], LABELS[known], classes=["dance"])
    assert list(model.classes_) == ["dance", "jump", "walk"]
    assert model.graphs_.n_graphs == 3 and model.graphs_.visits(1)[0].sum() == 0
    model.partial_fit([CLIPS[i] for i in wave], LABELS[wave])
    assert list(model.classes_) == ["dance", "jump", "walk", "wave"]
    # wave's frames fall in nodes built without them, and are still told apart (chance: 1/4)
    predicted = model.predict(CLIPS)
    assert (predicted[wave] == "wave").mean() >= 0.75 and model.score(CLIPS, LABELS) >= 0.9
    check_against_one_shot(model, [CLIPS[i] for i in known + wave], LABELS[known + wave])


def test_clip_graphs_grow_one_per_clip():
    model = MotionTreeHMM(max_depth=3, min_samples_leaf=8, graph="clip")
    grow(model, CLIPS, LABELS, [[0, 1, 2]] + [[i] for i in range(3, len(CLIPS))])
    assert model.graphs_.n_graphs == len(CLIPS)
    check_against_one_shot(model, CLIPS, LABELS)


def test_after_fit_diag_merges_and_full_raises():
    first, rest = [0, 3, 6, 9], [1, 2, 4, 5, 7, 8, 10, 11]
    model = MotionTreeHMM(max_depth=3, min_samples_leaf=8).fit(
        [CLIPS[i] for i in first], LABELS[first]
    )
    model.partial_fit([CLIPS[i] for i in rest], LABELS[rest])
    check_against_one_shot(model, [CLIPS[i] for i in first + rest], LABELS[first + rest])
    full = MotionTreeHMM(max_depth=3, covariance_type="full").fit(CLIPS[:4], LABELS[:4])
    with pytest.raises(ValueError, match="cannot be recovered"):
        full.partial_fit(CLIPS[4:], LABELS[4:])


@pytest.mark.parametrize(
    "bad",
    [
        {"split_growth": 1.0},
        {"rebuild_tol": 0},
        {"split_growth": "x"},
        {"rebuild_growth": 0.5},
        {"rebuild_growth": True},
        {"classes": "dance"},
    ],
)
def test_bad_growth_parameters(bad):
    with pytest.raises(ValueError, match=next(iter(bad))):
        MotionTreeHMM().partial_fit(CLIPS, LABELS, **bad)


def test_a_database_grown_clip_by_clip_recognises_as_a_rebuilt_one():
    data = make_motions(
        n_clips_per_class=6, classes=["walk", "jog", "jump", "kick"], random_state=2
    )
    clips, names = [c[:, 6:] for c in data.clips], data.target_names[data.target]
    train, test = np.flatnonzero(data.groups < 3), np.flatnonzero(data.groups == 3)
    first = [int(train[names[train] == c][0]) for c in np.unique(names)]
    model = MotionTreeHMM(max_depth=6).partial_fit([clips[i] for i in first], names[first])
    for i in np.random.default_rng(0).permutation(train):
        if i not in first:
            model.partial_fit([clips[i]], names[i : i + 1])
    rebuilt = MotionTreeHMM(max_depth=6).fit([clips[i] for i in train], names[train])
    X_test, y_test = [clips[i] for i in test], names[test]
    assert model.score(X_test, y_test) >= rebuilt.score(X_test, y_test) - 0.05
    assert model.tree_.count[0] == sum(len(clips[i]) for i in train)


def test_a_pickled_database_keeps_growing_the_same():
    import pickle

    model = MotionTreeHMM(max_depth=4, min_samples_leaf=8).partial_fit(CLIPS[:6], LABELS[:6])
    copy = pickle.loads(pickle.dumps(model))
    for m in (model, copy):
        m.partial_fit(CLIPS[6:], LABELS[6:], split_growth=1.5)
    np.testing.assert_array_equal(copy.tree_.count, model.tree_.count)
    np.testing.assert_array_equal(copy.tree_.covariance, model.tree_.covariance)
    np.testing.assert_array_equal(copy.predict_proba(CLIPS), model.predict_proba(CLIPS))


@pytest.mark.parametrize("graph", ["class", "clip"])
def test_splits_and_rebuilds_keep_statistics_and_graphs_exact(graph):
    model = MotionTreeHMM(max_depth=5, min_samples_leaf=8, graph=graph)
    model.partial_fit(CLIPS[:2], LABELS[:2], classes=["zzz"])
    before = model.tree_.n_tree_nodes
    for i in range(2, len(CLIPS)):
        model.partial_fit(CLIPS[i : i + 1], LABELS[i : i + 1], split_growth=1.5, rebuild_tol=0.5)
    assert model.tree_.n_tree_nodes != before  # the structure changed on the way
    assert "zzz" in model.classes_
    check_against_one_shot(model, CLIPS, LABELS)


def test_novelty_follows_the_grown_database():
    """After leaves split, novelty_score weighs the new nodes by their share of all frames."""
    model = MotionTreeHMM(max_depth=5, min_samples_leaf=8)
    rest = list(range(1, 4)) + list(range(5, len(CLIPS)))
    grow(model, CLIPS, LABELS, [[0, 4], rest], split_growth=1.5)
    assert model.tree_.n_layers > 1
    visits = model.global_graph_.visits(model.layer_)[0]
    assert model.log_node_weights_.shape == (model.tree_.n_nodes[model.layer_],)
    np.testing.assert_allclose(np.exp(model.log_node_weights_), visits / visits.sum())
    typical = model.novelty_score(CLIPS)
    moved = model.novelty_score([c + 10 * model.scale_ for c in CLIPS])
    assert np.all(moved < typical)


def test_a_doubled_database_is_rebuilt_as_fit_builds_it():
    model = MotionTreeHMM(max_depth=4, min_samples_leaf=8)
    order = list(np.random.default_rng(2).permutation(len(CLIPS)))
    model.partial_fit([CLIPS[i] for i in order[:2]], LABELS[order[:2]], classes=["zzz"])
    built, rebuilt_at = sum(len(CLIPS[i]) for i in order[:2]), []
    for n in range(3, len(CLIPS) + 1):
        center = model.center_
        i = order[n - 1]
        model.partial_fit([CLIPS[i]], LABELS[i : i + 1], split_growth=None)
        total = sum(len(CLIPS[j]) for j in order[:n])
        if total < 2 * built:  # not due: the standardisation stays
            assert model.center_ is center
            continue
        built = total
        rebuilt_at.append(n)
        seen = [CLIPS[j] for j in order[:n]]
        fitted = MotionTreeHMM(max_depth=4, min_samples_leaf=8).fit(seen, LABELS[order[:n]])
        # the whole database is fit's on every clip so far (the declared class kept)
        np.testing.assert_array_equal(model.center_, fitted.center_)
        np.testing.assert_array_equal(model.tree_.threshold, fitted.tree_.threshold)
        np.testing.assert_array_equal(model.tree_.covariance, fitted.tree_.covariance)
        assert model.temperature_ == fitted.temperature_ and "zzz" in model.classes_
        proba = model.predict_proba(CLIPS)[:, :-1]  # "zzz" (no clip) sorts last
        np.testing.assert_allclose(
            proba / proba.sum(axis=1, keepdims=True), fitted.predict_proba(CLIPS), rtol=1e-9
        )
    assert len(rebuilt_at) >= 2  # 2 clips first: the frames doubled twice on the way to 12
    check_against_one_shot(model, [CLIPS[i] for i in order], LABELS[order])


def test_a_doubled_subtree_is_rebuilt_by_the_build_rule():
    model = MotionTreeHMM(max_depth=4, min_samples_leaf=8, standardize=False)
    model.partial_fit(CLIPS, LABELS)
    before = model.tree_
    # a new clip near the frames of the root's smaller child: it doubles, the root does not
    frames = np.concatenate(CLIPS)
    child = min(before.left[0], before.right[0], key=lambda v: before.count[v])
    near = frames[before.apply(frames, 1) == list(before.layers[1]).index(child)]
    new = [near + np.random.default_rng(0).normal(0, 1e-3, near.shape)]
    model.partial_fit(new, ["new"], split_growth=None)
    tree = model.tree_
    assert tree.count[0] < 2 * before.count[0] and tree.threshold[0] == before.threshold[0]
    node = tree.left[0] if child == before.left[0] else tree.right[0]
    assert tree.count[node] == 2 * before.count[child]
    everything = np.concatenate(CLIPS + new)
    paths = list(tree.iter_apply(everything))
    # every split under the rebuilt child is the build's on its frames now
    inside = [node]
    for v in inside:
        if tree.left[v] < 0:
            continue
        inside += [tree.left[v], tree.right[v]]
        mine = everything[tree.layers[tree.depth[v]][paths[tree.depth[v]]] == v]
        alone = MotionTree.build(mine, max_depth=1, min_samples_leaf=8, split=model.split)
        np.testing.assert_allclose(alone.threshold[0], tree.threshold[v], rtol=1e-9)
    assert len(inside) > 1 and "new" in model.classes_
    check_against_one_shot(model, CLIPS + new, list(LABELS) + ["new"])


def test_a_rebuilt_database_keeps_the_channel_names_of_dataframes():
    import warnings

    import pandas as pd

    def frame(indices):
        parts = {i: pd.DataFrame(CLIPS[i], columns=[f"ch{j}" for j in range(12)]) for i in indices}
        return pd.concat(parts, names=["clip", "frame"])

    model = MotionTreeHMM(max_depth=3, min_samples_leaf=8).partial_fit(
        frame([0, 4]), LABELS[[0, 4]]
    )
    center = model.center_
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no "fitted without feature names" on the way
        for i in (1, 2, 3, 5):
            model.partial_fit(frame([i]), LABELS[[i]])
        assert model.center_ is not center  # the frames doubled: rebuilt on the way
        assert list(model.feature_names_in_) == [f"ch{j}" for j in range(12)]
        np.testing.assert_array_equal(model.predict(frame(range(12))), model.predict(CLIPS))
    with pytest.raises(ValueError, match="ch"):
        model.partial_fit(frame([6]).rename(columns={"ch0": "other"}), LABELS[[6]])
