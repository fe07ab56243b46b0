"""Node covariances and log densities against sklearn and scipy."""

import numpy as np
import pytest
from scipy.stats import multivariate_normal
from sklearn.covariance import ledoit_wolf
from sklearn.covariance import ledoit_wolf_shrinkage as sk_shrinkage

from skmotion.tree._gaussian import (
    Gaussians,
    centred_moments,
    estimate_covariance,
    ledoit_wolf_shrinkage,
    low_rank_covariance,
)


@pytest.mark.parametrize("chunk_rows", [None, 7])
def test_centred_moments_in_chunks(chunk_rows):
    X = np.random.default_rng(0).normal(size=(40, 5)) + 100.0
    mean, scatter, sq_norms = centred_moments(X, chunk_rows=chunk_rows)
    centred = X - X.mean(0)
    np.testing.assert_allclose(mean, X.mean(0))
    np.testing.assert_allclose(scatter, centred.T @ centred, rtol=1e-10)
    np.testing.assert_allclose(sq_norms, (centred**2).sum(1), rtol=1e-10)


@pytest.mark.parametrize("n, d", [(50, 4), (5, 20), (2, 3), (200, 60)])
def test_ledoit_wolf_matches_sklearn(n, d):
    X = np.random.default_rng(n).normal(size=(n, d)) @ np.diag(np.linspace(0.1, 3, d))
    _, scatter, sq_norms = centred_moments(X)
    Xc = X - X.mean(0)
    assert ledoit_wolf_shrinkage(scatter, sq_norms) == pytest.approx(
        sk_shrinkage(Xc, assume_centered=True)
    )
    expected, _ = ledoit_wolf(Xc, assume_centered=True)
    np.testing.assert_allclose(
        estimate_covariance(scatter, len(sq_norms), "full", 0.0, sq_norms), expected, atol=1e-12
    )


def test_diag_and_spherical_add_the_regularisation():
    X = np.array([[0.0, 1.0, 5.0], [2.0, 1.0, 5.0], [4.0, 1.0, 5.0]])
    _, scatter, sq_norms = centred_moments(X)
    np.testing.assert_allclose(
        estimate_covariance(scatter, len(sq_norms), "diag", 0.1, sq_norms), [8 / 3 + 0.1, 0.1, 0.1]
    )
    assert estimate_covariance(scatter, len(sq_norms), "spherical", 0.1, sq_norms) == pytest.approx(
        8 / 9 + 0.1
    )


def test_fewer_frames_than_channels_stay_positive_definite():
    X = np.random.default_rng(0).normal(size=(3, 30))
    X[:, 5] = 7.0  # a constant channel
    _, scatter, sq_norms = centred_moments(X)
    for kind in ("full", "diag", "spherical"):
        cov = np.atleast_1d(estimate_covariance(scatter, len(sq_norms), kind, 1e-6, sq_norms))
        eig = np.linalg.eigvalsh(cov) if cov.ndim == 2 else cov
        assert eig.min() > 0


@pytest.mark.parametrize("kind", ["full", "diag", "spherical"])
def test_log_pdf_matches_scipy(kind):
    rng = np.random.default_rng(1)
    d, k = 4, 3
    means = rng.normal(size=(k, d))
    if kind == "full":
        A = rng.normal(size=(k, d, d))
        covs = A @ A.transpose(0, 2, 1) + np.eye(d)
        dense = covs
    elif kind == "diag":
        covs = rng.uniform(0.5, 2, size=(k, d))
        dense = np.stack([np.diag(c) for c in covs])
    else:
        covs = rng.uniform(0.5, 2, size=k)
        dense = np.stack([c * np.eye(d) for c in covs])
    X = rng.normal(size=(7, d)) * 3
    got = Gaussians(means, covs, kind).log_pdf(X)
    expected = np.stack(
        [multivariate_normal(means[j], dense[j]).logpdf(X) for j in range(k)], axis=1
    )
    np.testing.assert_allclose(got, expected, rtol=1e-10)
    np.testing.assert_allclose(
        Gaussians(means, covs, kind).log_pdf(X, [2, 0]), expected[:, [2, 0]], rtol=1e-10
    )


def test_unknown_kind():
    with pytest.raises(ValueError, match="covariance_type must be one of"):
        estimate_covariance(np.zeros((2, 2)), 2, "tied", 0.0)


@pytest.mark.parametrize("n, d", [(1, 6), (2, 6), (5, 20), (12, 192), (20, 20)])
def test_the_low_rank_form_is_the_full_estimate(n, d):
    """floor I + V^T diag(values) V is the Ledoit-Wolf estimate (sklearn's), and V has the
    frames' rank."""
    X = np.random.default_rng(d + n).normal(size=(n, d)) @ np.diag(np.linspace(0.1, 3, d)) + 5.0
    mean, scatter, sq_norms = centred_moments(X)
    floor, vectors, values = low_rank_covariance(X - mean, scatter, sq_norms, 1e-3)
    assert len(vectors) == min(n - 1, d)
    np.testing.assert_allclose(vectors @ vectors.T, np.eye(len(vectors)), atol=1e-12)
    rebuilt = floor * np.eye(d) + vectors.T @ np.diag(values) @ vectors
    expected = (
        ledoit_wolf(X - mean, assume_centered=True)[0] + 1e-3 * np.eye(d)
        if n > 1
        else 1e-3 * np.eye(d)
    )
    np.testing.assert_allclose(rebuilt, expected, atol=1e-12)
    np.testing.assert_allclose(
        rebuilt, estimate_covariance(scatter, len(sq_norms), "full", 1e-3, sq_norms), atol=1e-12
    )
