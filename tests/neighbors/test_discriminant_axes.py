"""IntervalIndexNeighbors(axes="discriminant"): the tree's levels on Fisher's discriminant axes."""

import pickle

import numpy as np
import pytest

from skmotion.datasets import make_repeated_motions
from skmotion.metrics import pruning_efficiency, recall
from skmotion.neighbors import IntervalIndexNeighbors


def _noisy_first_column(seed=0, n_labels=12, per_label=8):
    """Labels apart along column 1 only; column 0 (the leading one) is wide noise.

    The leading component tells the labels nothing, so a one-level tree on it
    cannot prune; the axis that separates them is column 1, by construction.
    """
    rng = np.random.default_rng(seed)
    labels = np.repeat(np.arange(n_labels), per_label)
    X = np.column_stack(
        [
            rng.normal(0.0, 10.0, len(labels)),
            labels + rng.normal(0.0, 0.05, len(labels)),
            rng.normal(0.0, 1.0, len(labels)),
        ]
    )
    return X, labels


def test_axes_find_the_separating_column():
    X, y = _noisy_first_column()
    train, query = np.arange(len(y)) % 8 != 0, np.arange(len(y)) % 8 == 0
    # epsilon 2: a held-out clip may fall a little outside its label's training range
    svd = IntervalIndexNeighbors(n_levels=1, epsilon=2.0).fit(X[train], y[train])
    lda = IntervalIndexNeighbors(n_levels=1, epsilon=2.0, axes="discriminant").fit(
        X[train], y[train]
    )
    axis = lda.axes_[:, 0] / np.linalg.norm(lda.axes_[:, 0])
    assert abs(axis[1]) > 0.999  # column 1, the only one the labels differ on
    found_svd, found_lda = svd.candidates(X[query]), lda.candidates(X[query])
    # twice each label's spread: every similar clip is found either way
    assert recall(found_svd, y[query], y[train]) == 1.0
    assert recall(found_lda, y[query], y[train]) == 1.0
    # ... but only the axis prunes: labels are 1 apart and spread 0.05 or so on it
    assert pruning_efficiency(found_lda, y[query], y[train]) > 0.8
    assert pruning_efficiency(found_svd, y[query], y[train]) < 0.2


def test_tree_is_the_svd_tree_of_the_projected_table():
    # The plumbing: fit, insert and every query go through the same axes, so the
    # index equals a plain index fitted on the projected table with the same radii.
    X, y = _noisy_first_column(seed=1)
    first = np.arange(len(y)) % 4 != 0  # fitted on; the rest inserted
    lda = IntervalIndexNeighbors(n_levels=2, epsilon=0.8, axes="discriminant")
    lda.fit(X[first], y[first])
    projected = X @ lda.axes_
    plain = IntervalIndexNeighbors(n_levels=2, epsilon=0.8).fit(projected[first], y[first])
    np.testing.assert_allclose(plain.radius_, lda.radius_)
    lda.insert(X[~first], y[~first])
    plain.insert(projected[~first], y[~first])
    for got, expected in zip(lda.candidates(X[::7]), plain.candidates(projected[::7])):
        np.testing.assert_array_equal(got, expected)
    for got, expected in zip(lda.candidates(), plain.candidates()):
        np.testing.assert_array_equal(got, expected)


def test_clips_prune_more_on_repetitions_and_pickle():
    data = make_repeated_motions(
        n_motions_per_class=3, n_repeats=6, duration=(1.5, 2.5), random_state=0
    )
    y = np.asarray(data.target)
    query = np.r_[y[1:] != y[:-1], True]  # the last repetition of each motion
    train = [c for c, q in zip(data.clips, query) if not q]
    queries = [c for c, q in zip(data.clips, query) if q]
    found = {}
    for axes in ("svd", "discriminant"):
        index = IntervalIndexNeighbors(target_recall=0.99, axes=axes, random_state=0)
        found[axes] = index.fit(train, y[~query]).candidates(queries)
    inputs = index.feature_extractor_.transform(queries)  # what the axes read
    assert index.axes_.shape == (inputs.shape[1], index.n_levels_)
    assert recall(found["discriminant"], y[query], y[~query]) >= 0.95
    assert pruning_efficiency(found["discriminant"], y[query], y[~query]) > pruning_efficiency(
        found["svd"], y[query], y[~query]
    )
    again = pickle.loads(pickle.dumps(index))
    np.testing.assert_array_equal(again.kneighbors(queries)[1], index.kneighbors(queries)[1])


def test_one_label_is_an_error():
    X = np.random.default_rng(0).normal(size=(10, 3))
    with pytest.raises(ValueError, match='axes="discriminant" needs two or more labels'):
        IntervalIndexNeighbors(n_levels=2, axes="discriminant").fit(X, np.zeros(10))


def test_pickles_from_before_the_parameter_load_with_svd_axes():
    X, y = _noisy_first_column()
    index = IntervalIndexNeighbors(n_levels=2, epsilon=1.0).fit(X, y)
    state = index.__getstate__()
    del state["axes"], state["axes_"]
    old = IntervalIndexNeighbors.__new__(IntervalIndexNeighbors)
    old.__setstate__(state)
    assert old.get_params()["axes"] == "svd"
    for got, expected in zip(old.candidates(X), index.candidates(X)):
        np.testing.assert_array_equal(got, expected)


def test_msrc12_repetitions_of_eight_people(shared_data):
    """Real Kinect gestures: similar = the same gesture by the same person.

    Measured (people 1-8, target_recall 0.96): discriminant axes prune 0.94 at
    held-out recall 0.97, the leading components 0.68 at 0.97.
    """
    path = shared_data / "msrc12" / "msrc12_sequences.npz"
    if not path.is_file():
        pytest.skip(f"{path} not found")
    from benchmarks._msrc12 import msrc12_repetitions

    data = msrc12_repetitions(path)
    keep = data.person <= 8
    label = (data.gesture * 100 + data.person)[keep]
    sequence = data.sequence[keep]
    clips = [c for c, k in zip(data.clips, keep) if k]
    query = np.r_[sequence[1:] != sequence[:-1], True]  # each sequence's last repetition
    stored = [c for c, q in zip(clips, query) if not q]
    queries = [c for c, q in zip(clips, query) if q]
    measured = {}
    for axes in ("svd", "discriminant"):
        index = IntervalIndexNeighbors(axes=axes, target_recall=0.96, random_state=0)
        found = index.fit(stored, label[~query]).candidates(queries)
        measured[axes] = (
            pruning_efficiency(found, label[query], label[~query]),
            recall(found, label[query], label[~query]),
        )
    assert measured["discriminant"][0] >= 0.9 and measured["discriminant"][1] >= 0.95
    assert measured["discriminant"][0] > measured["svd"][0] + 0.15
