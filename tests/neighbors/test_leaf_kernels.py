"""The compiled leaf kernels against plain references."""

import numpy as np
from hypothesis import given
from hypothesis import strategies as st
from scipy.spatial.distance import cdist
from skmotion.neighbors._leaf_kernels import euclidean_block, filter_items, smallest_columns


@given(st.integers(0, 10_000), st.integers(1, 12))
def test_euclidean_block_equals_cdist(seed, n_features):
    rng = np.random.default_rng(seed)
    query, stored = rng.normal(size=(7, n_features)), rng.normal(size=(30, n_features))
    rows, columns = rng.integers(0, 7, 4), rng.permutation(30)[:11]
    expected = cdist(query[rows], stored[columns])
    np.testing.assert_allclose(euclidean_block(query, stored, rows, columns), expected, rtol=1e-12)


def test_euclidean_block_keeps_small_distances():
    # Far from the origin, 1e-6 apart: the expansion |x|^2 - 2 x.y + |y|^2 cancels to
    # rounding noise; sums of squared differences keep the distance.
    stored = np.array([[1e4, 1e4], [1e4 + 1e-6, 1e4]])
    out = euclidean_block(stored, stored, np.array([0]), np.array([0, 1]))
    np.testing.assert_allclose(out, [[0.0, 1e-6]], rtol=1e-6)


@given(st.integers(0, 10_000), st.integers(1, 4), st.sampled_from([np.int8, np.int16, np.int32]))
def test_filter_items_keeps_the_items_holding_the_entries(seed, n_levels, dtype):
    rng = np.random.default_rng(seed)
    first = rng.integers(0, 5, (40, n_levels))
    deep = np.stack([first, first + rng.integers(0, 3, (40, n_levels))], axis=1).astype(dtype)
    entries = rng.integers(0, 7, n_levels).astype(dtype)
    items = np.sort(rng.permutation(40)[:25]).astype(np.int32)
    expected = [
        i
        for i in items
        if all(deep[i, 0, j] <= entries[j] <= deep[i, 1, j] for j in range(n_levels))
    ]
    assert filter_items(items, deep, entries).tolist() == expected


@given(st.integers(0, 10_000), st.integers(1, 6), st.integers(1, 9))
def test_smallest_columns_equal_a_stable_argsort(seed, n_rows, n_columns):
    # Few distinct values (and infinities) so that ties are common: the lower column first.
    rng = np.random.default_rng(seed)
    distances = rng.choice([0.0, 0.5, 1.0, 2.0, np.inf], size=(n_rows, n_columns))
    n = int(rng.integers(1, n_columns + 1))
    columns, nearest = smallest_columns(distances, n)
    expected = np.argsort(distances, axis=1, kind="stable")[:, :n]
    np.testing.assert_array_equal(columns, expected)
    np.testing.assert_array_equal(nearest, np.take_along_axis(distances, expected, axis=1))
