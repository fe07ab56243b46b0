"""MotionTreeHMM.transform (per-layer class scores) against enumeration; out-of-fold rows; folds."""

import copy
import itertools
import pickle

import numpy as np
import pandas as pd
import pytest
from scipy.special import log_softmax, logsumexp
from sklearn.base import clone
from sklearn.linear_model import LogisticRegression
from sklearn.metrics import log_loss
from sklearn.pipeline import make_pipeline, make_union

from skmotion.datasets import make_motions
from skmotion.tree import MotionTreeEncoder, MotionTreeHMM, TransitionGraphs, node_log_posterior
from skmotion.tree._calibration import held_out_folds


def blobs(seed=3):
    """Three classes of short 2-D clips wandering between blobs, each class its own habits."""
    rng = np.random.default_rng(seed)
    centres = np.array([[0.0, 0.0], [5.0, 0.0], [0.0, 5.0], [5.0, 5.0]])
    habits = [[0, 1, 0, 1], [2, 3, 2, 3], [0, 2, 3, 1]]
    clips, y = [], []
    for label, habit in enumerate(habits):
        for _ in range(6):
            n = int(rng.integers(4, 7))
            visits = np.resize(np.roll(habit, int(rng.integers(4))), n)
            clips.append(centres[visits] + rng.normal(scale=1.0, size=(n, 2)))
            y.append(f"c{label}")
    return clips, np.array(y)


def enumerated_scores(model, clip):
    """``(n_classes, n_scored)``: log of the n_paths best sequences' summed probability, by hand.

    Every node sequence of every scored layer is scored from the definition
    (``log Ps(k | x)`` of each frame plus ``log Pt`` of each transition); a
    class's value with clip graphs is its best graph's.
    """
    frames = (clip - model.center_) / model.scale_
    out = np.full((len(model.classes_), len(model.score_layers_)), -np.inf)
    for column, layer in enumerate(model.score_layers_):
        log_ps = node_log_posterior(model.tree_, model.graphs_, layer, frames, model.node_prior)
        for graph, cls in enumerate(model.graph_classes_):
            log_pt = np.log(model.graphs_.matrix(layer, graph))
            every = [
                sum(log_ps[graph, t, n] for t, n in enumerate(seq))
                + sum(log_pt[a, b] for a, b in zip(seq[:-1], seq[1:]))
                for seq in itertools.product(range(log_ps.shape[2]), repeat=len(frames))
            ]
            best = np.sort(every)[::-1][: model.n_paths]
            out[cls, column] = max(out[cls, column], logsumexp(best))
    return out


@pytest.mark.parametrize("graph", ["class", "clip"])
def test_transform_equals_the_enumerated_definition(graph):
    """Wide beam (every node kept): each column is the log-softmax over classes, per layer,
    of the enumerated K-best generation probability divided by the clip's length."""
    X, y = blobs()
    model = MotionTreeHMM(max_depth=2, min_samples_leaf=3, n_paths=4, graph=graph).fit(X, y)
    assert model.n_nodes_.max() <= model.n_paths  # the beam keeps every node: exhaustive
    tests = [X[0][:4], X[7][:3], X[15], X[3][:1] + 0.5]
    features = model.transform(tests)
    for row, clip in zip(features, tests):
        per_frame = enumerated_scores(model, clip) / len(clip)
        expected = log_softmax(per_frame, axis=0).T.ravel()  # layer-major
        np.testing.assert_allclose(row, expected, rtol=1e-9, atol=1e-9)
    names = model.get_feature_names_out()
    assert list(names[:3]) == ["layer1_class_c0", "layer1_class_c1", "layer1_class_c2"]
    assert names[-1] == "layer2_class_c2" and len(names) == features.shape[1]


def test_fit_transform_rows_are_out_of_fold():
    """Each training row equals transform by the graphs counted without the clip's fold."""
    X, y = blobs()
    model = MotionTreeHMM(max_depth=2, min_samples_leaf=3, calibration_cv=3)
    rows = model.fit_transform(X, y)
    y_index = np.searchsorted(model.classes_, y)
    folds = held_out_folds(y_index, None, 3)
    assert sorted(np.concatenate([held for _, held in folds])) == list(range(len(X)))
    for train, held in folds:
        frames = np.vstack([X[i] for i in train])
        labels = list(model.tree_.iter_apply((frames - model.center_) / model.scale_))
        offsets = np.r_[0, np.cumsum([len(X[i]) for i in train])]
        count = dict(offsets=offsets, n_nodes=model.tree_.n_nodes, smoothing=model.smoothing)
        fold_model = copy.copy(model)
        fold_model.graphs_ = TransitionGraphs.count(
            labels, graph_of_clip=y_index[train], n_graphs=3, **count
        )
        fold_model.global_graph_ = TransitionGraphs.count(
            labels, graph_of_clip=np.zeros(len(train), int), n_graphs=1, **count
        )
        expected = fold_model.transform([X[i] for i in held])
        np.testing.assert_allclose(rows[held], expected, rtol=1e-12, atol=1e-12)
    # in-sample rows are surer of the right class than the held-out ones
    in_sample = model.transform(X)
    assert in_sample[np.arange(len(X)), y_index].mean() > rows[np.arange(len(X)), y_index].mean()


