"""Every public clip estimator with small valid data, for the bad-input tables.

Each entry builds a fresh estimator and its fit data: a list of clips and labels
(or None). The data are small so that a whole table of bad inputs runs in seconds.
"""

from dataclasses import dataclass
from functools import cache

from skmotion.control import KMeansPrimitiveController
from skmotion.datasets import humanoid_skeleton, make_motions
from skmotion.decomposition import EigenMovementPCA, SVDFeatureExtractor
from skmotion.neighbors import IntervalIndexNeighbors
from skmotion.preprocessing import (
    FlattenClips,
    LowPassFilter,
    ResampleClips,
    VirtualMarkerTransform,
)
from skmotion.tree import MotionTreeHMM
from tests.decomposition.test_eigenmovements import stroke_clips

OUTPUT_METHODS = ("predict", "predict_proba", "score_samples", "decode", "transform", "kneighbors")


@cache
def _motions():
    data = make_motions(
        n_clips_per_class=3,
        n_subjects=3,
        classes=["walk", "wave", "squat"],
        duration=(0.6, 0.9),
        random_state=0,
    )
    return tuple(data.clips), data.target_names[data.target]


def joint_angles():
    clips, y = _motions()
    return [c.copy() for c in clips], y.copy()


def without_root():
    clips, y = joint_angles()
    return [c[:, 6:12].copy() for c in clips], y


def equal_length():
    clips, y = without_root()
    n = min(len(c) for c in clips)
    return [c[:n] for c in clips], None


def strokes():
    return stroke_clips(6, seed=0), None


@cache
def _codes():
    clips, _ = strokes()
    return tuple(EigenMovementPCA(3, n_samples=20).fit_transform(clips))


def codes():
    return [c.copy() for c in _codes()], None


@dataclass(frozen=True)
class Entry:
    """An estimator factory, its data and whether it is a classifier (needs y)."""

    name: str
    make: object
    data: object
    classifier: bool = False


SKELETON = humanoid_skeleton()

ENTRIES = {
    e.name: e
    for e in [
        Entry(
            "MotionTreeHMM",
            lambda: MotionTreeHMM(max_depth=3, min_samples_leaf=4),
            without_root,
            True,
        ),
        Entry(
            "IntervalIndexNeighbors", lambda: IntervalIndexNeighbors(n_levels=2), without_root, True
        ),
        Entry("SVDFeatureExtractor", lambda: SVDFeatureExtractor(n_components=3), without_root),
        Entry("EigenMovementPCA", lambda: EigenMovementPCA(3, n_samples=20), strokes),
        Entry(
            "KMeansPrimitiveController",
            lambda: KMeansPrimitiveController(3, n_init=1, random_state=0),
            codes,
        ),
        Entry(
            "VirtualMarkerTransform",
            lambda: VirtualMarkerTransform(SKELETON, frame_rate=30.0),
            joint_angles,
        ),
        Entry("ResampleClips", lambda: ResampleClips(n_frames=8), without_root),
        Entry("FlattenClips", FlattenClips, equal_length),
        Entry("LowPassFilter", lambda: LowPassFilter(order=2), without_root),
    ]
}


_DATA = object()


def fit(entry, X=_DATA, y=_DATA):
    """The entry's estimator fitted on X and y (by default its own valid data)."""
    data_X, data_y = entry.data()
    X = data_X if X is _DATA else X
    y = data_y if y is _DATA else y
    estimator = entry.make()
    return estimator.fit(X, y) if entry.classifier else estimator.fit(X)


def output_methods(estimator):
    return [m for m in OUTPUT_METHODS if hasattr(estimator, m)]
