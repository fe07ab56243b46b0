"""MotionClassifier against its steps run by hand, on synthetic and real skeletons."""

import pickle

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from sklearn.base import clone
from sklearn.linear_model import LogisticRegression
from sklearn.model_selection import GridSearchCV, GroupKFold
from sklearn.neighbors import KNeighborsClassifier
from sklearn.pipeline import make_pipeline
from sklearn.preprocessing import StandardScaler
from skmotion.recognition._covariance_rows import covariance_rows

from skmotion.datasets import make_motions, make_position_motions
from skmotion.preprocessing import FlattenClips, ResampleClips, VirtualMarkerTransform
from skmotion.recognition import MotionClassifier, block_scales, clip_covariances
from skmotion.recognition._motion_classifier import fit_in_span
from skmotion.tree import MotionTreeEncoder
from tests.clip_conformance import ClipCase, parametrize_with_clip_checks


def small_clips():
    data = make_motions(
        n_clips_per_class=3, classes=["walk", "jump", "wave"], duration=(1.0, 1.5), random_state=1
    )
    return [c[:, 6:] for c in data.clips], data.target_names[data.target]


@parametrize_with_clip_checks(
    [ClipCase(MotionClassifier(max_depth=3, C=1.0), small_clips, param_grid={"C": [0.1, 1.0]})]
)
def test_conformance(check):
    check()


@pytest.fixture(scope="module")
def positions():
    data = make_position_motions("kinect_v2", n_clips_per_class=6, random_state=0)
    return data


def _split(data, subject=3):
    test = data.groups == subject
    clips = data.clips
    pick = lambda mask: [c for c, m in zip(clips, mask) if m]  # noqa: E731
    return pick(~test), data.target[~test], pick(test), data.target[test]


def test_equals_its_steps_run_by_hand(positions):
    """The estimator is exactly: markers, block scaling, the encoder, scaled columns, LR."""
    Xtr, ytr, Xte, _ = _split(positions)
    rate = positions.frame_rate
    model = MotionClassifier(layout="kinect_v2", frame_rate=rate, max_depth=4).fit(Xtr, ytr)

    markers = VirtualMarkerTransform(layout="kinect_v2", frame_rate=rate).fit(Xtr)
    Mtr, Mte = markers.transform(Xtr), markers.transform(Xte)
    frames = np.vstack(Mtr)
    velocity = np.array([n.rsplit("_", 1)[1][0] == "v" for n in markers.get_feature_names_out()])
    # each block's root-mean-square deviation, by hand
    dev = frames - frames.mean(axis=0)
    rms_p = np.sqrt(np.mean(dev[:, ~velocity] ** 2))
    rms_v = np.sqrt(np.mean(dev[:, velocity] ** 2))
    scale = np.where(velocity, rms_v, rms_p)
    np.testing.assert_allclose(model.scale_, scale)
    center = frames.mean(axis=0)
    S = lambda M: [(m - center) / scale for m in M]  # noqa: E731
    encoder = MotionTreeEncoder(
        max_depth=4, layers="all", moment_pyramid=(1, 2, 4), standardize=False, sparse_output=False
    ).fit(S(Mtr))
    # the vocabulary, then each clip's channel covariances (np.cov's upper triangle)
    upper = np.triu_indices(len(scale))
    cov = lambda M: [np.cov(m, rowvar=False, bias=True)[upper] for m in M]  # noqa: E731
    Ftr = np.hstack([encoder.transform(S(Mtr)), cov(S(Mtr))])
    Fte = np.hstack([encoder.transform(S(Mte)), cov(S(Mte))])
    # the covariances' columns weigh covariance_weight=0.2 after the columns' scaling
    weight = np.where(np.arange(Ftr.shape[1]) < encoder.n_features_out_, 1.0, 0.2)
    # each column centred and divided by the square root of its standard deviation
    root = lambda F: weight * (F - Ftr.mean(axis=0)) / np.sqrt(Ftr.std(axis=0))  # noqa: E731
    assert len(Ftr) <= Ftr.shape[1] / 4  # few clips: the model is solved in their span
    span = _span(root(Ftr))
    head = LogisticRegression(C=1.0, max_iter=1000).fit(root(Ftr) @ span, ytr)
    np.testing.assert_allclose(
        model.predict_proba(Xte), head.predict_proba(root(Fte) @ span), atol=1e-10
    )
    # column_power=1 is sklearn's StandardScaler
    standard = clone(model).set_params(column_power=1.0).fit(Xtr, ytr)
    scaler = StandardScaler().fit(Ftr)
    Ztr, Zte = weight * scaler.transform(Ftr), weight * scaler.transform(Fte)
    span = _span(Ztr)
    head = LogisticRegression(C=1.0, max_iter=1000).fit(Ztr @ span, ytr)
    np.testing.assert_allclose(
        standard.predict_proba(Xte), head.predict_proba(Zte @ span), atol=1e-10
    )


