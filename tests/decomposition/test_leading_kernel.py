"""The compiled leading-eigenpair kernel against numpy's SVD of each clip."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from skmotion.decomposition._leading import leading_spectra

from skmotion.decomposition._clip_svd import clip_spectra


def _check_against_svd(clip, values, vectors, n_vectors, vector_atol=1e-6):
    _, s, vt = np.linalg.svd(clip / np.abs(clip).max())
    n_pairs = min(n_vectors, len(s))
    np.testing.assert_allclose(values[:n_pairs], s[:n_pairs] ** 2, rtol=1e-8, atol=1e-12)
    np.testing.assert_array_equal(values[n_pairs:], 0.0)  # beyond the smaller side
    for i in range(n_pairs):
        gaps = np.abs(s[i] ** 2 - np.delete(s**2, i))
        if gaps.min(initial=np.inf) < 1e-3 * s[0] ** 2:
            continue  # nearly equal singular values: the vector is barely defined
        np.testing.assert_allclose(abs(vectors[:, i] @ vt[i]), 1.0, atol=vector_atol)


@settings(max_examples=25, deadline=None)
@given(
    st.integers(0, 10_000),
    st.integers(2, 12),
    st.integers(1, 5),
    st.sampled_from([1e-200, 1.0, 1e200]),
)
def test_leading_pairs_match_the_svd_of_clips_of_any_length(seed, n_channels, n_vectors, scale):
    # Tall and short clips (A^T A and A A^T routes) in one call, at any scale.
    rng = np.random.default_rng(seed)
    lengths = rng.integers(1, 2 * n_channels + 3, size=8)
    decay = np.exp(-np.arange(n_channels) / rng.uniform(1, 6))
    clips = [rng.normal(size=(n, n_channels)) * decay * scale for n in lengths]
    n_vectors = min(n_vectors, n_channels)
    values, vectors = leading_spectra(clips, n_vectors, 1e-9, 4, 96)
    assert values.shape == (len(clips), n_vectors)
    for clip, vals, vecs in zip(clips, values, vectors):
        _check_against_svd(clip, vals, vecs, n_vectors)


@settings(max_examples=15, deadline=None)
@given(st.integers(0, 10_000))
def test_power_steps_and_the_lapack_fallback_agree(seed):
    # max_steps=0 sends every clip to dsyevr; the power steps must land on the
    # same pair (within their residual bound).
    rng = np.random.default_rng(seed)
    clips = [rng.normal(size=(40, 12)) + rng.normal(size=12) for _ in range(6)]
    power = leading_spectra(clips, 1, 1e-9, 4, 96)
    lapack = leading_spectra(clips, 1, 1e-9, 4, 0)
    np.testing.assert_allclose(power[0], lapack[0], rtol=1e-12)
    np.testing.assert_allclose(np.abs(power[1]), np.abs(lapack[1]), atol=1e-7)
    for clip, vals, vecs in zip(clips, *lapack):
        _check_against_svd(clip, vals, vecs, 1, vector_atol=1e-10)


def test_a_zero_clip_has_zero_pairs_and_channels_must_agree():
    values, vectors = leading_spectra([np.zeros((5, 3)), np.eye(3)], 2, 1e-9, 4, 96)
    np.testing.assert_array_equal(values[0], 0.0)
    np.testing.assert_array_equal(vectors[0], 0.0)
    np.testing.assert_allclose(values[1], [1.0, 1.0])
    with pytest.raises(ValueError, match="clip 1 has 4 channels"):
        leading_spectra([np.ones((3, 3)), np.ones((3, 4))], 1, 1e-9, 4, 96)


def test_iterative_first_vector_equals_the_exact_route():
    # clip_spectra(..., 1, method="iterative") goes through the kernel; its
    # first pair is the full eigh's, and a rank-one clip keeps one direction.
    rng = np.random.default_rng(3)
    clips = [rng.normal(size=(n, 7)) + 2 * rng.normal(size=7) for n in (3, 7, 30, 30)]
    clips.append(np.outer(np.arange(1.0, 6.0), rng.normal(size=7)))
    values, vectors = clip_spectra(clips, 1, method="iterative")
    exact_values, exact_vectors = clip_spectra(clips, 1, method="exact")
    np.testing.assert_allclose(values[:, 0], exact_values[:, 0], rtol=1e-10)
    np.testing.assert_array_equal(values[:, 1:], 0.0)
    np.testing.assert_allclose(np.abs(vectors), np.abs(exact_vectors), atol=1e-7)


@settings(max_examples=20, deadline=None)
@given(
    st.integers(0, 10_000),
    st.sampled_from([(40, 60), (90, 30), (70, 24), (30, 45)]),
    st.integers(2, 6),
    st.integers(0, 8),
)
def test_subspace_iteration_matches_the_svd(seed, shape, n_vectors, n_constant):
    # Matrices large enough for subspace iteration (block n_vectors + 4 under
    # half the Gram size), motion-like decaying spectra, and clips whose
    # constant channels leave the Gram matrix rank-deficient.
    rng = np.random.default_rng(seed)
    n_frames, n_channels = shape
    decay = np.exp(-np.arange(n_channels) / rng.uniform(2, 8))
    clips = [rng.normal(size=shape) * decay + rng.normal(size=n_channels) for _ in range(4)]
    clips[0][:, :n_constant] = 0.0
    values, vectors = leading_spectra(clips, n_vectors, 1e-9, 4, 24)
    lapack = leading_spectra(clips, n_vectors, 1e-9, 4, 0)  # dsyevr for every clip
    np.testing.assert_allclose(values, lapack[0], rtol=1e-9, atol=1e-12)
    for clip, vals, vecs in zip(clips, values, vectors):
        _check_against_svd(clip, vals, vecs, n_vectors)


def test_start_blocks_are_the_generators_draws_whatever_the_order_of_shapes():
    # The start block is cut from a cached, growing array of draws; it must be
    # exactly default_rng(0).standard_normal(shape) for every shape, in any order.
    from skmotion.decomposition._leading import _start_block

    for shape in [(3, 2), (60, 10), (1, 1), (200, 10), (7, 5), (40, 5), (500, 12)]:
        block = _start_block(*shape)
        np.testing.assert_array_equal(block, np.random.default_rng(0).standard_normal(shape))
        assert block.flags.c_contiguous and not block.flags.writeable
