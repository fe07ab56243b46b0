"""The compiled ranking distances against psi_from_signatures (the matrix-product reference)."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from skmotion.neighbors._psi_rank import psi_distances

from skmotion.neighbors._psi import psi_from_signatures, psi_signatures
from skmotion.utils import check_clips


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 10_000), st.integers(1, 9), st.integers(1, 6))
def test_equals_one_minus_psi_of_the_gathered_signatures(seed, n_channels, k):
    rng = np.random.default_rng(seed)
    clips = check_clips([rng.normal(size=(rng.integers(2, 20), n_channels)) for _ in range(30)])
    queries = check_clips([rng.normal(size=(rng.integers(2, 20), n_channels)) for _ in range(5)])
    stored, asked = psi_signatures(clips, k), psi_signatures(queries, k)
    # Rows and columns in any order, repeated, and a query equal to a stored clip.
    rows = rng.integers(0, 5, size=rng.integers(0, 8))
    columns = rng.integers(0, 30, size=rng.integers(0, 40))
    got = psi_distances(*asked, *stored, rows, columns)
    expected = 1.0 - psi_from_signatures(
        asked[0][rows], asked[1][rows], stored[0][columns], stored[1][columns]
    )
    assert got.shape == (len(rows), len(columns))
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-14)
    self_distance = psi_distances(*stored, *stored, np.arange(30), np.arange(30)).diagonal()
    assert (self_distance >= 0).all()  # clipped: psi(Q, Q) never above 1
    np.testing.assert_allclose(self_distance, 0.0, atol=1e-14)


def test_signatures_must_match():
    a = (np.ones((2, 3)) / 3, np.ones((2, 3, 4)))
    with pytest.raises(ValueError, match="differ in k or in channels"):
        psi_distances(*a, np.ones((2, 2)), np.ones((2, 2, 4)), np.arange(2), np.arange(2))


@settings(max_examples=15, deadline=None)
@given(st.integers(0, 10_000), st.integers(1, 25))
def test_both_ranking_routes_agree(seed, n_rows):
    # psi_distance_block switches from the compiled loop to matrix products
    # at _ROWS_FOR_PRODUCTS queries; either side gives the same distances.
    from skmotion.neighbors._ranking import psi_distance_block

    rng = np.random.default_rng(seed)
    clips = check_clips([rng.normal(size=(12, 7)) for _ in range(40)])
    signatures = psi_signatures(clips, 6)
    rows = np.sort(rng.choice(40, size=n_rows, replace=False))
    columns = np.sort(rng.choice(40, size=30, replace=False))
    block = psi_distance_block(signatures, signatures, rows, columns)
    np.testing.assert_allclose(
        block, psi_distances(*signatures, *signatures, rows, columns), rtol=0, atol=1e-14
    )
