"""The conformance checks pass a correct estimator and catch broken ones; every public
estimator of skmotion is run through them."""

import ast
import importlib
import inspect
import pathlib
import pkgutil
import subprocess
import sys

import numpy as np
import pytest
from sklearn.base import BaseEstimator, ClassifierMixin
from sklearn.utils.validation import check_is_fitted

import skmotion
import skmotion.estimator_checks as cc
from skmotion.base import ClipEstimatorMixin
from skmotion.utils import check_clips


class ClipMeanCentroid(ClipEstimatorMixin, ClassifierMixin, BaseEstimator):
    """Nearest centroid on clip means: small, correct, with a seed and n_jobs."""

    def __init__(self, shrink=0.0, random_state=None, n_jobs=None):
        self.shrink = shrink
        self.random_state = random_state
        self.n_jobs = n_jobs

    def fit(self, X, y):
        clips = check_clips(X, estimator=self, reset=True)
        features = self._features(clips)
        self.classes_, y = np.unique(y, return_inverse=True)
        self.centroids_ = np.stack([features[y == k].mean(0) for k in range(len(self.classes_))])
        self.centroids_ *= 1 - self.shrink
        return self

    def _features(self, clips):
        return np.stack([c.mean(axis=0) for c in clips])

    def decision_function(self, X):
        check_is_fitted(self)
        features = self._features(check_clips(X, estimator=self))
        return -((features[:, None] - self.centroids_[None]) ** 2).sum(-1)

    def predict(self, X):
        scores = self.decision_function(X)
        return self.classes_[scores.argmax(1)]


class MutatesInput(ClipMeanCentroid):
    def fit(self, X, y):
        clips = check_clips(X, estimator=self, reset=True)
        clips[0] -= clips[0].mean(axis=0)  # centres the caller's array in place
        return super().fit(clips, y)


class SkipsChannelCheck(ClipMeanCentroid):
    def decision_function(self, X):
        check_is_fitted(self)
        features = np.stack([np.asarray(c)[:, : self.n_features_in_].mean(0) for c in X])
        return -((features[:, None] - self.centroids_[None]) ** 2).sum(-1)


class IgnoresSeed(ClipMeanCentroid):
    def fit(self, X, y):
        super().fit(X, y)
        self.centroids_ = self.centroids_ + np.random.default_rng().normal(
            size=self.centroids_.shape
        )
        return self


class SetsAttributeInInit(ClipMeanCentroid):
    def __init__(self, shrink=0.0, random_state=None, n_jobs=None):
        super().__init__(shrink, random_state, n_jobs)
        self.centroids_ = None


class ForgetsEmptyCheck(ClipMeanCentroid):
    def fit(self, X, y):
        if len(X) == 0:
            self.classes_ = np.array([])
            return self
        return super().fit(X, y)


class KeepsNaN(ClipMeanCentroid):
    def fit(self, X, y):
        clips = check_clips(X, estimator=self, reset=True, allow_nan=True)
        return super().fit([np.nan_to_num(c) for c in clips], y)


class ParallelDiffers(ClipMeanCentroid):
    def fit(self, X, y):
        super().fit(X, y)
        self.centroids_ = self.centroids_ + (self.n_jobs or 1) * 1e-9
        return self


def _data():
    rng = np.random.default_rng(0)
    X = [rng.normal(size=(n, 3)) + (k % 3) for k, n in enumerate([8, 12, 9, 15, 10, 11, 14, 9, 13])]
    return X, np.array(["a", "b", "c"] * 3)


@cc.parametrize_with_clip_checks(
    [cc.ClipCase(ClipMeanCentroid(), _data, param_grid={"shrink": [0.0, 0.1]})]
)
def test_correct_estimator_passes(check):
    check()


