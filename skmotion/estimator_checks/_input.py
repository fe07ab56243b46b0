"""Clip conformance checks of the input: containers, channels, empty, NaN and short clips.

Every container kind gives the same results; bad collections are rejected with a
``ValueError`` naming what and where. Run through :mod:`skmotion.estimator_checks`.
"""

import numpy as np
import pandas as pd
from sklearn.base import clone

from skmotion.estimator_checks._helpers import (
    OUTPUT_METHODS,
    _fit,
    _raises,
    as_dataframe,
    assert_outputs_equal,
    equal_length,
    motion_tags,
    outputs,
)


def check_containers_agree(estimator, X, y):
    """Lists, tuples, 3-D arrays and DataFrames agree; clips come back in kind."""
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


def check_channel_mismatch(estimator, X, y):
    """One channel more than in fit is a ``ValueError`` about channels."""
    est = _fit(clone(estimator), X, y)
    wider = [np.hstack([c, np.zeros((len(c), 1))]) for c in X]
    for method in (*OUTPUT_METHODS, "score"):
        if hasattr(est, method):
            args = (wider, y) if method == "score" and y is not None else (wider,)
            with _raises(ValueError, match="channel", what=f"{method} on a channel more"):
                getattr(est, method)(*args)


def check_empty_collection(estimator, X, y):
    """``fit`` on an empty collection is a ``ValueError`` saying it is empty."""
    with _raises(ValueError, match="empty", what="fit on an empty collection"):
        _fit(clone(estimator), [], [] if y is not None else None)


def check_nan_rejected(estimator, X, y):
    """NaN in clip 1 is a ``ValueError`` naming the clip (unless NaN is allowed)."""
    if clone(estimator).__sklearn_tags__().input_tags.allow_nan:
        return
    bad = [np.array(c, dtype=float) for c in X]
    bad[1][0, 0] = np.nan
    with _raises(ValueError, match="clip 1", what="fit with NaN in clip 1"):
        _fit(clone(estimator), bad, y)


def check_too_short(estimator, X, y):
    """A clip shorter than ``min_frames`` is a ``ValueError`` naming the clip."""
    min_frames = motion_tags(estimator).min_frames
    if min_frames <= 1:
        return
    short = [np.asarray(c) for c in X]
    short[2] = short[2][: min_frames - 1]
    with _raises(ValueError, match="clip 2", what="fit with clip 2 too short"):
        _fit(clone(estimator), short, y)
