"""Conformance checks for estimators whose samples are motion clips.

The cases and the runners are in ``_cases.py``; the checks, by what they
check, in ``_fitting.py`` (fitting, pickles, determinism), ``_input.py``
(containers, bad input) and ``_sklearn.py`` (sklearn's own data-free checks,
set_output, cross-validation), over ``_helpers.py`` (every method's outputs,
comparing them). This package sits beside ``skmotion.utils``, not in it: the
checks fit pipelines of skmotion's own transformers, which ``utils`` (imported
by every estimator) must not import.

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

    from skmotion.estimator_checks import ClipCase, parametrize_with_clip_checks

    @parametrize_with_clip_checks([ClipCase(MyEstimator(), make_data)])
    def test_conformance(check):
        check()

``make_data`` returns ``(X, y)``: a list of clips (at least 3 clips per class for
classifiers) and labels, or ``y=None``. pytest is imported only by
:func:`parametrize_with_clip_checks`; the rest needs only skmotion's own dependencies.
"""

from skmotion.estimator_checks._cases import (
    CHECKS,
    ClipCase,
    check_clip_estimator,
    clip_checks,
    make_check_data,
    parametrize_with_clip_checks,
)

# The checks themselves, importable from here too.
from skmotion.estimator_checks._fitting import (  # noqa: F401
    check_deterministic,
    check_fit_idempotent,
    check_fit_returns_self,
    check_fitted_attributes,
    check_input_not_modified,
    check_n_jobs,
    check_not_fitted,
    check_pickle,
)
from skmotion.estimator_checks._helpers import (  # noqa: F401
    OUTPUT_METHODS,
    as_dataframe,
    assert_outputs_equal,
    equal_length,
    motion_tags,
    outputs,
)
from skmotion.estimator_checks._input import (  # noqa: F401
    check_channel_mismatch,
    check_containers_agree,
    check_empty_collection,
    check_nan_rejected,
    check_too_short,
)
from skmotion.estimator_checks._sklearn import (  # noqa: F401
    SKLEARN_DATA_FREE_CHECKS,
    check_cross_val_score,
    check_grid_search,
    check_set_output_pandas,
    check_sklearn,
    scoring_model,
)

__all__ = [
    "CHECKS",
    "ClipCase",
    "SKLEARN_DATA_FREE_CHECKS",
    "check_clip_estimator",
    "clip_checks",
    "make_check_data",
    "parametrize_with_clip_checks",
]
