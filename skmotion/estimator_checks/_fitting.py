"""Clip conformance checks of fitting and fitted state.

``fit`` returns self and sets only trailing-underscore attributes, nothing works before
``fit``, the input is left alone, pickles, seeds, refits and ``n_jobs`` give identical
results. Run through :mod:`skmotion.estimator_checks`.
"""

import copy
import pickle

import numpy as np
from sklearn.base import clone
from sklearn.exceptions import NotFittedError

from skmotion.estimator_checks._helpers import (
    OUTPUT_METHODS,
    _fit,
    _raises,
    assert_outputs_equal,
    outputs,
)


def check_fit_returns_self(estimator, X, y):
    """``fit`` returns the estimator itself."""
    est = clone(estimator)
    assert _fit(est, X, y) is est, "fit must return self"


def check_not_fitted(estimator, X, y):
    """Every output method raises ``NotFittedError`` before ``fit``."""
    est = clone(estimator)
    for method in (*OUTPUT_METHODS, "score"):
        if hasattr(est, method):
            args = (X, y) if method == "score" and y is not None else (X,)
            with _raises(NotFittedError, what=f"{method} before fit"):
                getattr(est, method)(*args)


def check_fitted_attributes(estimator, X, y):
    """Sets ``n_features_in_``, fitted attributes end in ``_``; parameters unchanged."""
    est = clone(estimator)
    params = copy.deepcopy(est.get_params())
    before = set(vars(est))
    _fit(est, X, y)
    assert est.n_features_in_ == X[0].shape[1], "n_features_in_ must be the channel count"
    new = [a for a in set(vars(est)) - before if not a.startswith("_")]
    bad = [a for a in new if not a.endswith("_")]
    assert not bad, f"fit set public attributes without a trailing underscore: {bad}"
    after = est.get_params()
    for key, value in params.items():
        assert pickle.dumps(value) == pickle.dumps(after[key]), f"fit changed parameter {key!r}"


def check_input_not_modified(estimator, X, y):
    """``fit`` and the output methods leave ``X`` and ``y`` as they were."""
    X_copy = copy.deepcopy(X)
    y_copy = copy.deepcopy(y)
    est = _fit(clone(estimator), X, y)
    outputs(est, X, y)
    for i, (a, b) in enumerate(zip(X, X_copy)):
        np.testing.assert_array_equal(a, b, err_msg=f"clip {i} of X was modified")
    if y is not None:
        np.testing.assert_array_equal(y, y_copy, err_msg="y was modified")


def check_pickle(estimator, X, y):
    """A pickled and restored estimator gives identical results."""
    est = _fit(clone(estimator), X, y)
    expected = outputs(est, X, y)
    restored = pickle.loads(pickle.dumps(est))
    assert_outputs_equal(expected, outputs(restored, X, y), exact=True, context="after pickling")


def check_deterministic(estimator, X, y):
    """Two fits with the same ``random_state`` give identical results."""
    est = clone(estimator)
    if "random_state" in est.get_params():
        est.set_params(random_state=0)
    first = outputs(_fit(clone(est), X, y), X, y)
    second = outputs(_fit(clone(est), X, y), X, y)
    assert_outputs_equal(first, second, exact=True, context="two fits with the same seed")


def check_fit_idempotent(estimator, X, y):
    """Refitting the same instance on the same data gives identical results."""
    est = clone(estimator)
    if "random_state" in est.get_params():
        est.set_params(random_state=0)
    first = outputs(_fit(est, X, y), X, y)
    again = outputs(_fit(est, X, y), X, y)
    assert_outputs_equal(first, again, exact=True, context="refitting the same instance")


def check_n_jobs(estimator, X, y):
    """``n_jobs=1`` and ``n_jobs=2`` give identical results."""
    est = clone(estimator)
    if "n_jobs" not in est.get_params():
        return
    if "random_state" in est.get_params():
        est.set_params(random_state=0)
    serial = outputs(_fit(clone(est).set_params(n_jobs=1), X, y), X, y)
    parallel = outputs(_fit(clone(est).set_params(n_jobs=2), X, y), X, y)
    assert_outputs_equal(serial, parallel, exact=True, context="n_jobs=1 vs n_jobs=2")