def _span(columns):
    """An orthonormal basis of the rows' span, ``X^T V L^(-1/2)`` from the rows' Gram
    matrix ``X X^T = V L V^T`` (the basis ``fit_in_span`` solves in: with the model's
    default tolerance another basis ends the solver's path elsewhere)."""
    values, vectors = np.linalg.eigh(columns @ columns.T)
    kept = values > values[-1] * len(columns) * np.finfo(float).eps
    basis = columns.T @ vectors[:, kept] / np.sqrt(values[kept])
    np.testing.assert_allclose(basis.T @ basis, np.eye(kept.sum()), atol=1e-8)
    return basis


@pytest.mark.parametrize("n_classes", [2, 4])
@pytest.mark.parametrize("class_weight", [None, "balanced"])
def test_the_span_gives_the_full_problems_optimum(n_classes, class_weight):
    """Solved in the span of 30 rows, the weights over 400 columns are the full problem's."""
    rng = np.random.default_rng(n_classes)
    X = rng.normal(size=(30, 400))
    y = rng.integers(0, n_classes, size=30)
    y[:n_classes] = np.arange(n_classes)
    X[:, :5] += y[:, None]
    tight = dict(C=0.5, class_weight=class_weight, tol=1e-12, max_iter=100_000)
    full = LogisticRegression(**tight).fit(X, y)
    span = fit_in_span(LogisticRegression(**tight), X, y)
    assert span.coef_.shape == full.coef_.shape and span.n_features_in_ == 400
    np.testing.assert_allclose(span.coef_, full.coef_, atol=1e-7)
    np.testing.assert_allclose(span.intercept_, full.intercept_, atol=1e-7)
    Z = rng.normal(size=(10, 400))
    np.testing.assert_allclose(span.predict_proba(Z), full.predict_proba(Z), atol=1e-7)
    # many rows: the model is fitted on the columns as they are (no basis)
    many = rng.normal(size=(120, 400)), rng.integers(0, n_classes, size=120)
    direct = LogisticRegression(C=0.5, class_weight=class_weight, max_iter=1000).fit(*many)
    same = fit_in_span(LogisticRegression(C=0.5, class_weight=class_weight, max_iter=1000), *many)
    np.testing.assert_array_equal(same.coef_, direct.coef_)


