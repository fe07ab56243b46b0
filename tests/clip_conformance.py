"""The clip conformance checks, now installed with skmotion: see skmotion.estimator_checks.

This module re-exports them for the project's tests written against the old place.
"""

from skmotion.estimator_checks import *  # noqa: F403
from skmotion.estimator_checks import (  # noqa: F401
    as_dataframe,
    assert_outputs_equal,
    check_channel_mismatch,
    check_containers_agree,
    check_cross_val_score,
    check_deterministic,
    check_empty_collection,
    check_fit_idempotent,
    check_fit_returns_self,
    check_fitted_attributes,
    check_grid_search,
    check_input_not_modified,
    check_n_jobs,
    check_nan_rejected,
    check_not_fitted,
    check_pickle,
    check_set_output_pandas,
    check_sklearn,
    check_too_short,
    equal_length,
    motion_tags,
    outputs,
    scoring_model,
)
from skmotion.estimator_checks._helpers import _as_list, _fit  # noqa: F401
