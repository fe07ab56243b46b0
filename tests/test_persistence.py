"""Persistence: every estimator and data structure round trips through pickle and joblib;
pickles record the skmotion version and refuse to load into an incompatible one."""

import importlib
import inspect
import pickle

import joblib
import numpy as np
import pytest
from sklearn.base import BaseEstimator

import skmotion
from skmotion.base import IncompatibleVersionError, VersionedStateMixin, compatible_versions
from skmotion.control import KMeansPrimitiveController
from skmotion.datasets import humanoid_skeleton, make_motions, make_walks
from skmotion.decomposition import EigenMovementPCA, SVDFeatureExtractor
from skmotion.io import as_motions
from skmotion.live import ActivitySegmenter, GestureDetector, LinearGestureDetector
from skmotion.neighbors import IntervalIndexNeighbors, MotionMatcher
from skmotion.preprocessing import (
    FillGaps,
    FlattenClips,
    LowPassFilter,
    ResampleClips,
    ToAeon,
    VirtualMarkerTransform,
)
from skmotion.recognition import MotionClassifier
from skmotion.tree import MotionTreeEncoder, MotionTreeHMM
from tests.clip_conformance import _as_list, assert_outputs_equal, outputs
from tests.decomposition.test_eigenmovements import stroke_clips
from tests.preprocessing.test_fill_gaps import _holed_case as _holed_positions


def _motions():
    data = make_motions(
        n_clips_per_class=3, classes=["walk", "jump", "wave"], duration=(1.0, 1.5), random_state=1
    )
    return [c[:, 6:] for c in data.clips], data.target_names[data.target]


def _joint_angles():
    data = make_motions(
        n_clips_per_class=2, classes=["walk", "squat"], duration=(0.6, 1.0), random_state=0
    )
    return data.clips, data.target


def _walk_takes():
    data = make_walks(1, turn=1.0, random_state=0)
    return as_motions(data.clips, data.skeleton, data.frame_rate), None


def _strokes():
    return stroke_clips(9), None


def _codes():
    return EigenMovementPCA(4, n_samples=20).fit_transform(stroke_clips(12, seed=2)), None


def _equal_length():
    clips, y = _motions()
    return [c[:20] for c in clips], y


def _extra(name, *args, **kwargs):
    """A method beyond the common outputs, with its arguments."""
    return lambda est, X: _as_list(getattr(est, name)(X, *args, **kwargs))


# Estimator, data, and the methods beyond the common ones (predict, transform, score...).
CASES = {
    "MotionTreeHMM": (
        MotionTreeHMM(max_depth=3, min_samples_leaf=4),
        _motions,
        {
            # decode gives (logprob, paths), as hmmlearn's does
            "decode": lambda est, X: [est.decode(X)[0], *_as_list(est.decode(X)[1])],
            "predict_next": lambda est, X: [est.predict_next(X, 2).probabilities],
            "novelty_score": _extra("novelty_score"),
        },
    ),
    "MotionTreeEncoder": (MotionTreeEncoder(max_depth=3, layers="all"), _motions, {}),
    "MotionClassifier": (
        MotionClassifier(max_depth=3),
        _motions,
        {"novelty_score": lambda est, X: [est.novelty_score(X)]},
    ),
    "IntervalIndexNeighbors": (
        IntervalIndexNeighbors(n_levels=3, n_neighbors=2),
        _motions,
        {
            "kneighbors": lambda est, X: list(est.kneighbors(X)),
            "candidates": lambda est, X: [np.concatenate(est.candidates(X))],
        },
    ),
    "MotionMatcher": (
        MotionMatcher(),
        _walk_takes,
        {
            "kneighbors": lambda est, X: list(est.kneighbors(est.features_[::9], n_neighbors=2)),
            "frame_features": _extra("frame_features"),
        },
    ),
    "SVDFeatureExtractor": (
        SVDFeatureExtractor(n_components=3, weighting="first_two"),
        _motions,
        {},
    ),
    "EigenMovementPCA": (
        EigenMovementPCA(n_components=3, n_samples=20),
        _strokes,
        {"reconstruct": _extra("reconstruct"), "segment": _extra("segment")},
    ),
    "KMeansPrimitiveController": (
        KMeansPrimitiveController(4, n_init=2, random_state=0),
        _codes,
        {"quantize": _extra("quantize")},
    ),
    "VirtualMarkerTransform": (
        VirtualMarkerTransform(humanoid_skeleton(), frame_rate=30.0),
        _joint_angles,
        {},
    ),
    "ResampleClips": (ResampleClips(n_frames=7, kind="cubic"), _motions, {}),
    "FlattenClips": (FlattenClips(), _equal_length, {}),
    "LowPassFilter": (LowPassFilter(order=4), _motions, {}),
    "FillGaps": (FillGaps(layout="kinect_v1"), _holed_positions, {}),
    "ToAeon": (ToAeon(), _motions, {}),
    "GestureDetector": (
        GestureDetector(window=8, random_state=0),
        _motions,
        {"scores": lambda est, X: [proba for _, proba in est.scores(X)]},
    ),
    "LinearGestureDetector": (
        LinearGestureDetector(n_segments=2, segment=3, random_state=0),
        _motions,
        {"scores": lambda est, X: [proba for _, proba in est.scores(X)]},
    ),
    "ActivitySegmenter": (
        ActivitySegmenter(window=8),
        _motions,
        {"predict_proba_frames": lambda est, X: est.predict_proba_frames(X)},
    ),
}


