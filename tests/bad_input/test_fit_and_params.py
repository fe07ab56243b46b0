"""Bad labels, calls out of order, channel counts different from fit, short clips
and wrong frame rates, for every public clip estimator and the functions that
take a frame rate.

Each table row is (what, bad input, expected exception, message fragment).
"""

import re

import numpy as np
import pytest
from sklearn.exceptions import NotFittedError

from skmotion.datasets import humanoid_skeleton, make_motions, make_repeated_motions
from skmotion.decomposition import EigenMovementPCA
from skmotion.io import Motion
from skmotion.preprocessing import (
    ResampleClips,
    VirtualMarkerTransform,
    energy_segments,
    movement_energy,
    segment_clip,
    zvc_segments,
)
from tests.bad_input.estimators import ENTRIES, fit, output_methods

CLASSIFIERS = [e for e in ENTRIES.values() if e.classifier]


def _ids(entries):
    return [e.name for e in entries]


@pytest.mark.parametrize("entry", list(ENTRIES.values()), ids=_ids(ENTRIES.values()))
def test_output_before_fit_is_not_fitted_error(entry):
    X, _ = entry.data()
    estimator = entry.make()
    methods = output_methods(estimator)
    assert methods, "every clip estimator has an output method"
    for method in methods:
        with pytest.raises(NotFittedError, match="not fitted yet"):
            getattr(estimator, method)(X)


@pytest.mark.parametrize("entry", list(ENTRIES.values()), ids=_ids(ENTRIES.values()))
def test_channel_count_different_from_fit(entry):
    X, _ = entry.data()
    estimator = fit(entry)
    extra = [np.c_[np.asarray(c), np.zeros(len(c))] for c in X]
    n = X[0].shape[1]
    for method in output_methods(estimator):
        with pytest.raises(
            ValueError,
            match=f"X has {n + 1} channels, but {entry.name} was fitted with {n} channels",
        ):
            getattr(estimator, method)(extra)


# (case id, labels from the good labels, message pattern)
LABEL_CASES = [
    ("too few labels", lambda y: y[:-1], r"y has \d+ labels,? but X h(as|olds) \d+ clips"),
    (
        "too many labels",
        lambda y: np.r_[y, y[:1]],
        r"y has \d+ labels,? but X h(as|olds) \d+ clips",
    ),
    ("2-D labels", lambda y: np.c_[y, y], "y"),
    ("continuous labels", lambda y: np.linspace(0, 1, len(y)), "Unknown label type"),
]


@pytest.mark.parametrize("entry", CLASSIFIERS, ids=_ids(CLASSIFIERS))
@pytest.mark.parametrize(
    "case_id, make_bad, fragment", LABEL_CASES, ids=[c[0] for c in LABEL_CASES]
)
def test_bad_labels(entry, case_id, make_bad, fragment):
    X, y = entry.data()
    with pytest.raises(ValueError) as info:
        fit(entry, X, make_bad(y))
    assert re.search(fragment, str(info.value)), info.value


@pytest.mark.parametrize("entry", CLASSIFIERS, ids=_ids(CLASSIFIERS))
def test_one_class_predicts_that_class(entry):
    # As sklearn's check_classifiers_one_label allows (and its KNeighborsClassifier
    # does): a one-class model is a valid model of that class, not an error.
    X, y = entry.data()
    estimator = fit(entry, X, np.full(len(y), "walk"))
    assert (estimator.predict(X) == "walk").all()
    np.testing.assert_array_equal(estimator.predict_proba(X), 1.0)


@pytest.mark.parametrize("entry", CLASSIFIERS, ids=_ids(CLASSIFIERS))
def test_missing_labels(entry):
    X, _ = entry.data()
    with pytest.raises((TypeError, ValueError), match="y"):
        entry.make().fit(X, None)


# One-frame clips: either a ValueError naming the clip and the frames needed, or a
# result that is finite and consistent (what the one frame allows).
ONE_FRAME = {
    "MotionTreeHMM": None,
    "IntervalIndexNeighbors": None,
    "SVDFeatureExtractor": None,
    "EigenMovementPCA": "clip 1 has 1 frame(s); EigenMovementPCA needs at least",
    "KMeansPrimitiveController": None,
    "VirtualMarkerTransform": "clip 1 has 1 frame(s); VirtualMarkerTransform needs at least 2",
    "ResampleClips": None,
    "FlattenClips": "clip 1 has 1 frames, but",
    "LowPassFilter": "clip 1 has 1 frame(s); LowPassFilter needs at least",
}


