"""IntervalIndexNeighbors against brute-force references, sklearn's and the clip checks."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from sklearn.model_selection import GridSearchCV, GroupKFold
from sklearn.utils.estimator_checks import parametrize_with_checks

from skmotion.datasets import load_uea, make_motions, make_repeated_motions
from skmotion.decomposition import SVDFeatureExtractor
from skmotion.metrics import (
    make_pruning_scorer,
    pruning_efficiency,
    pruning_scorer,
    recall,
    recall_scorer,
)
from skmotion.neighbors import IntervalIndexNeighbors, pairwise_psi
from skmotion.neighbors._interval_neighbors import learn_delta
from tests.clip_conformance import ClipCase, parametrize_with_clip_checks
from tests.neighbors.test_interval_index import brute_force_candidates


def _clips():
    data = make_motions(
        n_clips_per_class=3, classes=["walk", "wave", "squat"], duration=(1.0, 1.5), random_state=0
    )
    return [c[:, 6:] for c in data.clips], data.target_names[data.target]


@parametrize_with_clip_checks(
    [
        ClipCase(
            IntervalIndexNeighbors(n_levels=3),
            _clips,
            param_grid={"epsilon": [0.8, 1.2], "n_levels": [2, 3]},
        ),
        ClipCase(
            IntervalIndexNeighbors(
                n_levels=2, n_neighbors=3, features=SVDFeatureExtractor(weighting="first_two")
            ),
            _clips,
        ),
    ]
)
def test_clip_conformance(check):
    check()


@parametrize_with_checks([IntervalIndexNeighbors(n_levels=2)])
def test_sklearn_checks_on_feature_vectors(estimator, check):
    check(estimator)


@pytest.fixture(scope="module")
def repeated():
    data = make_repeated_motions(
        n_motions_per_class=3, n_repeats=4, duration=(1.5, 2.5), random_state=0
    )
    return data.clips, data.target


def test_delta_is_learned_from_labels():
    features = np.array([[0.0, 1.0], [0.3, 0.9], [1.0, 0.0], [1.1, 0.5], [5.0, 5.0]])
    labels = np.array([0, 0, 1, 1, 2])  # label 2 has one clip: no spread to learn
    np.testing.assert_allclose(learn_delta(features, labels, 1.0), [0.3, 0.5])
    np.testing.assert_allclose(learn_delta(features, labels, 0.0), [0.1, 0.1])
    index = IntervalIndexNeighbors(n_levels=2, epsilon=0.5).fit(features, labels)
    np.testing.assert_allclose(index.delta_, [0.3, 0.5])
    np.testing.assert_allclose(index.index_.radius, [0.15, 0.25])
    # Level 0 spans [0, 5] in entries of width 0.15: ceil(5 / 0.15) = 34 of them.
    assert index.index_.n_entries == [34, 20]


@given(st.integers(0, 10_000), st.integers(1, 30), st.sampled_from([0.0, 0.5, 0.9, 1.0]))
def test_delta_equals_a_loop_over_the_labels(seed, n_labels, quantile):
    rng = np.random.default_rng(seed)
    features = rng.normal(size=(40, 3))
    labels = rng.choice([f"m{i}" for i in range(n_labels)], size=40)
    spreads = [
        np.ptp(features[labels == g], axis=0)
        for g in np.unique(labels)
        if np.count_nonzero(labels == g) > 1
    ]
    expected = np.quantile(spreads, quantile, axis=0) if spreads else np.zeros(3)
    np.testing.assert_allclose(
        learn_delta(features, labels, quantile), expected, rtol=1e-12, atol=1e-15
    )


def _brute_force(index, queries):
    edges, radius = index.index_.edges, index.index_.radius
    return [brute_force_candidates(edges, radius, index._stored["tree"], q) for q in queries]


@given(
    st.integers(0, 10_000),
    st.integers(1, 4),
    st.sampled_from([0.3, 0.7, 1.0, 1.5]),
    st.sampled_from([0.5, 1.0]),
    st.sampled_from([3, 64]),
)
def test_candidates_are_the_overlapping_clips_at_every_level(
    seed, n_levels, epsilon, quantile, max_entries
):
    rng = np.random.default_rng(seed)
    X = rng.normal(size=(40, 5))
    y = rng.integers(0, 4, size=40)
    index = IntervalIndexNeighbors(
        n_levels=n_levels, epsilon=epsilon, delta_quantile=quantile, max_entries=max_entries
    ).fit(X, y)
    queries = np.vstack([rng.normal(size=(15, 5)) * 1.5, X[:5]])
    found = index.candidates(queries)
    assert [f.tolist() for f in found] == _brute_force(index, queries[:, :n_levels])
    # With epsilon >= 1 and the paper's delta, stored clips find every clip of their label.
    if epsilon >= 1 and quantile == 1.0:
        for i, f in enumerate(index.candidates()):
            np.testing.assert_array_equal(
                np.intersect1d(f, np.flatnonzero(y == y[i])),
                np.setdiff1d(np.flatnonzero(y == y[i]), [i]),
            )


def test_recall_is_one_by_construction_on_clips(repeated):
    clips, target = repeated
    index = IntervalIndexNeighbors(n_levels=6, epsilon=1.0).fit(clips, target)
    ids = np.arange(len(clips))
    candidates = index.candidates()
    assert recall(candidates, target, target, query_ids=ids) == 1.0
    assert pruning_efficiency(candidates, target, target, query_ids=ids) > 0.5
    assert all(i not in c for i, c in zip(ids, candidates))


def test_kneighbors_with_all_candidates_is_the_brute_force_psi_ranking(repeated):
    clips, target = repeated
    queries = clips[::5]
    index = IntervalIndexNeighbors(n_levels=4, epsilon=1e6, n_neighbors=5).fit(clips, target)
    assert all(len(c) == len(clips) for c in index.candidates(queries))
    distances, neighbours = index.kneighbors(queries)
    reference = 1 - pairwise_psi(queries, clips)
    order = np.argsort(reference, axis=1, kind="stable")[:, :5]
    np.testing.assert_array_equal(neighbours, order)
    # The index finds the leading eigenpairs iteratively (residual <= 1e-9 of the largest).
    np.testing.assert_allclose(distances, np.take_along_axis(reference, order, axis=1), atol=1e-8)
    # X=None: every stored clip against the others.
    distances, neighbours = index.kneighbors(n_neighbors=3)
    loo = 1 - pairwise_psi(clips)
    np.fill_diagonal(loo, np.inf)
    np.testing.assert_array_equal(neighbours, np.argsort(loo, axis=1, kind="stable")[:, :3])


def test_kneighbors_ranks_only_candidates_and_falls_back_when_too_few(repeated):
    clips, target = repeated
    index = IntervalIndexNeighbors(n_levels=6, epsilon=0.5).fit(clips, target)
    queries = clips[1::3]
    found = index.candidates(queries)
    psi_distances = 1 - pairwise_psi(queries, clips)
    distances, neighbours = index.kneighbors(queries, n_neighbors=2)
    for q, (cands, row) in enumerate(zip(found, neighbours)):
        pool = cands if len(cands) >= 2 else np.arange(len(clips))
        best = pool[np.argsort(psi_distances[q, pool], kind="stable")[:2]]
        np.testing.assert_array_equal(row, best)
    assert np.all(np.diff(distances, axis=1) >= 0)


def test_euclidean_ranking_on_feature_vectors():
    rng = np.random.default_rng(0)
    X, y = rng.normal(size=(60, 6)), rng.integers(0, 3, size=60)
    queries = rng.normal(size=(10, 6))
    index = IntervalIndexNeighbors(n_levels=3, epsilon=0.8, n_neighbors=4).fit(X, y)
    assert index.effective_metric_ == "euclidean"
    distances, neighbours = index.kneighbors(queries)
    for q, cands in enumerate(index.candidates(queries)):
        pool = cands if len(cands) >= 4 else np.arange(60)
        d = np.linalg.norm(X[pool] - queries[q], axis=1)
        np.testing.assert_array_equal(neighbours[q], pool[np.argsort(d, kind="stable")[:4]])
        np.testing.assert_allclose(distances[q], np.sort(d)[:4])


def test_seven_levels_with_filtered_levels_rank_exactly_one_query_at_a_time():
    # Default widths on 7 components: an item meets ~3 entries per level, so only
    # the first levels are materialised and the rest filter; the answers are the
    # brute-force ranking of each query's candidates (the paper's leaf), and one
    # query per call (the fast validation path) answers as the batch does.
    rng = np.random.default_rng(1)
    centers = rng.normal(size=(100, 8)) * 3
    y = rng.integers(0, 100, 2000)
    X = centers[y] + rng.normal(scale=0.3, size=(2000, 8))
    queries = centers[rng.integers(0, 100, 40)] + rng.normal(scale=0.3, size=(40, 8))
    index = IntervalIndexNeighbors(n_neighbors=3, random_state=0).fit(X, y)
    assert index.index_._n_tree < index.n_levels_
    distances, neighbours = index.kneighbors(queries)
    for q, cands in enumerate(index.candidates(queries)):
        assert cands.tolist() == brute_force_candidates(
            index.index_.edges, index.index_.radius, X, queries[q]
        )
        pool = cands if len(cands) >= 3 else np.arange(len(X))
        d = np.linalg.norm(X[pool] - queries[q], axis=1)
        np.testing.assert_array_equal(neighbours[q], pool[np.argsort(d, kind="stable")[:3]])
        np.testing.assert_allclose(distances[q], np.sort(d)[:3], rtol=1e-12)
        one_d, one_i = index.kneighbors(queries[q : q + 1])
        np.testing.assert_array_equal(one_i[0], neighbours[q])
        np.testing.assert_array_equal(one_d[0], distances[q])
    # The validation a query skips is still done where it matters.
    with pytest.raises(ValueError, match="NaN"):
        index.kneighbors(np.full((1, 8), np.nan))
    with pytest.raises(ValueError, match="features"):
        index.kneighbors(np.zeros((1, 5)))
    np.testing.assert_array_equal(index.kneighbors(queries[:5].tolist())[1], neighbours[:5])


def test_predict_votes_among_neighbours(repeated):
    clips, target = repeated
    index = IntervalIndexNeighbors(n_levels=5, n_neighbors=3).fit(clips, target)
    proba = index.predict_proba(clips[:8])
    neighbours = index.kneighbors(clips[:8], return_distance=False)
    for row, ids in zip(proba, neighbours):
        expected = (
            np.bincount(np.searchsorted(index.classes_, target[ids]), minlength=len(index.classes_))
            / 3
        )
        np.testing.assert_allclose(row, expected)
    np.testing.assert_array_equal(index.predict(clips[:8]), index.classes_[proba.argmax(axis=1)])


def test_insert_adds_clips_without_rebuilding(repeated):
    clips, target = repeated
    # The first 30 clips hold 8 of the 21 motions: the others are new labels.
    index = IntervalIndexNeighbors(n_levels=5, epsilon=0.9).partial_fit(
        clips[:30], target[:30], classes=target
    )
    edges = [e.copy() for e in index.index_.edges]
    index.insert(clips[30:], target[30:])
    assert index.n_samples_fit_ == len(clips)
    for before, after in zip(edges, index.index_.edges):
        np.testing.assert_array_equal(before, after)
    queries = index.feature_extractor_.transform(clips)[:, :5]
    assert [c.tolist() for c in index.candidates(clips)] == _brute_force(index, queries)
    np.testing.assert_array_equal(index.labels_, target)
    # Inserting clip by clip gives the same index.
    one_by_one = IntervalIndexNeighbors(n_levels=5, epsilon=0.9).partial_fit(
        clips[:30], target[:30], classes=target
    )
    for i in range(30, len(clips)):
        one_by_one.partial_fit(clips[i : i + 1], target[i : i + 1])
    for a, b in zip(one_by_one.candidates(clips), index.candidates(clips)):
        np.testing.assert_array_equal(a, b)


def test_insert_and_query_errors(repeated):
    clips, target = repeated
    index = IntervalIndexNeighbors(n_levels=3).fit(clips, target)
    with pytest.raises(ValueError, match=r"labels \[99\] are not among the classes"):
        index.insert(clips[:2], [0, 99])
    with pytest.raises(ValueError, match="fitted on clips"):
        index.candidates(np.zeros((2, 75)))
    with pytest.raises(ValueError, match="n_neighbors must be an integer from 1 to"):
        index.kneighbors(clips[:2], n_neighbors=len(clips) + 1)
    with pytest.raises(ValueError, match="y has 3 labels"):
        IntervalIndexNeighbors(n_levels=3).fit(clips, target[:3])
    with pytest.raises(ValueError, match=r"n_levels=7 is more than the 3 feature\(s\) of X"):
        IntervalIndexNeighbors(n_levels=7).fit(np.zeros((5, 3)), [0, 0, 1, 1, 1])


def test_grid_search_over_epsilon_and_n_levels_with_the_scorers(repeated):
    clips, target = repeated
    groups = np.arange(len(clips)) % 4  # one repetition of each motion per fold
    search = GridSearchCV(
        IntervalIndexNeighbors(),
        {"epsilon": [0.6, 1.2], "n_levels": [3, 5]},
        scoring={
            "pruning": pruning_scorer,
            "recall": recall_scorer,
            "bounded": make_pruning_scorer(0.95),
        },
        refit="bounded",
        cv=GroupKFold(4),
    ).fit(clips, target, groups=groups)
    results = search.cv_results_
    for i in range(len(results["params"])):
        pruning, found = results["mean_test_pruning"][i], results["mean_test_recall"][i]
        assert 0 <= pruning <= 1 and 0 <= found <= 1
    # epsilon widens the entries: more candidates, less pruning, more recall.
    by = {(p["epsilon"], p["n_levels"]): i for i, p in enumerate(results["params"])}
    for levels in (3, 5):
        wide, narrow = by[(1.2, levels)], by[(0.6, levels)]
        assert results["mean_test_pruning"][wide] <= results["mean_test_pruning"][narrow]
        assert results["mean_test_recall"][wide] >= results["mean_test_recall"][narrow]
    assert search.best_estimator_.n_samples_fit_ == len(clips)


def test_on_uea_data(shared_data):
    train = load_uea("BasicMotions", subset="train", data_home=shared_data)
    test = load_uea("BasicMotions", subset="test", data_home=shared_data)
    index = IntervalIndexNeighbors(n_levels=5, epsilon=1.0).fit(train.clips, train.target)
    ids = np.arange(len(train.clips))
    assert recall(index.candidates(), train.target, train.target, query_ids=ids) == 1.0
    # 1-NN by psi among the candidates recognises the held-out recordings.
    assert index.score(test.clips, test.target) >= 0.8


def _six_channel_data(n_per_class=8, random_state=0):
    """BasicMotions-shaped: 4 classes, 6 channels (accelerometer + gyroscope), 100 frames."""
    rng = np.random.default_rng(random_state)
    t = np.linspace(0, 2 * np.pi, 100)[:, None]
    clips, labels = [], []
    for label in range(4):
        freq = rng.uniform(1, 4, size=6)
        gain = rng.uniform(0.2, 2.0, size=6)
        for _ in range(n_per_class):
            wave = np.sin((label + 1) * freq * t + rng.uniform(0, 0.3, size=6)) * gain
            clips.append(wave + 0.05 * rng.normal(size=wave.shape))
            labels.append(label)
    return clips, np.array(labels)


def test_defaults_adapt_to_six_channel_data():
    clips, labels = _six_channel_data()
    index = IntervalIndexNeighbors().fit(clips, labels)
    # 7 levels asked by default; the first singular vector of 6 channels gives 6 components.
    assert index.n_levels_ == 6 and index.index_.n_levels == 6
    assert index.feature_extractor_.n_components_ == 6
    assert index.score(clips, labels) == 1.0
    two = IntervalIndexNeighbors(features=SVDFeatureExtractor(weighting="first_two"))
    assert two.fit(clips, labels).n_levels_ == 7
    with pytest.raises(ValueError, match=r"n_levels=7 is more than the 6 SVD feature components"):
        IntervalIndexNeighbors(n_levels=7).fit(clips, labels)


def test_levels_come_from_n_levels_or_features_never_silently_overridden():
    clips, labels = _six_channel_data(n_per_class=4)
    by_features = IntervalIndexNeighbors(features=SVDFeatureExtractor(n_components=3))
    assert by_features.fit(clips, labels).n_levels_ == 3
    both = IntervalIndexNeighbors(n_levels=4, features=SVDFeatureExtractor(n_components=4))
    assert both.fit(clips, labels).n_levels_ == 4
    with pytest.raises(ValueError, match=r"n_levels=2 and features.n_components=5 disagree"):
        IntervalIndexNeighbors(n_levels=2, features=SVDFeatureExtractor(n_components=5)).fit(
            clips, labels
        )
    # The index's feature vectors are the public projection's, as a lone extractor gives them.
    alone = SVDFeatureExtractor(n_components=3).fit(clips)
    np.testing.assert_allclose(
        by_features.feature_extractor_.transform(clips), alone.transform(clips), atol=1e-12
    )


@pytest.mark.parametrize("scale", [1e-300, 1e300])
def test_extreme_but_finite_clips_give_the_same_answers(repeated, scale):
    clips, target = repeated
    index = IntervalIndexNeighbors(n_levels=4, n_neighbors=3).fit(clips, target)
    scaled = [c * scale for c in clips]
    big = IntervalIndexNeighbors(n_levels=4, n_neighbors=3).fit(scaled, target)
    np.testing.assert_allclose(big.delta_, index.delta_, atol=1e-10)
    np.testing.assert_array_equal(
        big.kneighbors(return_distance=False), index.kneighbors(return_distance=False)
    )
    # Mixed scales: a scaled query finds what the plain query finds.
    distances, found = index.kneighbors(scaled[:5])
    expected_distances, expected = index.kneighbors(clips[:5])
    np.testing.assert_array_equal(found, expected)
    np.testing.assert_allclose(distances, expected_distances, atol=1e-10)


def test_verbose_reports_the_stages_of_fit_and_is_silent_by_default(repeated, capsys):
    clips, target = repeated
    IntervalIndexNeighbors(n_levels=3).fit(clips, target)
    assert capsys.readouterr().err == ""
    IntervalIndexNeighbors(n_levels=3, verbose=1).fit(clips, target)
    err = capsys.readouterr().err
    for stage in ("decomposing the clips", "learning the entry widths", "building the tree"):
        assert stage in err


def test_an_unfitted_index_pickles():
    """joblib and Dask send unfitted clones to their workers: they must load there."""
    import pickle

    index = pickle.loads(pickle.dumps(IntervalIndexNeighbors(epsilon=0.5)))
    assert index.get_params()["epsilon"] == 0.5
    assert not hasattr(index, "_stored")
