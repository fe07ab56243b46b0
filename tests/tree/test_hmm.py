"""MotionTreeHMM: conformance, recognition on known data, and its outputs against the references."""

import warnings

import numpy as np
import pytest
from scipy.special import logsumexp
from sklearn.model_selection import GridSearchCV, GroupKFold, cross_val_score
from sklearn.pipeline import make_pipeline
from sklearn.preprocessing import FunctionTransformer

from skmotion.datasets import load_uea, make_motions
from skmotion.preprocessing import VirtualMarkerTransform
from skmotion.tree import MotionTreeHMM, exhaustive_viterbi
from tests.clip_conformance import ClipCase, parametrize_with_clip_checks


def drop_root(clips):
    """Joint angles without the root's position and rotation (a simple feature step)."""
    return [np.asarray(c)[:, 6:] for c in clips]


def small_motions():
    data = make_motions(
        n_clips_per_class=3, classes=["walk", "jump", "wave"], duration=(1.0, 1.5), random_state=1
    )
    return drop_root(data.clips), data.target_names[data.target]


@pytest.fixture(scope="module")
def motions():
    data = make_motions(
        n_clips_per_class=8, classes=["walk", "jog", "jump", "kick", "squat"], random_state=0
    )
    return drop_root(data.clips), data.target_names[data.target], data.groups


@parametrize_with_clip_checks(
    [
        ClipCase(
            MotionTreeHMM(max_depth=3, min_samples_leaf=4),
            small_motions,
            param_grid={"max_depth": [2, 3], "min_samples_leaf": [4, 8]},
        )
    ]
)
def test_conformance(check):
    check()


def test_recognises_synthetic_motions_across_subjects(motions):
    X, y, groups = motions
    scores = cross_val_score(
        MotionTreeHMM(max_depth=6, split="median"), X, y, groups=groups, cv=GroupKFold(4)
    )
    assert scores.mean() >= 0.95


def test_recognises_basic_motions(shared_data):
    train = load_uea("BasicMotions", subset="train", data_home=shared_data)
    test = load_uea("BasicMotions", subset="test", data_home=shared_data)
    model = MotionTreeHMM(split="median", max_depth=6).fit(train.clips, train.target)
    assert model.score(test.clips, test.target) >= 0.95


def test_defaults_recognise_msrc12_people_never_seen(shared_data):
    """Real Kinect gestures, odd -> even person ids: the measured defaults against the former ones.

    Every gesture, the first two repetitions of each sequence (594 training
    clips). Measured: 0.837 with the defaults (depth 12, 8 frames per leaf),
    0.795 with the former depth-8 tree of 4-frame leaves; on all of MSRC-12 the
    grouped CV over the training people chose the deeper tree (0.79 -> 0.85).
    """
    path = shared_data / "msrc12" / "msrc12_sequences.npz"
    if not path.is_file():
        pytest.skip(f"{path} not found")
    from benchmarks._msrc12 import msrc12_repetitions

    data = msrc12_repetitions(path, max_per_sequence=2)
    train = data.person % 2 == 1
    pick = lambda mask: [c for c, m in zip(data.clips, mask) if m]  # noqa: E731
    markers = VirtualMarkerTransform(layout="kinect_v1", frame_rate=data.frame_rate)
    Xtr = markers.fit_transform(pick(train))
    Xte = markers.transform(pick(~train))

    def accuracy(**params):
        model = MotionTreeHMM(calibration_cv=None, **params).fit(Xtr, data.gesture[train])
        return model.score(Xte, data.gesture[~train])

    defaults, former = accuracy(), accuracy(max_depth=8, min_samples_leaf=4)
    assert defaults >= 0.82  # chance is 1 / 12
    assert defaults >= former + 0.03


def test_string_labels_and_probabilities(motions):
    X, y, _ = motions
    model = MotionTreeHMM(max_depth=4).fit(X, y)
    assert list(model.classes_) == sorted(set(y))
    log_prob = model.score_samples(X[:6])
    proba = model.predict_proba(X[:6])
    np.testing.assert_allclose(proba.sum(axis=1), 1.0)
    # per-frame generation probabilities over the fitted temperature, then a softmax
    scaled = log_prob / np.array([len(c) for c in X[:6]])[:, None] / model.temperature_
    np.testing.assert_allclose(proba, np.exp(scaled - logsumexp(scaled, axis=1, keepdims=True)))
    np.testing.assert_array_equal(model.predict(X[:6]), model.classes_[log_prob.argmax(axis=1)])


