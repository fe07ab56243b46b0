"""The clip conformance checks as one list, run on one estimator or as pytest tests.

:class:`ClipCase` (an estimator and its data), ``CHECKS`` (every check, in
order), :func:`check_clip_estimator` and :func:`parametrize_with_clip_checks`.
"""

from dataclasses import dataclass, field
from functools import partial

import numpy as np

from skmotion.estimator_checks._fitting import (
    check_deterministic,
    check_fit_idempotent,
    check_fit_returns_self,
    check_fitted_attributes,
    check_input_not_modified,
    check_n_jobs,
    check_not_fitted,
    check_pickle,
)
from skmotion.estimator_checks._helpers import (
    motion_tags,
)
from skmotion.estimator_checks._input import (
    check_channel_mismatch,
    check_containers_agree,
    check_empty_collection,
    check_nan_rejected,
    check_too_short,
)
from skmotion.estimator_checks._sklearn import (
    SKLEARN_DATA_FREE_CHECKS,
    check_cross_val_score,
    check_grid_search,
    check_set_output_pandas,
    check_sklearn,
)

__all__ = [
    "CHECKS",
    "SKLEARN_DATA_FREE_CHECKS",
    "ClipCase",
    "check_clip_estimator",
    "clip_checks",
    "make_check_data",
    "parametrize_with_clip_checks",
]


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
    >>> from skmotion.estimator_checks import ClipCase, parametrize_with_clip_checks
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
    >>> from skmotion.estimator_checks import make_check_data
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
    >>> from skmotion.estimator_checks import check_clip_estimator
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
