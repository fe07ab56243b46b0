"""Pruning efficiency, recall and the scorers against hand-counted examples."""

import numpy as np
import pytest
from sklearn.pipeline import make_pipeline
from sklearn.preprocessing import FunctionTransformer

from skmotion.datasets import make_repeated_motions
from skmotion.metrics import (
    make_pruning_scorer,
    make_search_scorer,
    pruning_efficiency,
    pruning_scorer,
    recall,
    recall_scorer,
)
from skmotion.neighbors import IntervalIndexNeighbors

Y_STORED = np.array(["a", "a", "a", "b", "b", "c"])


def test_hand_counted():
    candidates = [[0, 1, 3], [3, 5], [0, 1, 2, 3, 4, 5]]
    y_query = ["a", "b", "c"]
    # a: 1 of 3 irrelevant returned -> 2/3 pruned, 2/3 of the a's found
    # b: 1 of 4 irrelevant returned -> 3/4 pruned, 1/2 of the b's found
    # c: everything returned -> 0 pruned, 1/1 found
    assert pruning_efficiency(candidates, y_query, Y_STORED) == pytest.approx(
        (2 / 3 + 3 / 4 + 0) / 3
    )
    assert recall(candidates, y_query, Y_STORED) == pytest.approx((2 / 3 + 1 / 2 + 1) / 3)


def test_queries_that_are_stored_clips_leave_themselves_out():
    # Query 0 is stored clip 0 (an "a"): the other a's are 1 and 2, irrelevant 3, 4, 5.
    candidates = [[0, 1, 4]]
    assert recall(candidates, ["a"], Y_STORED, query_ids=[0]) == pytest.approx(1 / 2)
    assert pruning_efficiency(candidates, ["a"], Y_STORED, query_ids=[0]) == pytest.approx(2 / 3)
    # Clip 5 is the only "c": no similar clip, so recall is undefined for it.
    assert np.isnan(recall([[0]], ["c"], Y_STORED, query_ids=[5]))
    assert recall([[0], [1, 2]], ["c", "a"], Y_STORED, query_ids=[5, 0]) == 1.0


def test_unknown_query_label_has_only_irrelevant_clips():
    assert pruning_efficiency([[0, 3]], ["z"], Y_STORED) == pytest.approx(4 / 6)
    assert np.isnan(recall([[0, 3]], ["z"], Y_STORED))
    assert np.isnan(pruning_efficiency([[0]], ["a"], ["a", "a"]))


def test_errors():
    with pytest.raises(ValueError, match="candidates holds 2 sets, but y_query has 1"):
        recall([[0], [1]], ["a"], Y_STORED)
    with pytest.raises(ValueError, match="query_ids has 2 ids"):
        recall([[0]], ["a"], Y_STORED, query_ids=[0, 1])
    with pytest.raises(ValueError, match="min_recall"):
        make_pruning_scorer(1.5)


@pytest.fixture(scope="module")
def fitted():
    data = make_repeated_motions(
        n_motions_per_class=2, n_repeats=4, duration=(1.5, 2.5), random_state=1
    )
    train = np.arange(len(data.clips)) % 4 != 0
    clips_train = [c for c, t in zip(data.clips, train) if t]
    clips_test = [c for c, t in zip(data.clips, train) if not t]
    return data.target[train], clips_train, data.target[~train], clips_test


def test_scorers_on_an_index_and_a_pipeline(fitted):
    y_train, X_train, y_test, X_test = fitted
    index = IntervalIndexNeighbors(n_levels=5, epsilon=0.8).fit(X_train, y_train)
    candidates = index.candidates(X_test)
    assert pruning_scorer(index, X_test, y_test) == pruning_efficiency(candidates, y_test, y_train)
    assert recall_scorer(index, X_test, y_test) == recall(candidates, y_test, y_train)
    # In a Pipeline, the steps before the index transform the queries first.
    scale = FunctionTransformer(lambda X: [2.0 * c for c in X])
    pipe = make_pipeline(scale, IntervalIndexNeighbors(n_levels=5, epsilon=0.8)).fit(
        X_train, y_train
    )
    assert pruning_scorer(pipe, X_test, y_test) == pytest.approx(
        pruning_scorer(index, X_test, y_test)
    )


def test_bounded_scorer_rewards_pruning_only_at_the_recall_bound(fitted):
    y_train, X_train, y_test, X_test = fitted
    index = IntervalIndexNeighbors(n_levels=5, epsilon=0.5).fit(X_train, y_train)
    pruning, found = pruning_scorer(index, X_test, y_test), recall_scorer(index, X_test, y_test)
    assert make_pruning_scorer(min_recall=found)(index, X_test, y_test) == pruning
    assert make_pruning_scorer(min_recall=min(1.0, found + 0.01))(
        index, X_test, y_test
    ) == pytest.approx(found - 1)
    assert "min_recall=0.9" in repr(make_pruning_scorer(0.9))


def test_search_scorer_gives_the_three_scores_at_once(fitted):
    y_train, X_train, y_test, X_test = fitted
    for epsilon in (0.5, 1.0):
        index = IntervalIndexNeighbors(n_levels=5, epsilon=epsilon).fit(X_train, y_train)
        scores = make_search_scorer(0.9)(index, X_test, y_test)
        assert scores == {
            "pruning": pruning_scorer(index, X_test, y_test),
            "recall": recall_scorer(index, X_test, y_test),
            "pruning_at_recall": make_pruning_scorer(0.9)(index, X_test, y_test),
        }
        for name, value in scores.items():  # one factory: each score alone is the dict's entry
            assert make_search_scorer(0.9, score=name)(index, X_test, y_test) == value
    assert "min_recall=0.8" in repr(make_search_scorer(0.8))
    with pytest.raises(ValueError, match="min_recall"):
        make_search_scorer(-0.1)
    with pytest.raises(ValueError, match="score"):
        make_search_scorer(score="precision")
