"""Conformance checks for estimators whose samples are motion clips.

sklearn's ``check_estimator`` skips every check for estimators that do not take 2-D
tables (one sample per row), so this module covers the same ground for clip
collections: fit returns self; fitted attributes end in ``_``; input is not modified;
lists, tuples, 3-D arrays and (clip, frame) DataFrames give the same results; pickles
predict identically; a channel mismatch, an empty collection, NaN and too-short clips
are rejected with a message naming the clip; the same seed gives the same result and
``n_jobs`` does not change it; ``set_output(transform="pandas")`` and
``get_feature_names_out`` agree; ``cross_val_score`` and ``GridSearchCV`` run; plus
sklearn's own checks that need no data (cloning, ``get_params``/``set_params``, repr).

Run them on one estimator with :func:`check_clip_estimator`, or one pytest test per
check with :func:`parametrize_with_clip_checks` (as sklearn's
``parametrize_with_checks``)::

    from skmotion.utils.estimator_checks import ClipCase, parametrize_with_clip_checks

    @parametrize_with_clip_checks([ClipCase(MyEstimator(), make_data)])
    def test_conformance(check):
        check()

``make_data`` returns ``(X, y)``: a list of clips (at least 3 clips per class for
classifiers) and labels, or ``y=None``. pytest is imported only by
:func:`parametrize_with_clip_checks`; the rest needs only skmotion's own dependencies.
"""

import copy
import pickle
import re
from contextlib import contextmanager
from dataclasses import dataclass, field
from functools import partial

import numpy as np
import pandas as pd
from sklearn.base import clone, is_classifier, is_regressor
from sklearn.exceptions import NotFittedError
from sklearn.linear_model import LogisticRegression
from sklearn.model_selection import GridSearchCV, KFold, cross_val_score
from sklearn.pipeline import make_pipeline

from skmotion.base import MotionTags
from skmotion.preprocessing import FlattenClips, ResampleClips

__all__ = [
    "CHECKS",
    "SKLEARN_DATA_FREE_CHECKS",
    "ClipCase",
    "check_clip_estimator",
    "clip_checks",
    "make_check_data",
    "parametrize_with_clip_checks",
]

OUTPUT_METHODS = (
    "predict",
    "predict_proba",
    "predict_log_proba",
    "decision_function",
    "score_samples",
    "transform",
)

# sklearn's checks that need no data: they cover get_params/set_params/clone.
SKLEARN_DATA_FREE_CHECKS = (
    "check_estimator_cloneable",
    "check_estimator_repr",
    "check_no_attributes_set_in_init",
    "check_parameters_default_constructible",
    "check_get_params_invariance",
    "check_set_params",
    "check_do_not_raise_errors_in_init_or_set_params",
    "check_valid_tag_types",
    "check_mixin_order",
    "check_estimator_tags_renamed",
)


@dataclass
class ClipCase:
    """An estimator with the data to check it on.

    Parameters
    ----------
    estimator : estimator instance
        Configured cheaply (small trees, few components).
    data : callable, default=None
        Returns ``(X, y)``: a list of clips and labels (or None); by default
        :func:`make_check_data` for the estimator.
    param_grid : dict, default=None
        A small grid for the GridSearchCV check; by default the first parameter
        at its current value.
    skip : dict, default={}
        Check name -> reason, for checks that do not apply.
    """

    estimator: object
    data: object = None
    param_grid: dict = None
    skip: dict = field(default_factory=dict)


# -- helpers -------------------------------------------------------------------------


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
    if isinstance(result, (list, tuple)):
        return [np.asarray(r) for r in result]
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


def scoring_model(estimator, y):
    """The estimator, followed by what it needs to be cross-validated."""
    kind = motion_tags(estimator).output_kind
    if y is None or is_classifier(estimator) or is_regressor(estimator):
        return estimator
    if kind == "clips":
        return make_pipeline(
            estimator, ResampleClips(n_frames=8), FlattenClips(), LogisticRegression(max_iter=500)
        )
    return make_pipeline(estimator, LogisticRegression(max_iter=500))