def skmotion_estimators():
    """Every public estimator class of skmotion's subpackages."""
    found = {}
    for name in skmotion._SUBPACKAGES:
        module = importlib.import_module(f"skmotion.{name}")
        for public in getattr(module, "__all__", []):
            obj = getattr(module, public)
            if inspect.isclass(obj) and issubclass(obj, BaseEstimator):
                found[obj.__name__] = obj
    return found


def _fitted(name):
    estimator, data, extra = CASES[name]
    X, y = data()
    fitted = estimator.fit(X, y) if y is not None else estimator.fit(X)
    return fitted, X, y, extra


def _results(estimator, X, y, extra):
    results = outputs(estimator, X, y)
    results.update(
        {method: [np.asarray(a) for a in get(estimator, X)] for method, get in extra.items()}
    )
    return results


def test_every_estimator_is_versioned_and_has_a_case():
    estimators = skmotion_estimators()
    unversioned = [n for n, cls in estimators.items() if not issubclass(cls, VersionedStateMixin)]
    assert not unversioned, (
        f"estimators without VersionedStateMixin (derive from ClipEstimatorMixin): {unversioned}"
    )
    missing = sorted(set(estimators) - set(CASES))
    assert not missing, f"add a persistence case to tests/test_persistence.py for {missing}"


@pytest.mark.parametrize("name", sorted(CASES))
def test_pickle_and_joblib_round_trip(name, tmp_path):
    estimator, X, y, extra = _fitted(name)
    expected = _results(estimator, X, y, extra)
    restored = pickle.loads(pickle.dumps(estimator))
    assert_outputs_equal(
        expected, _results(restored, X, y, extra), exact=True, context=f"{name} after pickle"
    )
    joblib.dump(estimator, tmp_path / "model.joblib", compress=3)
    loaded = joblib.load(tmp_path / "model.joblib")
    assert_outputs_equal(
        expected, _results(loaded, X, y, extra), exact=True, context=f"{name} after joblib"
    )
    assert "_skmotion_version" not in vars(loaded), (
        "the version belongs to the pickle, not to the object"
    )


def test_data_structures_round_trip():
    index, X, _, _ = _fitted("IntervalIndexNeighbors")
    vectors = index.feature_extractor_.transform(X)
    restored = pickle.loads(pickle.dumps(index.index_))
    for a, b in zip(index.index_.candidates(vectors), restored.candidates(vectors)):
        np.testing.assert_array_equal(a, b)
    model, X, _, _ = _fitted("MotionTreeHMM")
    frames = (np.concatenate(X) - model.center_) / model.scale_
    tree = pickle.loads(pickle.dumps(model.tree_))
    np.testing.assert_array_equal(tree.apply(frames), model.tree_.apply(frames))
    graphs = pickle.loads(pickle.dumps(model.graphs_))
    layer = model.layer_
    np.testing.assert_array_equal(graphs.matrix(layer, 1), model.graphs_.matrix(layer, 1))


@pytest.mark.parametrize(
    "saved, running, expected",
    [
        ("0.1.0", "0.1.0", True),
        ("0.1.0", "0.1.7", True),  # patch releases keep the fitted state's layout
        ("0.1.7", "0.1.0", True),
        ("0.1.0", "0.2.0", False),
        ("0.2.0", "0.1.0", False),
        ("1.1.0", "0.1.0", False),
        ("0.1.0.dev0", "0.1.2", True),
        (None, "0.1.0", False),  # no version recorded
        ("garbage", "0.1.0", False),
    ],
)
def test_compatible_versions(saved, running, expected):
    assert compatible_versions(saved, running) is expected


@pytest.mark.parametrize("name", ["MotionTreeHMM", "IntervalIndexNeighbors", "ResampleClips"])
def test_tampered_version_is_refused(name, tmp_path):
    estimator, X, y, extra = _fitted(name)
    version = skmotion.__version__.encode()
    data = pickle.dumps(estimator)
    assert data.count(version) == 1, "the pickle holds the version once"
    major, minor = map(int, skmotion.__version__.split(".")[:2])
    newer = f"{major}.{minor + 1}.0".encode()
    # Same length keeps the pickle valid, so only the recorded version changes.
    tampered = data.replace(version, newer.ljust(len(version), b"0")[: len(version)])
    message = (
        rf"saved by skmotion {major}\.{minor + 1}\.0 and cannot be loaded by skmotion "
        rf"{skmotion.__version__}"
    )
    with pytest.raises(IncompatibleVersionError, match=message):
        pickle.loads(tampered)
    path = tmp_path / "model.joblib"
    path.write_bytes(tampered)
    with pytest.raises(IncompatibleVersionError, match="refit it"):
        joblib.load(path)


def test_running_a_newer_minor_version_refuses_and_a_patch_release_loads(monkeypatch):
    estimator, X, y, extra = _fitted("LowPassFilter")
    data = pickle.dumps(estimator)
    major, minor, *_ = skmotion.__version__.split(".")
    monkeypatch.setattr(skmotion, "__version__", f"{major}.{minor}.99")
    assert_outputs_equal(outputs(estimator, X), outputs(pickle.loads(data), X), exact=True)
    monkeypatch.setattr(skmotion, "__version__", f"{major}.{int(minor) + 1}.0")
    with pytest.raises(
        IncompatibleVersionError, match=f"LowPassFilter was saved by skmotion {major}.{minor}"
    ):
        pickle.loads(data)


def test_missing_version_is_refused():
    estimator = ResampleClips(n_frames=3)
    state = estimator.__getstate__()
    del state["_skmotion_version"]
    blank = ResampleClips.__new__(ResampleClips)
    with pytest.raises(IncompatibleVersionError, match="unknown skmotion version"):
        blank.__setstate__(state)