@pytest.mark.parametrize("graph", ["class", "clip"])
def test_generation_probabilities_match_the_exhaustive_reference(motions, graph):
    X, y, _ = motions
    X, y = X[::4], y[::4]
    model = MotionTreeHMM(
        max_depth=3, min_samples_leaf=30, n_paths=8, graph=graph, score_layers=1
    ).fit(X, y)
    assert model.n_nodes_.max() <= 8  # n_paths covers every node: the beam prunes nothing
    query = [(X[0][::3] - model.center_) / model.scale_, (X[5][:7] - model.center_) / model.scale_]
    per_graph = np.array(
        [
            [
                logsumexp(
                    exhaustive_viterbi(
                        model.tree_, model.graphs_, -1, q, g, n_paths=8, node_prior="layer"
                    )[1]
                )
                for g in range(len(model.graph_classes_))
            ]
            for q in query
        ]
    )
    expected = np.full((2, len(model.classes_)), -np.inf)
    for g, c in enumerate(model.graph_classes_):  # a class scores as its best graph
        expected[:, c] = np.maximum(expected[:, c], per_graph[:, g])
    np.testing.assert_allclose(model.score_samples([X[0][::3], X[5][:7]]), expected)


def test_decode_and_predict_next_follow_the_global_graph(motions):
    X, y, _ = motions
    model = MotionTreeHMM(max_depth=3, min_samples_leaf=30, n_paths=8).fit(X[::3], y[::3])
    clip = X[1][:12]
    query = (clip - model.center_) / model.scale_
    best, scores = exhaustive_viterbi(model.tree_, model.global_graph_, -1, query, 0, n_paths=8)
    logprob, paths = model.decode([clip])
    np.testing.assert_array_equal(paths[0], best[0])
    # the path's log probability is the exhaustive Viterbi's best score (node_prior="layer":
    # the global graph visits every node, so both priors spread over the whole layer)
    np.testing.assert_allclose(logprob, scores[:1], rtol=1e-12)
    # at the root, every frame has probability 1
    logprob, paths = model.decode([clip], layer=0)
    assert (paths[0] == 0).all() and logprob.tolist() == [0.0]
    # the current node's probability, carried two steps by the global graph's matrix
    layer = model.layer_
    weights = np.exp(scores - logsumexp(scores))
    current = np.bincount(best[:, -1], weights=weights, minlength=model.n_nodes_[layer])
    P = model.global_graph_.matrix(layer, 0)
    future = current @ P @ P
    nxt = model.predict_next([clip], n_steps=2, n_best=4)
    np.testing.assert_array_equal(nxt.nodes[0], np.argsort(-future, kind="stable")[:4])
    np.testing.assert_allclose(nxt.probabilities[0], np.sort(future)[::-1][:4])
    np.testing.assert_allclose(
        nxt.means[0], model.tree_.means(layer)[nxt.nodes[0]] * model.scale_ + model.center_
    )


def test_sliding_window_profiles(motions):
    X, y, _ = motions
    model = MotionTreeHMM(max_depth=4).fit(X, y)
    clips = [X[0][:30], X[1][:7]]
    profiles = model.predict_proba_windows(clips, width=10, step=5)
    assert [len(p) for p in profiles] == [5, 1]
    np.testing.assert_allclose(profiles[0][2], model.predict_proba([X[0][10:20]])[0])
    np.testing.assert_allclose(profiles[1][0], model.predict_proba([X[1][:7]])[0])
    with pytest.raises(ValueError, match="width must be an int >= 1"):
        model.predict_proba_windows(clips, width=0)


def test_classifying_at_an_upper_layer(motions):
    X, y, groups = motions
    scores = cross_val_score(
        MotionTreeHMM(max_depth=8, layer=5, split="median"), X, y, groups=groups, cv=GroupKFold(4)
    )
    assert scores.mean() >= 0.9
    with pytest.raises(ValueError, match="layer 20 does not exist"):
        MotionTreeHMM(max_depth=3, layer=20).fit(X, y)


