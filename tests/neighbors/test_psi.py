"""psi and pairwise_psi against hand-worked values, the definition and their properties."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from sklearn.neighbors import KNeighborsClassifier

from skmotion.datasets import make_motions
from skmotion.neighbors import pairwise_psi, psi


def psi_by_definition(Q, P, k):
    """Written from the formula with np.linalg.eigh on Q^T Q and P^T P."""
    s, U = np.linalg.eigh(Q.T @ Q)
    t, V = np.linalg.eigh(P.T @ P)
    s, U, t, V = s[::-1][:k], U[:, ::-1][:, :k], t[::-1][:k], V[:, ::-1][:, :k]
    return 0.5 * sum((s[i] / s.sum() + t[i] / t.sum()) * abs(U[:, i] @ V[:, i]) for i in range(k))


def test_hand_worked():
    # Q^T Q = diag(4, 1): u1 = e1, u2 = e2. P^T P has eigenvalues 9 and 1 along
    # (1, 1)/sqrt2 and (1, -1)/sqrt2. psi = 1/2 [(4/5 + 9/10) + (1/5 + 1/10)] / sqrt2.
    Q = np.array([[2.0, 0.0], [0.0, 1.0]])
    R = np.array([[1.0, 1.0], [1.0, -1.0]]) / np.sqrt(2)
    P = np.diag([3.0, 1.0]) @ R.T
    assert psi(Q, P, k=2) == pytest.approx(1 / np.sqrt(2), abs=1e-12)
    # Same directions swapped between the first and second eigenvalues: nothing matches.
    assert psi(Q, np.array([[0.0, 2.0], [1.0, 0.0]]), k=2) == pytest.approx(0.0, abs=1e-12)
    # k=1 compares the first directions only.
    assert psi(Q, P, k=1) == pytest.approx(1 / np.sqrt(2), abs=1e-12)


clip = arrays(
    np.float64, st.tuples(st.integers(3, 25), st.just(5)), elements=st.floats(-4, 4, width=32)
)


def _well_posed(*clips, k=3):
    """Distinct, non-vanishing leading eigenvalues: the eigenvectors are unique."""
    for c in clips:
        s = np.linalg.svd(c, compute_uv=False)[: k + 1]
        if len(s) <= k or s[k - 1] < 1e-2 or np.abs(np.diff(s)).min() < 1e-2 * s[0]:
            return False
    return True


@given(clip, clip, st.integers(1, 5))
def test_properties(Q, P, k):
    if not _well_posed(Q, P, k=k):
        return
    value = psi(Q, P, k=k)
    assert 0.0 <= value <= 1.0
    assert value == pytest.approx(psi(P, Q, k=k), abs=1e-12)
    assert psi(Q, Q, k=k) == pytest.approx(1.0, abs=1e-12)
    assert value == pytest.approx(psi_by_definition(Q, P, k), abs=1e-7)
    # The same motion repeated: psi does not see the length.
    assert psi(np.vstack([Q, Q, Q]), P, k=k) == pytest.approx(value, abs=1e-7)


def test_k_beyond_the_channels_uses_all():
    rng = np.random.default_rng(0)
    Q, P = rng.normal(size=(30, 4)), rng.normal(size=(40, 4))
    assert psi(Q, P, k=10) == pytest.approx(psi(Q, P, k=4))


def test_rank_deficient_clip_is_still_similar_to_itself():
    Q = np.zeros((10, 6))
    Q[:, 0] = np.arange(10)  # rank one
    assert psi(Q, Q) == pytest.approx(1.0)
    assert psi(Q, 2 * Q) == pytest.approx(1.0)


def test_pairwise_matches_psi_and_works_as_precomputed_distance():
    data = make_motions(n_clips_per_class=3, random_state=0)
    clips = [c[:, 6:] for c in data.clips]
    S = pairwise_psi(clips)
    assert S.shape == (21, 21)
    np.testing.assert_allclose(S, S.T, atol=1e-12)
    np.testing.assert_allclose(np.diag(S), 1.0)
    for i, j in [(0, 1), (2, 17), (20, 5)]:
        assert S[i, j] == pytest.approx(psi(clips[i], clips[j]), abs=1e-12)
    cross = pairwise_psi(clips[:5], clips[5:], k=4)
    np.testing.assert_allclose(cross, pairwise_psi(clips, k=4)[:5, 5:], atol=1e-12)
    np.testing.assert_array_equal(pairwise_psi(clips, n_jobs=2), S)
    # Leave-one-out 1-NN with 1 - psi: a motion's nearest clip is mostly of its class.
    D = 1 - S
    np.fill_diagonal(D, np.inf)
    assert (data.target[D.argmin(axis=1)] == data.target).mean() >= 0.8
    knn = KNeighborsClassifier(n_neighbors=1, metric="precomputed").fit(
        1 - S[:14, :14], data.target[:14]
    )
    assert knn.predict(1 - S[14:, :14]).shape == (7,)


def test_errors():
    rng = np.random.default_rng(0)
    with pytest.raises(ValueError, match="clip 1 has 3 channels"):
        psi(rng.normal(size=(5, 4)), rng.normal(size=(5, 3)))
    with pytest.raises(ValueError, match="all zeros"):
        psi(rng.normal(size=(5, 4)), np.zeros((5, 4)))
    with pytest.raises(ValueError, match="Y: clips have 3 channels"):
        pairwise_psi([rng.normal(size=(5, 4))], [rng.normal(size=(5, 3))])
    with pytest.raises(ValueError, match="k"):
        psi(rng.normal(size=(5, 4)), rng.normal(size=(5, 4)), k=0)