def test_split_and_class_weight_reach_their_steps():
    """``split`` is the tree's and ``class_weight`` the logistic regression's: the same
    answers as the steps run by hand with them, on classes recorded unevenly."""
    X, y = small_clips()
    keep = np.flatnonzero((y != "wave") | (np.arange(len(y)) % 3 == 0))
    X, y = [X[i] for i in keep], y[keep]
    assert (y == "wave").sum() == 1 and len(y) == 7
    # (without the covariances, which have their own test)
    params = {
        "max_depth": 3,
        "split": "two_means",
        "class_weight": "balanced",
        "covariance_weight": 0,
    }
    model = MotionClassifier(**params).fit(X, y)
    frames = np.vstack(X)
    scaled = [(x - frames.mean(axis=0)) / frames.std(axis=0) for x in X]
    encoder = MotionTreeEncoder(
        max_depth=3,
        split="two_means",
        layers="all",
        moment_pyramid=(1, 2, 4),
        standardize=False,
        sparse_output=False,
    ).fit(scaled)
    F = encoder.transform(scaled)
    spread = F.std(axis=0)
    root = (F - F.mean(axis=0)) / np.sqrt(np.where(spread > 0, spread, 1.0))
    span = _span(root)
    head = LogisticRegression(C=1.0, class_weight="balanced", max_iter=1000).fit(root @ span, y)
    np.testing.assert_allclose(model.predict_proba(X), head.predict_proba(root @ span), atol=1e-10)
    # balanced: the one wave clip weighs 7 / (3 * 1), each other clip 7 / (3 * 3)
    unweighted = clone(model).set_params(class_weight=None).fit(X, y)
    assert not np.allclose(unweighted.predict_proba(X), model.predict_proba(X))


def test_beats_nearest_neighbour_on_a_held_out_subject(positions):
    """A subject never seen in training: at least as good as 1-NN on resampled markers."""
    scores, baseline = [], []
    rate = positions.frame_rate
    for subject in np.unique(positions.groups):
        Xtr, ytr, Xte, yte = _split(positions, subject)
        model = MotionClassifier(layout="kinect_v2", frame_rate=rate).fit(Xtr, ytr)
        scores.append(model.score(Xte, yte))
        knn = make_pipeline(
            VirtualMarkerTransform(layout="kinect_v2", frame_rate=rate),
            ResampleClips(n_frames=32),
            FlattenClips(),
            KNeighborsClassifier(1),
        ).fit(Xtr, ytr)
        baseline.append(knn.score(Xte, yte))
    assert np.mean(scores) >= np.mean(baseline)
    assert np.mean(scores) >= 0.9


def test_probabilities_and_decisions_agree(positions):
    Xtr, ytr, Xte, _ = _split(positions)
    model = MotionClassifier(layout="kinect_v2", frame_rate=positions.frame_rate, max_depth=4)
    model.fit(Xtr, ytr)
    proba = model.predict_proba(Xte)
    np.testing.assert_allclose(proba.sum(axis=1), 1.0)
    assert (model.classes_[proba.argmax(axis=1)] == model.predict(Xte)).all()
    assert (model.decision_function(Xte).argmax(axis=1) == proba.argmax(axis=1)).all()
    np.testing.assert_allclose(np.exp(model.predict_log_proba(Xte)), proba)
    # predicting folds the columns' scaling into the weights: the same as classifier_ on
    # the scaled columns that transform returns
    direct = model.classifier_.decision_function(model.transform(Xte))
    np.testing.assert_allclose(model.decision_function(Xte), direct, rtol=1e-9, atol=1e-9)


@pytest.mark.parametrize("n_classes", [2, 3])
def test_predict_and_decisions_are_the_readouts_own(positions, n_classes):
    # predict and decision_function take the readout's product without sklearn's input
    # checks: the same doubles and labels as its decision_function and predict, also for
    # two classes (one column of logits, its sign)
    Xtr, ytr, Xte, _ = _split(positions)
    keep = np.isin(ytr, np.unique(ytr)[:n_classes])
    model = MotionClassifier(layout="kinect_v2", frame_rate=positions.frame_rate, max_depth=3)
    model.fit([x for x, k in zip(Xtr, keep) if k], ytr[keep])
    features = model._raw(Xte)
    assert np.array_equal(model.decision_function(Xte), model._readout.decision_function(features))
    assert np.array_equal(model.predict(Xte), model._readout.predict(features))
    assert len(set(model.predict(Xte))) == n_classes  # both signs / several classes seen