def _finite(result):
    if isinstance(result, (list, tuple)):  # per-clip arrays, or decode's (logprob, paths)
        return all(_finite(part) for part in result)
    return np.asarray(result).dtype.kind not in "fiub" or bool(
        np.isfinite(np.asarray(result, dtype=float)).all()
    )


@pytest.mark.parametrize("entry", list(ENTRIES.values()), ids=_ids(ENTRIES.values()))
def test_one_frame_clip(entry):
    X, y = entry.data()
    short = list(X)
    short[1] = np.asarray(X[1])[:1]
    fragment = ONE_FRAME[entry.name]
    if fragment is not None:
        with pytest.raises(ValueError, match=None) as info:
            fit(entry, short, y)
        assert fragment in str(info.value), info.value
        estimator = fit(entry)
        for method in output_methods(estimator):
            with pytest.raises(ValueError) as info:
                getattr(estimator, method)(short)
            assert "clip 1 has 1 frame" in str(info.value), info.value
        return
    estimator = fit(entry, short, y)
    for method in output_methods(estimator):
        assert _finite(getattr(estimator, method)(short)), (
            f"{method} of a one-frame clip is not finite"
        )


def test_one_frame_clip_resamples_to_a_constant():
    clip = np.array([[1.0, -2.0, 3.0]])
    out = ResampleClips(n_frames=5).fit_transform([clip, np.ones((4, 3))])
    np.testing.assert_array_equal(out[0], np.repeat(clip, 5, axis=0))


BAD_RATES = [
    (0, ValueError, "frame_rate"),
    (-30.0, ValueError, "frame_rate"),
    (float("nan"), ValueError, "frame_rate"),
    (float("inf"), ValueError, "frame_rate"),
    ("30", (TypeError, ValueError), "frame_rate"),
]

SK = humanoid_skeleton()
CLIP = np.c_[np.cos(np.linspace(0, 6 * np.pi, 120)), np.sin(np.linspace(0, 6 * np.pi, 120))]

# (what, call with a frame rate)
RATE_TAKERS = [
    (
        "VirtualMarkerTransform",
        lambda r: VirtualMarkerTransform(SK, frame_rate=r).fit([np.zeros((3, 66))]),
    ),
    (
        "ResampleClips(frame_rate)",
        lambda r: ResampleClips(frame_rate=r, target_frame_rate=10).fit([CLIP]),
    ),
    (
        "ResampleClips(target_frame_rate)",
        lambda r: ResampleClips(frame_rate=30, target_frame_rate=r).fit([CLIP]),
    ),
    (
        "EigenMovementPCA",
        lambda r: EigenMovementPCA(2, segmentation="zvc", frame_rate=r).fit([CLIP] * 3),
    ),
    ("make_motions", lambda r: make_motions(1, frame_rate=r)),
    ("make_repeated_motions", lambda r: make_repeated_motions(frame_rate=r)),
    ("Motion", lambda r: Motion(SK, np.zeros((2, 66)), frame_rate=r)),
    ("movement_energy", lambda r: movement_energy(CLIP, frame_rate=r)),
    ("zvc_segments", lambda r: zvc_segments(CLIP, frame_rate=r)),
    ("energy_segments", lambda r: energy_segments(CLIP, threshold=0.1, frame_rate=r)),
    ("segment_clip", lambda r: segment_clip(CLIP, rule="zvc", frame_rate=r, filter_order=4)),
]


@pytest.mark.parametrize("what, call", RATE_TAKERS, ids=[w for w, _ in RATE_TAKERS])
@pytest.mark.parametrize(
    "rate, error, fragment", BAD_RATES, ids=["zero", "negative", "nan", "inf", "string"]
)
def test_wrong_frame_rate(what, call, rate, error, fragment):
    with pytest.raises(error) as info:
        call(rate)
    assert fragment in str(info.value), info.value
