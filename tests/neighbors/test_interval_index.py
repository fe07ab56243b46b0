"""The interval index against hand-worked trees and a brute-force reference."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from skmotion.neighbors._interval_index import IntervalIndex, entry_edges


def brute_force_candidates(edges, radius, items, query):
    """All items whose covering interval overlaps the query's entry at every level.

    Written from the definition with explicit loops: entry ``j`` of a level is the
    closed interval ``[b_j, b_{j+1}]`` with ``b_0 = -inf`` and ``b_n = +inf``; the
    query's entry is the one with ``b_j <= c < b_{j+1}``.
    """
    out = []
    for item_id, item in enumerate(items):
        keep = True
        for level, inner in enumerate(edges):
            bounds = [-np.inf, *inner.tolist(), np.inf]
            c = query[level]
            j = next(j for j in range(len(bounds) - 1) if bounds[j] <= c < bounds[j + 1])
            lo, hi = item[level] - radius[level], item[level] + radius[level]
            if not (bounds[j] <= hi and bounds[j + 1] >= lo):
                keep = False
                break
        if keep:
            out.append(item_id)
    return out


def test_hand_worked_two_levels():
    # Level 0: entries (-inf,0.25] [0.25,0.5] [0.5,0.75] [0.75,inf), radius 0.1.
    # Level 1: entries (-inf,0] [0,inf), radius 0.05.
    index = IntervalIndex([np.array([0.25, 0.5, 0.75]), np.array([0.0])], radius=[0.1, 0.05])
    items = np.array(
        [
            [0.30, 0.50],  # level 0 entries 0-1, level 1 entry 1
            [0.45, 0.02],  # level 0 entries 1-2, level 1 entries 0-1
            [0.90, -0.5],  # level 0 entry 3, level 1 entry 0
            [0.62, -0.04],  # level 0 entry 2, level 1 entries 0-1
        ]
    )
    index.insert(items)
    queries = {
        (0.1, 0.3): [0],
        (0.3, -0.3): [1],
        (0.3, 0.3): [0, 1],
        (0.55, 0.1): [1, 3],
        (0.55, -0.1): [1, 3],
        (0.8, -0.1): [2],
        (0.8, 0.1): [],
        (0.5, 0.0): [1, 3],  # on a boundary: the entry above
    }
    for query, expected in queries.items():
        assert index.candidates(np.array([query]))[0].tolist() == expected, query
    # Leaves: item 0 in 2 (0,1),(1,1); item 1 in 4; item 2 in 1; item 3 in 2.
    assert index.n_stored() == 2 + 4 + 1 + 2
    assert index.n_nodes == [1, 4, 6]


def test_entry_edges_follow_width_and_cap():
    np.testing.assert_allclose(entry_edges(-1.0, 1.0, 0.5, 100), [-0.5, 0.0, 0.5])
    # ceil(2 / 0.3) = 7 entries of width 0.3, the last one ending past 1.0.
    np.testing.assert_allclose(entry_edges(-1.0, 1.0, 0.3, 100), -1.0 + 0.3 * np.arange(1, 7))
    np.testing.assert_allclose(entry_edges(0.0, 1.0, 0.0, 5), [0.2, 0.4, 0.6, 0.8])
    assert entry_edges(0.3, 0.3, 0.1, 5).size == 0


def test_rejects_bad_structure():
    with pytest.raises(ValueError, match="strictly increasing"):
        IntervalIndex([np.array([0.5, 0.2])], radius=[0.1])
    with pytest.raises(ValueError, match="one non-negative value per level"):
        IntervalIndex([np.array([0.5])], radius=[0.1, 0.2])
    index = IntervalIndex([np.array([0.5]), np.array([0.5])], radius=[0.1, 0.1])
    with pytest.raises(ValueError, match="at least 2 components"):
        index.insert(np.zeros((3, 1)))


# Values on a coarse grid so that components often fall exactly on entry
# boundaries and covering intervals often just touch them.
grid = st.integers(-8, 8).map(lambda v: v / 8)


@st.composite
def index_case(draw):
    n_levels = draw(st.integers(1, 4))
    edges = [np.array(sorted(draw(st.sets(grid, max_size=5)))) for _ in range(n_levels)]
    radius = np.array(
        [draw(st.sampled_from([0.0, 0.125, 0.25, 0.3, 0.6])) for _ in range(n_levels)]
    )
    vector = st.lists(grid | st.floats(-1.5, 1.5), min_size=n_levels, max_size=n_levels)
    items = np.array(draw(st.lists(vector, min_size=1, max_size=25)), dtype=float)
    queries = np.array(draw(st.lists(vector, min_size=1, max_size=10)), dtype=float)
    split = draw(st.integers(0, len(items)))
    return edges, radius, items, queries, split


@given(index_case())
def test_candidates_equal_brute_force(case):
    edges, radius, items, queries, split = case
    index = IntervalIndex(edges, radius)
    # Two insertions (the second into a non-empty tree) must act as one.
    index.insert(items[:split])
    index.insert(items[split:])
    assert index.n_items == len(items)
    for query, found in zip(queries, index.candidates(queries)):
        assert found.tolist() == brute_force_candidates(edges, radius, items, query)
    # Every item is found by a query equal to itself.
    for item_id, found in enumerate(index.candidates(items)):
        assert item_id in found


@given(index_case())
def test_leaves_hold_each_item_in_prod_of_spans(case):
    edges, radius, items, _, _ = case
    index = IntervalIndex(edges, radius)
    index.insert(items)
    first, last = index.covering_entries(items)
    assert index.n_stored() == int(np.prod(last - first + 1, axis=1).sum())


def test_large_insertions_are_split_and_agree(monkeypatch):
    from skmotion.neighbors import _interval_index as module

    rng = np.random.default_rng(0)
    edges = [np.linspace(-1, 1, 9)[1:-1]] * 3
    items, queries = rng.uniform(-1, 1, (300, 3)), rng.uniform(-1, 1, (50, 3))
    whole = IntervalIndex(edges, [0.3] * 3)
    whole.insert(items)
    monkeypatch.setattr(module, "_PAIRS_PER_STEP", 64)
    pieces = IntervalIndex(edges, [0.3] * 3)
    pieces.insert(items)
    for a, b in zip(whole.candidates(queries), pieces.candidates(queries)):
        np.testing.assert_array_equal(a, b)
    assert whole.n_nodes == pieces.n_nodes


@given(st.integers(0, 10_000), st.integers(1, 5), st.sampled_from([2, 5, 64]))
def test_one_query_path_equals_the_batched_path(seed, n_levels, max_entries):
    rng = np.random.default_rng(seed)
    items = rng.normal(size=(60, n_levels))
    radius = rng.uniform(0.0, 0.5, size=n_levels)
    edges = [
        entry_edges(items[:, i].min(), items[:, i].max(), 0.3, max_entries) for i in range(n_levels)
    ]
    index = IntervalIndex(edges, radius)
    index.insert(items[:40])
    # Queries: random, far outside the range, and exactly on entry boundaries.
    on_edges = np.stack([rng.choice(e, size=10) if len(e) else np.zeros(10) for e in edges], axis=1)
    queries = np.vstack([rng.normal(size=(20, n_levels)) * 2, on_edges, items[40:] * 10])
    batched = index._leaf_of_batch(queries)
    one_by_one = np.concatenate([index.leaf_of(q[None]) for q in queries])
    np.testing.assert_array_equal(one_by_one, batched)
    # Still equal after more items grew the tables.
    index.insert(items[40:])
    np.testing.assert_array_equal(
        [index.leaf_of(q[None])[0] for q in queries], index._leaf_of_batch(queries)
    )


@given(st.integers(0, 10_000), st.integers(1, 6))
def test_items_of_many_leaves_equal_each_leafs_items(seed, n_insertions):
    # Several insertions leave several leaf blocks (merged or not); the batched
    # look-up equals leaf_items leaf by leaf, for empty and unknown leaves too.
    rng = np.random.default_rng(seed)
    edges = [np.linspace(-1, 1, 6)[1:-1]] * 2
    index = IntervalIndex(edges, [0.2, 0.3])
    assert [c.tolist() for c in index.items_of_leaves(np.array([0, 1]))] == [[], []]
    for size in rng.integers(1, 30, size=n_insertions):
        index.insert(rng.uniform(-1.2, 1.2, (size, 2)))
    leaves = np.r_[np.arange(index._n_leaves + 2), rng.integers(0, index._n_leaves, 20)]
    for leaf, items in zip(leaves, index.items_of_leaves(leaves)):
        assert items.dtype == np.intp
        np.testing.assert_array_equal(items, index.leaf_items(leaf))
    np.testing.assert_array_equal(
        index.leaf_sizes(leaves), [len(index.leaf_items(leaf)) for leaf in leaves]
    )


@given(st.integers(0, 10_000), st.integers(1, 6))
def test_one_leafs_items_equal_those_of_the_many_leaf_look_up(seed, n_insertions):
    # One query's leaf takes a route of its own (a search per block, not the
    # bounds of many leaves); it must give what the many-leaf look-up gives.
    rng = np.random.default_rng(seed)
    index = IntervalIndex([np.linspace(-1, 1, 6)[1:-1]] * 2, [0.2, 0.3])
    for size in rng.integers(1, 30, size=n_insertions):
        index.insert(rng.uniform(-1.2, 1.2, (size, 2)))
    leaves = np.r_[np.arange(index._n_leaves + 2), rng.integers(0, index._n_leaves, 5)]
    for leaf, items in zip(leaves, index.items_of_leaves(leaves)):
        (alone,) = index.items_of_leaves(np.array([leaf]))
        assert alone.dtype == np.intp
        np.testing.assert_array_equal(alone, items)


@given(index_case())
def test_filtered_levels_equal_the_materialised_tree(case):
    # Materialising one level and filtering the others gives the paper's tree:
    # the same candidates, leaf sizes, node counts and pairs as materialising all.
    from skmotion.neighbors import _interval_index as module

    edges, radius, items, queries, split = case
    whole = IntervalIndex(edges, radius)
    whole.insert(items)
    original = module._LEAVES_PER_ITEM
    module._LEAVES_PER_ITEM = 0
    try:
        filtered = IntervalIndex(edges, radius)
    finally:
        module._LEAVES_PER_ITEM = original
    filtered.insert(items[:split])
    filtered.insert(items[split:])
    assert filtered._n_tree == 1
    leaves = filtered.leaf_of(queries)
    for a, b in zip(whole.candidates(queries), filtered.candidates(queries)):
        np.testing.assert_array_equal(a, b)
    for query, leaf in zip(queries, leaves):
        np.testing.assert_array_equal(filtered.leaf_of(query[None]), [leaf])
        np.testing.assert_array_equal(filtered.leaf_items(leaf), whole.candidates(query[None])[0])
    np.testing.assert_array_equal(
        filtered.leaf_sizes(leaves), whole.leaf_sizes(whole.leaf_of(queries))
    )
    assert filtered.n_nodes == whole.n_nodes
    assert filtered.n_stored() == whole.n_stored()


def test_seven_levels_of_three_entries_materialise_four():
    # An item meets 3 entries per level: 3^4 = 81 leaves per item are materialised,
    # not 3^7 = 2187; the deeper three levels are filtered.
    rng = np.random.default_rng(0)
    edges = [np.arange(1.0, 10.0)] * 7
    index = IntervalIndex(edges, [1.0] * 7)
    items = rng.uniform(0, 10, (200, 7))
    index.insert(items)
    assert index._n_tree == 4
    first, last = index.covering_entries(items)
    assert index.n_stored() == int(np.prod(last - first + 1, axis=1).sum())
    materialised = int(sum(len(block[2]) for block in index._blocks))
    assert materialised == int(np.prod((last - first + 1)[:, :4], axis=1).sum())
    queries = rng.uniform(0, 10, (30, 7))
    for query, found in zip(queries, index.candidates(queries)):
        assert found.tolist() == brute_force_candidates(edges, [1.0] * 7, items, query)