def test_novelty_ranks_foreign_clips_lower(positions):
    Xtr, ytr, Xte, _ = _split(positions)
    model = MotionClassifier(layout="kinect_v2", frame_rate=positions.frame_rate, max_depth=4)
    model.fit(Xtr, ytr)
    rng = np.random.default_rng(0)
    # the same clips with joints thrown about: poses no person makes
    foreign = [c + rng.normal(scale=0.3, size=c.shape) for c in Xte]
    own, other = model.novelty_score(Xte), model.novelty_score(foreign)
    assert own.min() > np.median(other)


def test_pickle_clone_and_grid_search(positions):
    Xtr, ytr, Xte, _ = _split(positions)
    model = MotionClassifier(layout="kinect_v2", frame_rate=positions.frame_rate, max_depth=3)
    model.fit(Xtr, ytr)
    again = pickle.loads(pickle.dumps(model))
    np.testing.assert_array_equal(again.predict_proba(Xte), model.predict_proba(Xte))
    assert clone(model).get_params() == model.get_params()
    groups = positions.groups[positions.groups != 3]
    search = GridSearchCV(model, {"velocity_weight": [0.25, 1.0]}, cv=GroupKFold(3))
    search.fit(Xtr, ytr, groups=groups)
    assert set(search.best_params_) == {"velocity_weight"}


def test_plain_channels_are_standardised_one_by_one():
    X, y = small_clips()
    model = MotionClassifier(max_depth=3).fit(X, y)
    frames = np.vstack(X)
    np.testing.assert_allclose(model.scale_, frames.std(axis=0))
    assert model.markers_ is None


@pytest.mark.parametrize(
    "params, match",
    [
        ({"scaling": "blocks"}, "needs the marker step"),
        ({"layout": "kinect_v2", "skeleton": make_motions(1, random_state=0).skeleton}, "not both"),
        ({"C": 0.0}, "C"),
        ({"column_power": 1.5}, "column_power"),
        ({"scaling": "per-channel"}, "scaling"),
        ({"split": "mean"}, "split"),
        ({"class_weight": "even"}, "class_weight"),
        ({"covariance_weight": -1.0}, "covariance_weight"),
    ],
)
def test_bad_parameters_are_named(params, match):
    X, y = small_clips()
    with pytest.raises(ValueError, match=match):
        MotionClassifier(**params).fit(X, y)


def test_labels_must_match_the_clips():
    X, y = small_clips()
    with pytest.raises(ValueError, match="9 clips but y holds 8"):
        MotionClassifier(max_depth=2).fit(X, y[:8])


@settings(max_examples=25, deadline=None)
@given(
    st.integers(2, 40),
    st.lists(st.integers(0, 2), min_size=2, max_size=8),
    st.floats(0.1, 5.0),
)
def test_block_scales_give_each_block_its_weight(n_frames, blocks, weight):
    rng = np.random.default_rng(n_frames)
    blocks = np.asarray(blocks)
    frames = rng.normal(size=(n_frames, len(blocks))) * rng.uniform(0.1, 10, len(blocks))
    weights = [1.0, weight, 2.0]
    scaled = (frames - frames.mean(axis=0)) / block_scales(frames, blocks, weights)
    for block in np.unique(blocks):
        rms = np.sqrt(np.mean(scaled[:, blocks == block] ** 2))
        assert rms == pytest.approx(weights[block])
    # within a block, channels keep their relative spread (one number per block)
    for block in np.unique(blocks):
        cols = np.flatnonzero(blocks == block)
        ratio = scaled[:, cols].std(axis=0) / frames[:, cols].std(axis=0)
        np.testing.assert_allclose(ratio, ratio[0])


def test_msrc12_cross_subject(shared_data):
    """Real Kinect gestures, people never seen in training (odd ids train, even test)."""
    path = shared_data / "msrc12" / "msrc12_sequences.npz"
    if not path.is_file():
        pytest.skip(f"{path} not found")
    from benchmarks._msrc12 import msrc12_repetitions

    data = msrc12_repetitions(path, gestures=(1, 2, 3, 4), max_per_sequence=3)
    train = data.person % 2 == 1
    pick = lambda mask: [c for c, m in zip(data.clips, mask) if m]  # noqa: E731
    model = MotionClassifier(layout="kinect_v1", frame_rate=15).fit(
        pick(train), data.gesture[train]
    )
    assert model.score(pick(~train), data.gesture[~train]) >= 0.9