@pytest.mark.parametrize("graph", ["class", "clip"])
def test_the_papers_node_prior_gives_finite_answers(motions, graph):
    X, y, _ = motions
    model = MotionTreeHMM(max_depth=5, node_prior="graph", graph=graph).fit(X[::2], y[::2])
    proba = model.predict_proba(X[1::4])
    assert np.isfinite(proba).all() and np.allclose(proba.sum(axis=1), 1.0)
    assert np.isfinite(model.score_samples(X[1::4])).all()


@pytest.mark.parametrize("score_layers", [1, "all"])
def test_hard_cases_give_finite_answers(score_layers):
    rng = np.random.default_rng(0)
    X = [rng.normal(size=(n, 12)) for n in (40, 35, 50, 1, 2)]
    X[0][:, 3] = 1.5  # a constant channel
    X[1] = np.vstack([X[1][:5]] * 7)  # duplicated frames
    y = ["a", "a", "b", "b", "c"]  # class "c" has one clip of two frames
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        model = MotionTreeHMM(
            min_samples_leaf=1, n_paths=5, covariance_type="full", score_layers=score_layers
        )
        model.fit(X, y)
        for query in ([X[3]], [X[4]], [rng.normal(size=(1, 12)) * 100], [np.zeros((3, 12))]):
            assert np.isfinite(model.score_samples(query)).all()
            assert np.isfinite(model.predict_proba(query)).all()
            assert model.predict(query)[0] in model.classes_
            assert len(model.decode(query)[1][0]) == len(query[0])
            assert np.isfinite(model.predict_next(query).probabilities).all()
    assert model.tree_.count.min() >= 1


