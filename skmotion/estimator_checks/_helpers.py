"""What the clip conformance checks share: running an estimator and comparing its results.

Used by the checks of :mod:`skmotion.estimator_checks` (``_fitting``,
``_input``, ``_sklearn``); the public names are importable from there.
"""

import re
from contextlib import contextmanager

import numpy as np
import pandas as pd
from sklearn.base import is_classifier, is_regressor

from skmotion.base import MotionTags

OUTPUT_METHODS = (
    "predict",
    "predict_proba",
    "predict_log_proba",
    "decision_function",
    "score_samples",
    "transform",
)


@contextmanager
def _raises(expected, *, match=None, what):
    """Like ``pytest.raises``, without pytest: the block must raise ``expected`` (``match``)."""
    try:
        yield
    except expected as exc:
        if match is not None and not re.search(match, str(exc)):
            raise AssertionError(
                f"{what}: raised {type(exc).__name__}, but its message {str(exc)!r} does not "
                f"match {match!r}"
            ) from exc
        return
    names = expected.__name__ if isinstance(expected, type) else expected
    raise AssertionError(f"{what}: no {names} was raised")


def motion_tags(estimator):
    getter = getattr(estimator, "__skmotion_tags__", None)
    return getter() if getter is not None else MotionTags()


def _fit(estimator, X, y):
    return estimator.fit(X, y) if y is not None else estimator.fit(X)


def _as_list(result):
    """A method's result as comparable arrays (per-clip arrays for clip outputs)."""
    if isinstance(result, pd.DataFrame):
        if isinstance(result.index, pd.MultiIndex):
            codes, _ = pd.factorize(result.index.get_level_values(0), sort=False)
            starts = np.flatnonzero(np.r_[True, codes[1:] != codes[:-1]])
            return np.split(result.to_numpy(), starts[1:])
        return [result.to_numpy()]
    if isinstance(result, (list, tuple)):  # per-clip arrays, or a tuple such as decode's
        parts = [_as_list(r) if isinstance(r, list) else [np.asarray(r)] for r in result]
        return [a for part in parts for a in part]
    if isinstance(result, np.ndarray) and result.dtype != object and result.ndim == 3:
        return list(result)
    return [np.asarray(result)]


def outputs(estimator, X, y=None):
    """Results of every output method of a fitted estimator on ``X``."""
    results = {}
    for method in OUTPUT_METHODS:
        if hasattr(estimator, method):
            results[method] = _as_list(getattr(estimator, method)(X))
    if hasattr(estimator, "score") and (
        y is not None or not (is_classifier(estimator) or is_regressor(estimator))
    ):
        results["score"] = [
            np.asarray(estimator.score(X, y) if y is not None else estimator.score(X))
        ]
    return results


def assert_outputs_equal(expected, actual, *, exact=True, context=""):
    assert expected.keys() == actual.keys(), f"{context}: methods differ"
    for method in expected:
        a, b = expected[method], actual[method]
        assert len(a) == len(b), f"{context}: {method} returned {len(a)} vs {len(b)} items"
        for i, (u, v) in enumerate(zip(a, b)):
            if u.dtype.kind in "fc" and exact:
                np.testing.assert_array_equal(u, v, err_msg=f"{context}: {method}[{i}] differs")
            elif u.dtype.kind in "fc":
                np.testing.assert_allclose(
                    u, v, rtol=1e-9, atol=1e-12, err_msg=f"{context}: {method}[{i}]"
                )
            else:
                np.testing.assert_array_equal(u, v, err_msg=f"{context}: {method}[{i}] differs")


def equal_length(X, min_frames):
    """The clips cropped to the shortest length (for the 3-D container)."""
    n = min(len(c) for c in X)
    assert n >= min_frames, "the case's clips are too short to crop to equal length"
    return [np.asarray(c[:n]) for c in X]


def as_dataframe(X):
    return pd.concat({i: pd.DataFrame(c) for i, c in enumerate(X)}, names=["clip", "frame"])
