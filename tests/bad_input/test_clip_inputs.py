"""Bad clip collections, labels and parameters given to every public clip estimator.

The table ``CLIP_CASES`` lists (bad input, expected exception, message fragment);
each is tried on every estimator in ``fit`` and in every output method of a
fitted estimator. The fragments name what is wrong and where (clip, frame,
channel), so a failure deep inside NumPy or SciPy does not pass.
"""

import numpy as np
import pandas as pd
import pytest
import scipy.sparse as sp

from tests.bad_input.estimators import ENTRIES, fit, output_methods


def _replace(X, i, clip):
    X = list(X)
    X[i] = clip
    return X


def _poke(value):
    def bad(X):
        clip = np.array(X[1], dtype=float)
        clip[2, 0] = value
        return _replace(X, 1, clip)

    return bad


def _words(X):
    clip = np.asarray(X[1]).astype(str)
    clip[1, 0] = "left"
    return _replace(X, 1, clip)


def _objects(X):
    clip = np.array(X[1], dtype=object)
    clip[1, 0] = "left"
    return _replace(X, 1, clip)


# (case id, make bad X from good X, exception, message fragment)
CLIP_CASES = [
    ("empty list", lambda X: [], ValueError, "X is an empty collection"),
    ("empty tuple", lambda X: (), ValueError, "X is an empty collection"),
    (
        "empty 3-D array",
        lambda X: np.empty((0, 5, X[0].shape[1])),
        ValueError,
        "X is an empty collection",
    ),
    (
        "clip with zero frames",
        lambda X: _replace(X, 1, X[1][:0]),
        ValueError,
        "clip 1 has no frames",
    ),
    (
        "clip with zero channels",
        lambda X: _replace(X, 1, X[1][:, :0]),
        ValueError,
        "clip 1 has no channels",
    ),
    ("different channel counts", lambda X: _replace(X, 2, X[2][:, :-1]), ValueError, "clip 2 has"),
    ("NaN", _poke(np.nan), ValueError, "clip 1 contains NaN at frame 2, channel 0"),
    ("inf", _poke(np.inf), ValueError, "clip 1 contains inf at frame 2, channel 0"),
    ("-inf", _poke(-np.inf), ValueError, "clip 1 contains -inf at frame 2, channel 0"),
    ("object array with a word", _objects, ValueError, "clip 1 has non-numeric data"),
    # (an array of numeric strings is converted, by design: see tests/utils/test_clips.py)
    ("string array with a word", _words, ValueError, "clip 1 has non-numeric data"),
    (
        "complex clip",
        lambda X: _replace(X, 1, np.asarray(X[1]) + 1j),
        ValueError,
        "clip 1 has complex values",
    ),
    ("1-D clip", lambda X: _replace(X, 0, np.asarray(X[0])[:, 0]), ValueError, "clip 0 is 1-D"),
    ("3-D clip", lambda X: _replace(X, 0, np.asarray(X[0])[None]), ValueError, "clip 0 is 3-D"),
    ("a single 2-D clip", lambda X: np.asarray(X[0]), ValueError, "For a single clip pass [clip]"),
    (
        "sparse clip",
        lambda X: _replace(X, 0, sp.csr_matrix(np.asarray(X[0]))),
        TypeError,
        "clip 0 is a sparse matrix",
    ),
    ("dict", lambda X: dict(enumerate(X)), TypeError, "got dict"),
    ("None", lambda X: None, TypeError, "got NoneType"),
    ("a string", lambda X: "walk.bvh", TypeError, "got str"),
    (
        "flat DataFrame",
        lambda X: pd.DataFrame(np.asarray(X[0])),
        ValueError,
        "two-level (clip, frame) MultiIndex",
    ),
]

# Inputs that are valid for one estimator: KMeansPrimitiveController takes segment
# codes, where a clip without segments has zero frames; the index's predict(None)
# and kneighbors(None) query its own clips, as sklearn's neighbors do.
VALID = {
    ("KMeansPrimitiveController", "fit", "clip with zero frames"),
    ("KMeansPrimitiveController", "predict", "clip with zero frames"),
    ("IntervalIndexNeighbors", "predict", "None"),
}


# IntervalIndexNeighbors also takes a 2-D table of feature vectors (it runs sklearn's
# checks): a 2-D array or a flat DataFrame is a table there, not a bad clip collection.
TABLE_OVERRIDES = {
    ("fit", "a single 2-D clip"): (ValueError, "y has 9 labels, but X has"),
    ("fit", "flat DataFrame"): (ValueError, "y has 9 labels, but X has"),
    ("predict", "a single 2-D clip"): (ValueError, "was fitted on clips; pass the same kind"),
    ("predict", "flat DataFrame"): (ValueError, "was fitted on clips; pass the same kind"),
}


def _cases(stage):
    for name, entry in ENTRIES.items():
        for case_id, make_bad, error, fragment in CLIP_CASES:
            if (name, stage, case_id) in VALID:
                continue
            if name == "IntervalIndexNeighbors":
                error, fragment = TABLE_OVERRIDES.get((stage, case_id), (error, fragment))
            yield pytest.param(
                entry, case_id, make_bad, error, fragment, id=f"{name}-{stage}-{case_id}"
            )


def _check(error, fragment, call):
    with pytest.raises(error) as info:
        call()
    assert fragment in str(info.value), f"message does not say {fragment!r}: {info.value}"
    return info.value


@pytest.mark.parametrize("entry, case_id, make_bad, error, fragment", list(_cases("fit")))
def test_fit_rejects(entry, case_id, make_bad, error, fragment):
    X, y = entry.data()
    _check(error, fragment, lambda: fit(entry, make_bad(X), y))


@pytest.mark.parametrize("entry, case_id, make_bad, error, fragment", list(_cases("predict")))
def test_output_methods_reject(entry, case_id, make_bad, error, fragment):
    X, _ = entry.data()
    estimator = fit(entry)
    for method in output_methods(estimator):
        _check(error, fragment, lambda: getattr(estimator, method)(make_bad(X)))