# -- the checks -------------------------------------------------------------------------


def check_sklearn(name, estimator, X, y):
    # Imported here: sklearn's checks module imports pytest when it is installed.
    from sklearn.utils import estimator_checks as sk_checks

    getattr(sk_checks, name)(type(estimator).__name__, clone(estimator))


def check_fit_returns_self(estimator, X, y):
    est = clone(estimator)
    assert _fit(est, X, y) is est, "fit must return self"


def check_not_fitted(estimator, X, y):
    est = clone(estimator)
    for method in (*OUTPUT_METHODS, "score"):
        if hasattr(est, method):
            args = (X, y) if method == "score" and y is not None else (X,)
            with _raises(NotFittedError, what=f"{method} before fit"):
                getattr(est, method)(*args)


def check_fitted_attributes(estimator, X, y):
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
    X_copy = copy.deepcopy(X)
    y_copy = copy.deepcopy(y)
    est = _fit(clone(estimator), X, y)
    outputs(est, X, y)
    for i, (a, b) in enumerate(zip(X, X_copy)):
        np.testing.assert_array_equal(a, b, err_msg=f"clip {i} of X was modified")
    if y is not None:
        np.testing.assert_array_equal(y, y_copy, err_msg="y was modified")


def check_containers_agree(estimator, X, y):
    clips = equal_length(X, motion_tags(estimator).min_frames)
    forms = {
        "list": clips,
        "tuple": tuple(clips),
        "ndarray": np.stack(clips),
        "dataframe": as_dataframe(clips),
    }
    reference = None
    for kind, data in forms.items():
        est = _fit(clone(estimator), data, y)
        result = outputs(est, data, y)
        if reference is None:
            reference = result
        else:
            assert_outputs_equal(reference, result, exact=False, context=f"{kind} vs list")
        for method in ("transform",):
            if hasattr(est, method) and motion_tags(est).output_kind == "clips":
                out = getattr(est, method)(data)
                expected = {
                    "list": list,
                    "tuple": tuple,
                    "ndarray": np.ndarray,
                    "dataframe": pd.DataFrame,
                }[kind]
                assert isinstance(out, expected), (
                    f"{method} on a {kind} returned {type(out).__name__}"
                )


def check_pickle(estimator, X, y):
    est = _fit(clone(estimator), X, y)
    expected = outputs(est, X, y)
    restored = pickle.loads(pickle.dumps(est))
    assert_outputs_equal(expected, outputs(restored, X, y), exact=True, context="after pickling")


def check_channel_mismatch(estimator, X, y):
    est = _fit(clone(estimator), X, y)
    wider = [np.hstack([c, np.zeros((len(c), 1))]) for c in X]
    for method in (*OUTPUT_METHODS, "score"):
        if hasattr(est, method):
            args = (wider, y) if method == "score" and y is not None else (wider,)
            with _raises(ValueError, match="channel", what=f"{method} on a channel more"):
                getattr(est, method)(*args)


def check_empty_collection(estimator, X, y):
    with _raises(ValueError, match="empty", what="fit on an empty collection"):
        _fit(clone(estimator), [], [] if y is not None else None)


def check_nan_rejected(estimator, X, y):
    if clone(estimator).__sklearn_tags__().input_tags.allow_nan:
        return
    bad = [np.array(c, dtype=float) for c in X]
    bad[1][0, 0] = np.nan
    with _raises(ValueError, match="clip 1", what="fit with NaN in clip 1"):
        _fit(clone(estimator), bad, y)


def check_too_short(estimator, X, y):
    min_frames = motion_tags(estimator).min_frames
    if min_frames <= 1:
        return
    short = [np.asarray(c) for c in X]
    short[2] = short[2][: min_frames - 1]
    with _raises(ValueError, match="clip 2", what="fit with clip 2 too short"):
        _fit(clone(estimator), short, y)