@settings(max_examples=40, deadline=None)
@given(st.lists(st.integers(1, 60), min_size=1, max_size=5), st.integers(1, 40))
def test_clip_covariances_are_numpys_covariance(lengths, n_channels):
    """Each row is the upper triangle of ``np.cov(bias=True)`` of its clip (0 for one frame):
    the compiled pass (one dsyrk per clip, the triangle copied row by row) against NumPy."""
    rng = np.random.default_rng(len(lengths) * 7 + n_channels)
    clips = [rng.normal(size=(n, n_channels)) * rng.uniform(0.1, 5, n_channels) for n in lengths]
    rows, cols = np.triu_indices(n_channels)
    expected = np.zeros((len(clips), len(rows)))
    for i, clip in enumerate(clips):
        if len(clip) > 1:
            expected[i] = np.atleast_2d(np.cov(clip, rowvar=False, bias=True))[rows, cols]
    np.testing.assert_allclose(clip_covariances(clips), expected, rtol=1e-12, atol=1e-12)


def test_covariance_rows_write_into_a_tables_columns():
    # MotionClassifier's vocabulary: the covariances written into the last columns of a
    # wider table (strided rows), the same values as a fresh array, the other columns kept
    rng = np.random.default_rng(0)
    frames, offsets = rng.normal(size=(9, 3)), np.array([0, 4, 9])
    table = np.full((2, 8), 7.0)
    covariance_rows(frames, offsets, table[:, 2:])
    assert np.array_equal(table[:, 2:], covariance_rows(frames, offsets))
    assert (table[:, :2] == 7.0).all()
    with pytest.raises(ValueError, match=r"out must have shape \(2, 6\)"):
        covariance_rows(frames, offsets, table)


def test_covariance_rows_name_bad_offsets():
    frames = np.zeros((5, 2))
    with pytest.raises(ValueError, match="clip 1 has no frames"):
        covariance_rows(frames, np.array([0, 2, 2, 5]))
    with pytest.raises(ValueError, match="from 0 to the 5 frames"):
        covariance_rows(frames, np.array([0, 4]))


def test_covariance_weight_appends_the_weighted_covariances():
    """``covariance_weight`` appends each clip's channel covariances, scaled like the
    vocabulary's columns and multiplied by the weight, before the linear model."""
    X, y = small_clips()
    model = MotionClassifier(max_depth=3, covariance_weight=0.5).fit(X, y)
    frames = np.vstack(X)
    scaled = [(x - frames.mean(axis=0)) / frames.std(axis=0) for x in X]
    encoder = MotionTreeEncoder(
        max_depth=3, layers="all", moment_pyramid=(1, 2, 4), standardize=False, sparse_output=False
    ).fit(scaled)
    vocabulary = encoder.transform(scaled)
    covariances = np.array(
        [np.cov(s, rowvar=False, bias=True)[np.triu_indices(s.shape[1])] for s in scaled]
    )
    root = lambda F: (F - F.mean(axis=0)) / np.sqrt(np.where(F.std(axis=0) > 0, F.std(axis=0), 1.0))  # noqa: E731
    columns = np.hstack([root(vocabulary), 0.5 * root(covariances)])
    np.testing.assert_allclose(model.transform(X), columns, atol=1e-10)
    span = _span(columns)
    head = LogisticRegression(C=1.0, max_iter=1000).fit(columns @ span, y)
    np.testing.assert_allclose(
        model.predict_proba(X), head.predict_proba(columns @ span), atol=1e-10
    )
    # weight 0 leaves the covariances out
    assert (
        clone(model).set_params(covariance_weight=0.0).fit(X, y).transform(X).shape[1]
        == vocabulary.shape[1]
    )
