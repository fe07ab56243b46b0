"""Clip conformance checks of the sklearn integration.

sklearn's own checks that need no data, ``set_output``/``get_feature_names_out``,
``cross_val_score`` and ``GridSearchCV``. Run through :mod:`skmotion.estimator_checks`.
"""

import numpy as np
import pandas as pd
from sklearn.base import clone, is_classifier, is_regressor
from sklearn.linear_model import LogisticRegression
from sklearn.model_selection import GridSearchCV, KFold, cross_val_score
from sklearn.pipeline import make_pipeline

from skmotion.estimator_checks._helpers import _as_list, _fit, motion_tags
from skmotion.preprocessing import FlattenClips, ResampleClips

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


def check_sklearn(name, estimator, X, y):
    """sklearn's data-free check ``name`` on a clone of the estimator."""
    # Imported here: sklearn's checks module imports pytest when it is installed.
    from sklearn.utils import estimator_checks as sk_checks

    getattr(sk_checks, name)(type(estimator).__name__, clone(estimator))


def check_set_output_pandas(estimator, X, y):
    """``set_output(transform='pandas')`` agrees with the default and the names."""
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
    """``cross_val_score`` runs and gives finite scores."""
    model = scoring_model(estimator, y)
    if not hasattr(model, "score") and y is None:
        return
    scores = cross_val_score(model, X, y, cv=3, error_score="raise")
    assert len(scores) == 3 and np.isfinite(scores).all(), f"cross_val_score gave {scores}"


def check_grid_search(estimator, X, y, param_grid=None):
    """``GridSearchCV`` runs over a small grid and picks from it."""
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