def check_deterministic(estimator, X, y):
    est = clone(estimator)
    if "random_state" in est.get_params():
        est.set_params(random_state=0)
    first = outputs(_fit(clone(est), X, y), X, y)
    second = outputs(_fit(clone(est), X, y), X, y)
    assert_outputs_equal(first, second, exact=True, context="two fits with the same seed")


def check_fit_idempotent(estimator, X, y):
    est = clone(estimator)
    if "random_state" in est.get_params():
        est.set_params(random_state=0)
    first = outputs(_fit(est, X, y), X, y)
    again = outputs(_fit(est, X, y), X, y)
    assert_outputs_equal(first, again, exact=True, context="refitting the same instance")


def check_n_jobs(estimator, X, y):
    est = clone(estimator)
    if "n_jobs" not in est.get_params():
        return
    if "random_state" in est.get_params():
        est.set_params(random_state=0)
    serial = outputs(_fit(clone(est).set_params(n_jobs=1), X, y), X, y)
    parallel = outputs(_fit(clone(est).set_params(n_jobs=2), X, y), X, y)
    assert_outputs_equal(serial, parallel, exact=True, context="n_jobs=1 vs n_jobs=2")


def check_set_output_pandas(estimator, X, y):
    kind = motion_tags(estimator).output_kind
    if not hasattr(estimator, "transform") or kind not in ("clips", "table"):
        return
    default = _as_list(_fit(clone(estimator), X, y).transform(X))
    est = _fit(clone(estimator).set_output(transform="pandas"), X, y)
    frame = est.transform(X)
    assert isinstance(frame, pd.DataFrame), "set_output(transform='pandas') must give a DataFrame"
    np.testing.assert_array_equal(np.asarray(frame.columns), est.get_feature_names_out())
    for a, b in zip(default, _as_list(frame)):
        np.testing.assert_array_equal(a, b)


def check_cross_val_score(estimator, X, y):
    model = scoring_model(estimator, y)
    if not hasattr(model, "score") and y is None:
        return
    scores = cross_val_score(model, X, y, cv=3, error_score="raise")
    assert len(scores) == 3 and np.isfinite(scores).all(), f"cross_val_score gave {scores}"


def check_grid_search(estimator, X, y, param_grid=None):
    model = scoring_model(estimator, y)
    if param_grid is None:
        name, value = next(iter(sorted(estimator.get_params(deep=False).items())), (None, None))
        if name is None:
            return
        param_grid = {name: [value]}
    if model is not estimator:
        step = model.steps[0][0]
        param_grid = {f"{step}__{k}": v for k, v in param_grid.items()}
    cv = 3 if y is not None else KFold(3)
    search = GridSearchCV(model, param_grid, cv=cv, error_score="raise").fit(X, y)
    assert np.isfinite(search.cv_results_["mean_test_score"]).all()
    for key, value in search.best_params_.items():
        assert value in param_grid[key]


CHECKS = (
    check_fit_returns_self,
    check_not_fitted,
    check_fitted_attributes,
    check_input_not_modified,
    check_containers_agree,
    check_pickle,
    check_channel_mismatch,
    check_empty_collection,
    check_nan_rejected,
    check_too_short,
    check_deterministic,
    check_fit_idempotent,
    check_n_jobs,
    check_set_output_pandas,
    check_cross_val_score,
    check_grid_search,
)


def clip_checks(case):
    """Yield ``(check_id, callable)`` pairs for one case."""
    estimator = case.estimator
    name = type(estimator).__name__

    def run(check, *args, **kwargs):
        X, y = case.data() if case.data is not None else make_check_data(estimator)
        check(*args, estimator, X, y, **kwargs)

    for sk_name in SKLEARN_DATA_FREE_CHECKS:
        if sk_name not in case.skip:
            yield f"{name}-{sk_name}", partial(run, check_sklearn, sk_name)
    for check in CHECKS:
        if check.__name__ in case.skip:
            continue
        kwargs = {"param_grid": case.param_grid} if check is check_grid_search else {}
        yield f"{name}-{check.__name__}", partial(run, check, **kwargs)


