"""pruning_ceiling against hand-worked examples and a brute-force search over radii."""

import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from skmotion.metrics import pruning_ceiling, pruning_efficiency, recall

Y_STORED = np.array(["a", "a", "b", "b", "c"])
DISTANCES = np.array(
    [
        [0.1, 0.6, 0.5, 0.9, 0.2],  # an "a": its far a (0.6) is beyond b 0.5 and c 0.2
        [0.3, 0.8, 0.2, 0.4, 0.7],  # a "b": its far b (0.4) is beyond a 0.3
    ]
)


def test_hand_worked_at_full_recall():
    # query a keeps radius 0.6: of b, b, c only b 0.9 is farther -> 1/3 pruned
    # query b keeps radius 0.4: of a, a, c, 0.8 and 0.7 are farther -> 2/3 pruned
    assert pruning_ceiling(DISTANCES, ["a", "b"], Y_STORED) == pytest.approx((1 / 3 + 2 / 3) / 2)


def test_hand_worked_trade_between_queries():
    # Mean recall 0.75 lets one query keep one of its two similar clips.
    # Shrinking query a to 0.1 prunes b 0.5, b 0.9, c 0.2: 3/3 (gain 2/3);
    # shrinking query b to 0.2 prunes 0.3 too: 3/3 (gain 1/3). Query a's step wins.
    got = pruning_ceiling(DISTANCES, ["a", "b"], Y_STORED, min_recall=0.75)
    assert got == pytest.approx((1 + 2 / 3) / 2)
    # Half a step is all that 0.875 allows: the bound takes half of query a's gain.
    half = pruning_ceiling(DISTANCES, ["a", "b"], Y_STORED, min_recall=0.875)
    assert half == pytest.approx((1 / 3 + 1 / 3 + 2 / 3) / 2)


def test_ties_keep_the_irrelevant_clip_at_the_radius():
    # The irrelevant clip at exactly the similar clip's distance is kept.
    assert pruning_ceiling([[0.5, 0.5, 0.7]], ["a"], ["a", "b", "b"]) == pytest.approx(0.5)


def test_queries_without_similar_or_irrelevant_clips():
    # A query with no similar stored clip keeps nothing: it prunes everything.
    assert pruning_ceiling([[0.4, 0.1]], ["z"], ["a", "b"]) == 1.0
    # With no irrelevant clip anywhere, pruning is undefined (as pruning_efficiency).
    assert np.isnan(pruning_ceiling([[0.4, 0.1]], ["a"], ["a", "a"]))


def test_bad_input_names_what_is_wrong():
    with pytest.raises(ValueError, match=r"shape \(1, 3\); expected .* \(1, 2\)"):
        pruning_ceiling([[0.1, 0.2, 0.3]], ["a"], ["a", "b"])
    with pytest.raises(ValueError, match=r"distances\[0, 1\] is NaN"):
        pruning_ceiling([[0.1, np.nan]], ["a"], ["a", "b"])


def _ball(row, radius):
    return np.flatnonzero(row <= radius)


def _brute(distances, y_query, y_stored, min_recall):
    """The best mean pruning over every choice of one radius per query."""
    if all((y_stored == q).all() for q in y_query):
        return np.nan  # no irrelevant clip: pruning is undefined
    options = [np.r_[np.unique(row), -np.inf] for row in distances]
    best = -np.inf
    for radii in itertools.product(*options):
        found = [_ball(row, r) for row, r in zip(distances, radii)]
        kept = recall(found, y_query, y_stored)
        if np.isnan(kept) or kept >= min_recall - 1e-12:
            best = max(best, pruning_efficiency(found, y_query, y_stored))
    return best


@settings(max_examples=60, deadline=None)
@given(
    data=st.data(),
    n_queries=st.integers(1, 3),
    n_stored=st.integers(2, 5),
    min_recall=st.sampled_from([1.0, 0.9, 0.75, 0.5]),
)
def test_equals_or_bounds_the_brute_force_best(data, n_queries, n_stored, min_recall):
    labels = st.sampled_from(["a", "b", "c"])
    y_stored = np.array(data.draw(st.lists(labels, min_size=n_stored, max_size=n_stored)))
    y_query = np.array(data.draw(st.lists(labels, min_size=n_queries, max_size=n_queries)))
    cells = st.integers(0, 6).map(lambda v: v / 6)  # small grid: ties happen
    rows = st.lists(cells, min_size=n_stored, max_size=n_stored)
    distances = np.array(data.draw(st.lists(rows, min_size=n_queries, max_size=n_queries)))
    got = pruning_ceiling(distances, y_query, y_stored, min_recall=min_recall)
    best = _brute(distances, y_query, y_stored, min_recall)
    if np.isnan(got):
        assert np.isnan(best)
        return
    if min_recall == 1.0:
        assert got == pytest.approx(best)
    else:  # the relaxation is above the best choice by at most one query's step
        n_other = np.sum([(y_stored != q).any() for q in y_query])
        assert best - 1e-9 <= got <= best + 1 / n_other + 1e-9
