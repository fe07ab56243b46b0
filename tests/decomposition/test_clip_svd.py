"""clip_spectra (both Gram routes, batched by size) against numpy's SVD of each clip."""

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from skmotion.decomposition._clip_svd import clip_spectra


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 10_000), st.integers(2, 9), st.integers(1, 4))
def test_matches_the_svd_of_every_clip(seed, n_channels, n_vectors):
    rng = np.random.default_rng(seed)
    # Lengths on both sides of n_channels, repeated so that clips share a batch,
    # and one rank-deficient clip (a repeated frame pattern).
    lengths = rng.integers(1, 2 * n_channels + 2, size=12)
    clips = [
        rng.normal(size=(n, n_channels)) * rng.uniform(0.5, 3.0, size=n_channels) for n in lengths
    ]
    clips.append(np.tile(rng.normal(size=(1, n_channels)), (5, 1)))
    n_vectors = min(n_vectors, n_channels)
    eigenvalues, vectors = clip_spectra(clips, n_vectors)
    for clip, values, vecs in zip(clips, eigenvalues, vectors):
        # Each clip is decomposed divided by its largest absolute value.
        _, s, vt = np.linalg.svd(clip / np.abs(clip).max())
        rank = int(np.sum(s > s[0] * 1e-10))
        expected = np.zeros(n_channels)
        expected[:rank] = s[:rank] ** 2
        np.testing.assert_allclose(values, expected, rtol=1e-9, atol=1e-9 * s[0] ** 2)
        for i in range(n_vectors):
            if i >= rank:
                np.testing.assert_array_equal(vecs[:, i], 0.0)
                continue
            gaps = np.abs(s[i] ** 2 - np.delete(s[:rank] ** 2, i))
            if gaps.min(initial=np.inf) < 1e-6 * s[0] ** 2:
                continue  # a repeated singular value: the vector is not unique
            # Unit vectors equal up to sign.
            np.testing.assert_allclose(abs(vecs[:, i] @ vt[i]), 1.0, atol=1e-7)


@settings(max_examples=20, deadline=None)
@given(st.integers(0, 10_000), st.sampled_from([1e-300, 1e-150, 1e150, 1e300]))
def test_spectra_do_not_depend_on_the_clips_scale(seed, scale):
    # x1e300 would overflow a Gram matrix (1e600), x1e-300 underflow it: the
    # spectra of the scaled clips equal those of the clips themselves.
    rng = np.random.default_rng(seed)
    clips = [rng.normal(size=(n, 5)) for n in (3, 20, 20)]
    values, vectors = clip_spectra(clips, 3)
    big_values, big_vectors = clip_spectra([c * scale for c in clips], 3)
    np.testing.assert_allclose(big_values, values, rtol=1e-10, atol=1e-14)
    np.testing.assert_allclose(np.abs(big_vectors), np.abs(vectors), atol=1e-10)


def test_chunks_and_jobs_give_the_same_spectra():
    rng = np.random.default_rng(0)
    clips = [rng.normal(size=(n, 6)) for n in rng.integers(2, 12, size=1100)]  # three chunks
    one = clip_spectra(clips, 3)
    two = clip_spectra(clips, 3, n_jobs=2)
    for a, b in zip(one, two):
        np.testing.assert_array_equal(a, b)
    # A clip's spectrum does not depend on the clips beside it.
    alone = clip_spectra(clips[700:701], 3)
    np.testing.assert_array_equal(alone[0][0], one[0][700])
    np.testing.assert_array_equal(alone[1][0], one[1][700])


@settings(max_examples=15, deadline=None)
@given(
    st.integers(0, 10_000),
    st.sampled_from([(40, 60), (120, 30), (25, 25)]),
    st.sampled_from([1, 6]),  # power iteration, subspace iteration
)
def test_iterative_leading_pairs_match_the_full_svd(seed, shape, n_vectors):
    # Motion-like spectra (decaying) and one clip with two equal singular values.
    rng = np.random.default_rng(seed)
    n_frames, n_channels = shape
    decay = np.exp(-np.arange(n_channels) / rng.uniform(2, 8))
    clips = [rng.normal(size=shape) * decay for _ in range(5)]
    equal = rng.normal(size=shape) * decay
    equal[:, 1] = equal[:, 0] * 0  # rank change: a zero column
    clips.append(equal)
    values, vectors = clip_spectra(clips, n_vectors, method="iterative")
    for clip, vals, vecs in zip(clips, values, vectors):
        _, s, vt = np.linalg.svd(clip / np.abs(clip).max())
        np.testing.assert_allclose(
            vals[:n_vectors], s[:n_vectors] ** 2, rtol=1e-8, atol=1e-12 * s[0] ** 2
        )
        for i in range(n_vectors):
            gaps = np.abs(s[i] ** 2 - np.delete(s**2, i))
            if gaps.min() < 1e-3 * s[0] ** 2:
                continue  # nearly equal singular values: the vector is barely defined
            np.testing.assert_allclose(abs(vecs[:, i] @ vt[i]), 1.0, atol=1e-6)


def test_small_blas_runs_blas_on_one_thread_and_restores_the_count():
    # Both routes: limiting a multithreaded BLAS, and nothing to do when it is
    # on one thread already (as in a joblib worker).
    from threadpoolctl import threadpool_info, threadpool_limits

    from skmotion.decomposition._clip_svd import small_blas

    def blas_threads():
        return [lib["num_threads"] for lib in threadpool_info() if lib["user_api"] == "blas"]

    before = blas_threads()
    with small_blas():
        assert set(blas_threads()) <= {1}
    assert blas_threads() == before
    with threadpool_limits(limits=1, user_api="blas"):
        with small_blas():
            assert set(blas_threads()) <= {1}
        assert set(blas_threads()) <= {1}
    assert blas_threads() == before
