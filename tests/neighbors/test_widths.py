"""The learned entry widths (target_recall) against brute-force truths."""

import itertools

import numpy as np
import pytest

from skmotion.datasets import make_repeated_motions
from skmotion.metrics import pruning_efficiency, recall
from skmotion.neighbors import IntervalIndexNeighbors, pairwise_psi
from skmotion.neighbors._interval_index import IntervalIndex, entry_edges
from skmotion.neighbors._widths import label_pairs, surviving, weighted_quantile


def test_label_pairs_are_every_ordered_pair_with_per_query_weights():
    labels = np.array([0, 1, 0, 2, 0, 1])
    first, second, weight = label_pairs(labels, 100, np.random.RandomState(0))
    expected = {(i, j) for i, j in itertools.permutations(range(6), 2) if labels[i] == labels[j]}
    assert set(zip(first.tolist(), second.tolist())) == expected and len(first) == len(expected)
    # Each query with a similar clip weighs 1 in all: a weighted share is a mean recall.
    per_query = np.bincount(first, weights=weight, minlength=6)
    np.testing.assert_allclose(per_query, [1, 1, 1, 0, 1, 1])
    drawn = label_pairs(labels, 3, np.random.RandomState(0))
    assert len(drawn[0]) == 3 and all(labels[a] == labels[b] and a != b for a, b in zip(*drawn[:2]))


def test_weighted_quantile_against_repetition():
    rng = np.random.default_rng(0)
    values = rng.normal(size=50)
    counts = rng.integers(1, 4, size=50)
    for q in (0.1, 0.5, 0.99, 1.0):
        expected = np.quantile(np.repeat(values, counts), q, method="inverted_cdf")
        assert weighted_quantile(values, counts.astype(float), q) == expected


@pytest.mark.parametrize("width_factor", [1.0, 2.0, 0.5])
def test_surviving_is_what_the_tree_returns(width_factor):
    rng = np.random.default_rng(1)
    features = rng.uniform(-1, 1, size=(60, 3))
    radius = np.array([0.2, 0.35, 0.1])
    low, high = features.min(axis=0), features.max(axis=0)
    edges = [entry_edges(low[i], high[i], width_factor * radius[i], 64) for i in range(3)]
    index = IntervalIndex(edges, radius)
    index.insert(features)
    found = index.candidates(features)
    query, stored = np.divmod(np.arange(60 * 60), 60)
    keep = surviving(features[query], features[stored], radius, low, high, 64, width_factor)
    truth = np.zeros(60 * 60, bool)
    for q, c in enumerate(found):
        truth[q * 60 + c] = True
    np.testing.assert_array_equal(keep, truth)


@pytest.fixture(scope="module")
def repeats():
    data = make_repeated_motions(n_motions_per_class=4, n_repeats=5, random_state=0)
    return data.clips, data.target


@pytest.mark.parametrize("target", [0.9, 0.99])
def test_target_recall_holds_on_the_training_clips(repeats, target):
    clips, target_labels = repeats
    index = IntervalIndexNeighbors(target_recall=target, random_state=0).fit(clips, target_labels)
    assert index.width_rule_ == "target_recall"
    ids = np.arange(len(clips))
    found = index.candidates()
    assert recall(found, target_labels, target_labels, query_ids=ids) >= target - 1e-12
    # Narrower than the paper's recall-1 rule, which keeps all the similar pairs.
    paper = IntervalIndexNeighbors(epsilon=1.0).fit(clips, target_labels)
    assert paper.width_rule_ == "epsilon"
    assert pruning_efficiency(found, target_labels, target_labels, query_ids=ids) >= (
        pruning_efficiency(paper.candidates(), target_labels, target_labels, query_ids=ids)
    )


def test_default_is_target_recall_099_and_rules_do_not_mix(repeats):
    clips, labels = repeats
    default = IntervalIndexNeighbors(random_state=0).fit(clips, labels)
    asked = IntervalIndexNeighbors(target_recall=0.99, random_state=0).fit(clips, labels)
    np.testing.assert_array_equal(default.radius_, asked.radius_)
    with pytest.raises(ValueError, match="give one rule"):
        IntervalIndexNeighbors(epsilon=1.0, target_recall=0.9).fit(clips, labels)


def test_similar_by_psi_keeps_the_psi_nearest_neighbour(repeats):
    clips, labels = repeats
    index = IntervalIndexNeighbors(target_recall=0.95, similar="psi", random_state=0)
    index.fit(clips, np.zeros(len(clips), int))  # one class: labels say nothing
    similarity = pairwise_psi(clips)
    np.fill_diagonal(similarity, -1)
    nearest = similarity.argmax(axis=1)
    found = index.candidates()
    kept = np.mean([n in c for n, c in zip(nearest, found)])
    assert kept >= 0.95
    assert np.mean([len(c) for c in found]) < 0.8 * (len(clips) - 1)  # and it prunes
