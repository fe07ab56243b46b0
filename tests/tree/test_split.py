"""Split criteria: prefix-sum scores against direct computation on every cut."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from skmotion.tree._build._split import SPLIT_CRITERIA, best_split, split_scores

values = arrays(np.float64, st.integers(2, 40), elements=st.floats(-100, 100))


def direct_scores(v, criterion, var_floor=0.0):
    """Each cut scored from its two slices, with np.var (no prefix sums)."""
    n = len(v)
    out = []
    for i in range(1, n):
        left, right = v[:i], v[i:]
        if criterion == "min_error":
            v1 = max(np.var(left), var_floor, np.finfo(float).tiny)
            v2 = max(np.var(right), var_floor, np.finfo(float).tiny)
            out.append(
                i * np.log(v1)
                + (n - i) * np.log(v2)
                - 2 * (i * np.log(i) + (n - i) * np.log(n - i))
            )
        elif criterion == "two_means":
            out.append(np.sum((left - left.mean()) ** 2) + np.sum((right - right.mean()) ** 2))
        else:
            out.append(abs(i - n / 2))
    return np.array(out)


@given(values)
def test_min_error_matches_its_definition(v):
    v = np.sort(v)
    scale = max(np.ptp(v), 1.0)
    floor = (1e-6 * scale) ** 2  # keeps log() away from rounding noise of zero variances
    np.testing.assert_allclose(
        split_scores(v, "min_error", var_floor=floor),
        direct_scores(v, "min_error", floor),
        rtol=1e-6,
        atol=1e-4,
    )


@given(values)
def test_two_means_differs_from_the_sum_of_squares_by_a_constant(v):
    v = np.sort(v)
    diff = split_scores(v, "two_means") - direct_scores(v, "two_means")
    np.testing.assert_allclose(diff, diff[0], atol=1e-6 * max(1.0, np.sum((v - v.mean()) ** 2)))


def test_median_prefers_the_middle():
    assert np.argmin(split_scores(np.arange(10.0), "median")) + 1 == 5


def test_min_error_cuts_between_two_modes():
    rng = np.random.default_rng(0)
    v = np.sort(np.r_[rng.normal(0, 1, 300), rng.normal(20, 2, 100)])
    assert best_split(v, "min_error", min_samples_leaf=5) == 300


@pytest.mark.parametrize("criterion", SPLIT_CRITERIA)
@given(values, st.integers(1, 10), st.floats(0, 5))
def test_best_split_is_the_best_admissible_cut(criterion, v, leaf, tol):
    v = np.sort(np.round(v))  # rounding makes ties and small gaps common
    m = best_split(v, criterion, min_samples_leaf=leaf, tol=tol)
    admissible = [
        i for i in range(1, len(v)) if i >= leaf and len(v) - i >= leaf and v[i] - v[i - 1] > tol
    ]
    if not admissible:
        assert m is None
        return
    assert m in admissible
    scores = split_scores(v, criterion, var_floor=tol * tol)
    assert scores[m - 1] == min(scores[i - 1] for i in admissible)


def test_equal_values_are_never_separated():
    v = np.r_[np.zeros(10), np.ones(10), np.ones(10) * 2]
    m = best_split(v, "median", min_samples_leaf=1)
    assert m in (10, 20)
    assert best_split(np.ones(8), "two_means") is None


def test_unknown_criterion():
    with pytest.raises(ValueError, match="criterion must be one of"):
        split_scores(np.arange(3.0), "gini")


def _median_by_scores(values, leaf, tol):
    """The median rule as its definition states it: the admissible cut of least score."""
    n = len(values)
    if n < 2 * leaf:
        return None
    admissible = np.diff(values) > tol
    admissible[: leaf - 1] = False
    admissible[n - leaf :] = False
    if not admissible.any():
        return None
    return int(np.argmin(np.where(admissible, split_scores(values, "median"), np.inf))) + 1


@settings(max_examples=200, deadline=None)
@given(
    st.integers(1, 3_000),
    st.integers(1, 40),
    st.sampled_from([0.0, 1e-12, 0.5]),
    st.integers(1, 50),
    st.integers(0, 2**32 - 1),
)
def test_median_cut_is_the_least_score(n, leaf, tol, distinct, seed):
    # few distinct values: long runs of ties around the middle push the cut outwards
    rng = np.random.default_rng(seed)
    values = np.sort(rng.integers(0, distinct, n).astype(float))
    assert best_split(values, "median", min_samples_leaf=leaf, tol=tol) == _median_by_scores(
        values, leaf, tol
    )