def parametrize_with_clip_checks(cases):
    """A ``pytest.mark.parametrize`` over every check of every case, one test each.

    Parameters
    ----------
    cases : list of ClipCase

    Returns
    -------
    mark : pytest.MarkDecorator
        Decorates a test taking one argument, ``check``, to call.

    Examples
    --------
    >>> from skmotion.preprocessing import ResampleClips
    >>> from skmotion.utils.estimator_checks import ClipCase, parametrize_with_clip_checks
    >>> mark = parametrize_with_clip_checks([ClipCase(ResampleClips(n_frames=8))])
    >>> mark.args[0], len(mark.args[1]) > 20
    ('check', True)
    """
    import pytest  # a test extra: imported only here

    ids, checks = [], []
    for case in cases:
        for check_id, check in clip_checks(case):
            ids.append(check_id)
            checks.append(check)
    return pytest.mark.parametrize("check", checks, ids=ids)


def make_check_data(estimator, *, n_channels=10, random_state=0):
    """Ragged labelled clips that any clip estimator should accept: 9 clips of 3 classes.

    The clips are at least 20 frames longer than the estimator's ``min_frames`` tag; the
    classes differ in their mean. Labels are strings (``"a"``, ``"b"``, ``"c"``).

    Parameters
    ----------
    estimator : estimator instance
    n_channels : int, default=10
    random_state : int, default=0

    Returns
    -------
    X : list of ndarray of shape (n_frames_i, n_channels)
    y : ndarray of str of shape (9,)

    Examples
    --------
    >>> from skmotion.preprocessing import ResampleClips
    >>> from skmotion.utils.estimator_checks import make_check_data
    >>> X, y = make_check_data(ResampleClips(n_frames=8))
    >>> len(X), X[0].shape[1], y[:3].tolist()
    (9, 10, ['a', 'b', 'c'])
    """
    rng = np.random.default_rng(random_state)
    base = max(1, motion_tags(estimator).min_frames) + 20
    lengths = base + np.array([0, 7, 3, 12, 5, 9, 14, 2, 11])
    t = np.linspace(0, 2 * np.pi, lengths.max())
    X = []
    for k, n in enumerate(lengths):
        wave = np.sin(np.outer(t[:n], 1 + np.arange(n_channels) / n_channels) + k)
        X.append(wave + (k % 3) + 0.1 * rng.normal(size=(n, n_channels)))
    return X, np.array(["a", "b", "c"] * 3)


def check_clip_estimator(estimator, data=None, *, param_grid=None, skip=None):
    """Run every clip conformance check on one estimator; raise at the first failure.

    Parameters
    ----------
    estimator : estimator instance
        Configured to be quick (small trees, few components).
    data : callable or tuple, default=None
        ``(X, y)`` or a callable returning it; by default :func:`make_check_data`.
    param_grid : dict, default=None
        A small grid for the GridSearchCV check.
    skip : dict, default=None
        Check name -> reason, for checks that do not apply.

    Returns
    -------
    passed : list of str
        The checks run, in order.

    Raises
    ------
    AssertionError
        The first check that fails, its message saying what went wrong.

    Examples
    --------
    >>> from skmotion.preprocessing import ResampleClips
    >>> from skmotion.utils.estimator_checks import check_clip_estimator
    >>> passed = check_clip_estimator(ResampleClips(n_frames=8))
    >>> "ResampleClips-check_pickle" in passed
    True
    """
    if isinstance(data, tuple):
        fixed = data
        data = lambda: fixed  # noqa: E731
    case = ClipCase(estimator, data, param_grid=param_grid, skip=dict(skip or {}))
    passed = []
    for check_id, check in clip_checks(case):
        try:
            check()
        except AssertionError as exc:
            raise AssertionError(f"{check_id} failed: {exc}") from exc
        passed.append(check_id)
    return passed