def test_without_folds_fit_transform_is_fit_then_transform():
    X, y = blobs()
    model = MotionTreeHMM(max_depth=2, min_samples_leaf=3, calibration_cv=None)
    np.testing.assert_array_equal(model.fit_transform(X, y), model.transform(X))


def test_contiguous_and_grouped_folds():
    y = np.array([0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 1, 1])
    folds = held_out_folds(y, None, 3)
    assert [sorted(held) for _, held in folds] == [[0, 1, 6, 7], [2, 3, 8, 9], [4, 5, 10, 11]]
    groups = np.array([0, 0, 1, 1, 2, 2, 3, 3, 4, 4, 5, 5])
    for train, held in held_out_folds(y, groups, 3):
        assert not np.intersect1d(groups[train], groups[held]).size
    assert held_out_folds(y, None, None) is None
    assert held_out_folds(np.r_[y, 2], None, 3) is None  # a class of one clip
    with pytest.raises(ValueError, match="one group per clip"):
        MotionTreeHMM(max_depth=2).fit([np.ones((5, 2))] * 4, [0, 0, 1, 1], groups=[0, 1])


def overlapping_windows():
    """Windows (20 frames, hop 5) of one noisy 8 s take per class, split by time (60% trains)."""
    data = make_motions(n_clips_per_class=1, duration=(8.0, 8.0), noise=40.0, random_state=0)
    parts = {"train": ([], []), "test": ([], [])}
    for clip, label in zip(data.clips, data.target_names[data.target]):
        cut = int(0.6 * len(clip))
        for side, part in (("train", clip[:cut, 6:]), ("test", clip[cut:, 6:])):
            for start in range(0, len(part) - 20 + 1, 5):
                parts[side][0].append(part[start : start + 20])
                parts[side][1].append(label)
    return [(X, np.array(y)) for X, y in parts.values()]


def test_temperature_from_windows_that_do_not_leak_across_folds():
    """Shuffled folds put a window's overlapping neighbours on both sides: the held-out scores
    are too sure and the temperature too small. Contiguous folds (the default) do far better
    on the later windows of the same takes."""
    (Xtr, ytr), (Xte, yte) = overlapping_windows()
    shuffled = np.random.default_rng(0).permutation(len(Xtr)) % 30  # random groups: shuffled
    params = dict(max_depth=6, split="median", calibration_cv=3)
    leaky = MotionTreeHMM(**params).fit(Xtr, ytr, groups=shuffled)
    contiguous = MotionTreeHMM(**params).fit(Xtr, ytr)
    loss = [log_loss(yte, m.predict_proba(Xte), labels=m.classes_) for m in (leaky, contiguous)]
    assert contiguous.temperature_ > 10 * leaky.temperature_
    assert loss[1] < 0.2 * loss[0]
    np.testing.assert_array_equal(leaky.predict(Xte), contiguous.predict(Xte))


def test_pipelines_clone_pickle_and_pandas_output():
    X, y = blobs()
    stacked = make_pipeline(MotionTreeHMM(max_depth=2, min_samples_leaf=3), LogisticRegression())
    stacked.fit(X, y)
    assert stacked.score(X, y) >= 0.9
    union = make_pipeline(
        make_union(MotionTreeEncoder(max_depth=2), MotionTreeHMM(max_depth=2, min_samples_leaf=3)),
        LogisticRegression(),
    ).fit(X, y)
    assert union.score(X, y) >= 0.9
    model = stacked[0]
    again = pickle.loads(pickle.dumps(model))
    np.testing.assert_array_equal(again.transform(X), model.transform(X))
    np.testing.assert_array_equal(clone(model).fit(X, y).transform(X), model.transform(X))
    frame = clone(model).set_output(transform="pandas").fit(X, y).transform(X)
    assert isinstance(frame, pd.DataFrame)
    assert list(frame.columns) == list(model.get_feature_names_out())
    np.testing.assert_array_equal(frame.to_numpy(), model.transform(X))