def test_a_long_clip_does_not_underflow(motions):
    X, y, _ = motions
    model = MotionTreeHMM(max_depth=2, n_paths=2).fit(X, y)
    long_clip = np.vstack([X[0]] * (10_000 // len(X[0]) + 1))[:10_000]
    log_prob = model.score_samples([long_clip])
    assert np.isfinite(log_prob).all() and log_prob.min() < -745  # exp() of it would be 0
    assert model.predict([long_clip])[0] == y[0]


@pytest.mark.parametrize("in_pipeline", [False, True])
def test_grid_search_over_depth_and_leaf_size(in_pipeline):
    data = make_motions(n_clips_per_class=6, classes=["walk", "jump", "squat"], random_state=2)
    model = MotionTreeHMM(n_paths=2)
    grid = {"max_depth": [2, 4], "min_samples_leaf": [8, 32]}
    X = data.clips
    if in_pipeline:
        model = make_pipeline(FunctionTransformer(drop_root), model)
        grid = {f"motiontreehmm__{k}": v for k, v in grid.items()}
    else:
        X = drop_root(X)
    search = GridSearchCV(model, grid, cv=GroupKFold(3)).fit(X, data.target, groups=data.groups)
    assert len(search.cv_results_["params"]) == 4
    assert search.best_score_ >= 0.8


@pytest.fixture(scope="module")
def marker_search():
    """A GridSearchCV over depth and leaf size on virtual markers, with its data and folds."""
    from skmotion.preprocessing import VirtualMarkerTransform

    data = make_motions(
        n_clips_per_class=4, classes=["walk", "jump", "squat"], duration=(1.0, 1.5), random_state=3
    )
    pipe = make_pipeline(
        VirtualMarkerTransform(skeleton=data.skeleton, frame_rate=data.frame_rate),
        MotionTreeHMM(n_paths=2),
    )
    grid = {"motiontreehmm__max_depth": [2, 5], "motiontreehmm__min_samples_leaf": [4, 24]}
    splits = list(GroupKFold(2).split(data.clips, data.target, data.groups))
    search = GridSearchCV(pipe, grid, cv=splits).fit(data.clips, data.target)
    return search, data, splits


def test_grid_search_on_virtual_markers_equals_a_manual_loop(marker_search):
    from sklearn.base import clone
    from sklearn.model_selection import ParameterGrid

    search, data, splits = marker_search
    X, y = data.clips, data.target
    manual = []
    for params in ParameterGrid(search.param_grid):
        folds = []
        for train, test in splits:
            model = (
                clone(search.estimator).set_params(**params).fit([X[i] for i in train], y[train])
            )
            folds.append(np.mean(model.predict([X[i] for i in test]) == y[test]))
        manual.append((params, np.mean(folds)))
    assert [p for p, _ in manual] == list(search.cv_results_["params"])
    np.testing.assert_allclose([s for _, s in manual], search.cv_results_["mean_test_score"])
    best = max(
        range(len(manual)), key=lambda i: (manual[i][1], -i)
    )  # the first of the best, as sklearn
    assert search.best_params_ == manual[best][0]
    # the refit model is the best setting fitted on all clips
    refit = clone(search.estimator).set_params(**manual[best][0]).fit(X, y)
    np.testing.assert_array_equal(search.predict(X), refit.predict(X))


def test_the_fitted_marker_pipeline_pickles(marker_search):
    import pickle

    search, data, _ = marker_search
    restored = pickle.loads(pickle.dumps(search.best_estimator_))
    np.testing.assert_array_equal(
        restored.predict(data.clips), search.best_estimator_.predict(data.clips)
    )
    np.testing.assert_array_equal(
        restored.predict_proba(data.clips), search.best_estimator_.predict_proba(data.clips)
    )
    np.testing.assert_array_equal(
        restored.score_samples(data.clips), search.best_estimator_.score_samples(data.clips)
    )


@pytest.mark.parametrize("n_paths", [1, 3])  # 1: predict takes the best-score pass alone
@pytest.mark.parametrize("graph", ["class", "clip"])
def test_pruned_predict_agrees_with_full_scoring(motions, graph, n_paths):
    X, y, _ = motions
    model = MotionTreeHMM(max_depth=4, n_paths=n_paths, graph=graph).fit(X[::2], y[::2])
    np.testing.assert_array_equal(
        model.predict(X), model.classes_[np.argmax(model.score_samples(X), axis=1)]
    )


def test_several_scored_layers_multiply_their_generation_probabilities(motions):
    """score_samples over three layers is the sum of the single-layer models' log probabilities."""
    X, y, _ = motions
    model = MotionTreeHMM(max_depth=5, split="median", score_layers=3).fit(X[::2], y[::2])
    np.testing.assert_array_equal(model.score_layers_, [3, 4, 5])
    per_layer = [
        MotionTreeHMM(max_depth=5, split="median", layer=layer, score_layers=1).fit(X[::2], y[::2])
        for layer in (3, 4, 5)
    ]
    expected = np.sum([m.score_samples(X[1::3]) for m in per_layer], axis=0)
    np.testing.assert_allclose(model.score_samples(X[1::3]), expected, rtol=1e-10)
    log_prob = model.score_samples(X[:5])
    scaled = log_prob / np.array([len(c) for c in X[:5]])[:, None] / model.temperature_
    np.testing.assert_allclose(
        model.predict_proba(X[:5]), np.exp(scaled - logsumexp(scaled, axis=1, keepdims=True))
    )


@pytest.mark.parametrize("graph", ["class", "clip"])
def test_pruned_predict_over_several_layers_agrees_with_full_scoring(motions, graph):
    # with clip graphs a class scores as its best clip's product over the layers
    X, y, _ = motions
    model = MotionTreeHMM(max_depth=5, n_paths=3, score_layers=3, graph=graph).fit(X[::2], y[::2])
    np.testing.assert_array_equal(
        model.predict(X), model.classes_[np.argmax(model.score_samples(X), axis=1)]
    )


def test_score_layers_all_and_beyond_the_tree(motions):
    X, y, _ = motions
    everything = MotionTreeHMM(max_depth=4, score_layers="all").fit(X[::3], y[::3])
    np.testing.assert_array_equal(everything.score_layers_, [1, 2, 3, 4])
    beyond = MotionTreeHMM(max_depth=4, score_layers=50).fit(X[::3], y[::3])
    np.testing.assert_array_equal(beyond.score_samples(X[1::5]), everything.score_samples(X[1::5]))
    upper = MotionTreeHMM(max_depth=4, layer=2, score_layers=2).fit(X[::3], y[::3])
    np.testing.assert_array_equal(upper.score_layers_, [1, 2])
    with pytest.raises(ValueError, match="score_layers"):
        MotionTreeHMM(score_layers=0).fit(X, y)