@pytest.mark.parametrize(
    "estimator, check",
    [
        (MutatesInput(), cc.check_input_not_modified),
        (SkipsChannelCheck(), cc.check_channel_mismatch),
        (IgnoresSeed(), cc.check_deterministic),
        (ForgetsEmptyCheck(), cc.check_empty_collection),
        (KeepsNaN(), cc.check_nan_rejected),
        (ParallelDiffers(), cc.check_n_jobs),
    ],
    ids=lambda v: type(v).__name__ if isinstance(v, BaseEstimator) else v.__name__,
)
def test_broken_estimators_are_caught(estimator, check):
    X, y = _data()
    with pytest.raises((AssertionError, pytest.fail.Exception)):
        check(estimator, X, y)


def test_attribute_set_in_init_is_caught():
    with pytest.raises(AssertionError):
        cc.check_sklearn("check_no_attributes_set_in_init", SetsAttributeInInit(), *_data())


def test_every_check_is_generated_once():
    ids = [name for name, _ in cc.clip_checks(cc.ClipCase(ClipMeanCentroid(), _data))]
    assert len(ids) == len(set(ids)) == len(cc.CHECKS) + len(cc.SKLEARN_DATA_FREE_CHECKS)
    skipped = cc.ClipCase(ClipMeanCentroid(), _data, skip={"check_pickle": "reason"})
    assert "ClipMeanCentroid-check_pickle" not in [name for name, _ in cc.clip_checks(skipped)]


def test_check_clip_estimator_runs_every_check_and_names_the_failure():
    passed = cc.check_clip_estimator(ClipMeanCentroid(), _data)
    assert len(passed) == len(cc.CHECKS) + len(cc.SKLEARN_DATA_FREE_CHECKS)
    # a seedless estimator gives other results on every fit: the first check comparing two
    # fits fails, and the message names it
    with pytest.raises(AssertionError, match=r"IgnoresSeed-check_containers_agree failed"):
        cc.check_clip_estimator(IgnoresSeed(), _data())
    skipped = cc.check_clip_estimator(ClipMeanCentroid(), _data, skip={"check_pickle": "why"})
    assert "ClipMeanCentroid-check_pickle" not in skipped and len(skipped) == len(passed) - 1


def test_default_data_fits_the_estimator():
    X, y = cc.make_check_data(ClipMeanCentroid())
    assert len(X) == 9 and {c.shape[1] for c in X} == {10} and min(len(c) for c in X) >= 21
    assert cc.check_clip_estimator(ClipMeanCentroid())  # no data given: the default


def test_importing_the_checks_needs_no_pytest():
    code = (
        "import sys; sys.modules['pytest'] = None\n"  # any `import pytest` now fails
        "from skmotion.estimator_checks import check_clip_estimator\n"
        "from skmotion.preprocessing import ResampleClips\n"
        "print(len(check_clip_estimator(ResampleClips(n_frames=8))))"
    )
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    assert int(result.stdout) > 20


def _public_estimators():
    found = set()
    for info in pkgutil.walk_packages(skmotion.__path__, "skmotion."):
        if any(part.startswith("_") for part in info.name.split(".")[1:]):
            continue
        module = importlib.import_module(info.name)
        for name in getattr(module, "__all__", []):
            obj = getattr(module, name)
            if inspect.isclass(obj) and issubclass(obj, BaseEstimator):
                found.add(name)
    return found


def _checked_in_tests():
    """Estimator classes constructed as the first argument of a ClipCase in tests/."""
    names = set()
    for path in pathlib.Path(__file__).parent.rglob("test_*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if (
                isinstance(node, ast.Call)
                and getattr(node.func, "attr", getattr(node.func, "id", None)) == "ClipCase"
                and node.args
                and isinstance(node.args[0], ast.Call)
            ):
                func = node.args[0].func
                names.add(getattr(func, "id", getattr(func, "attr", None)))
    return names


def test_every_public_estimator_runs_the_checks():
    estimators = _public_estimators()
    assert {"MotionTreeHMM", "EigenMovementPCA", "ResampleClips"} <= estimators
    missing = sorted(estimators - _checked_in_tests())
    assert not missing, (
        f"no ClipCase runs the clip conformance checks on {missing}: add one to its tests "
        "with skmotion.estimator_checks.parametrize_with_clip_checks"
    )
