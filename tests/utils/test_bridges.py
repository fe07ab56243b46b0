"""Clips to and from aeon/sktime and tslearn collections; an aeon classifier after skmotion
steps in a Pipeline (tested with aeon and tslearn installed; skipped without them)."""

import pickle

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from sklearn.model_selection import StratifiedKFold, cross_val_score
from sklearn.pipeline import make_pipeline

from skmotion.datasets import make_motions
from skmotion.preprocessing import ResampleClips, ToAeon
from skmotion.utils import from_aeon, from_tslearn, to_aeon, to_tslearn
from tests.clip_conformance import ClipCase, parametrize_with_clip_checks


def _ragged(seed, n_clips=5, n_channels=3):
    rng = np.random.default_rng(seed)
    return [rng.normal(size=(int(rng.integers(2, 12)), n_channels)) for _ in range(n_clips)]


@given(st.integers(0, 10_000), st.integers(1, 6), st.integers(1, 4), st.booleans())
@settings(max_examples=40, deadline=None)
def test_round_trips_are_exact(seed, n_clips, n_channels, equal):
    clips = _ragged(seed, n_clips, n_channels)
    if equal:
        clips = [c[:2] for c in clips]
    converted = to_aeon(clips)
    assert isinstance(converted, np.ndarray) == (equal or n_clips == 1)
    for clip, case, back in zip(clips, converted, from_aeon(converted)):
        np.testing.assert_array_equal(case, clip.T)  # channels first, time second
        np.testing.assert_array_equal(back, clip)
    for clip, back in zip(clips, from_tslearn(to_tslearn(clips))):
        np.testing.assert_array_equal(back, clip)


def test_equal_length_true_names_the_clip():
    clips = [np.zeros((4, 2)), np.zeros((4, 2)), np.zeros((5, 2))]
    with pytest.raises(ValueError, match="clip 2 has 5 frames, clip 0 has 4"):
        to_aeon(clips, equal_length=True)
    assert isinstance(to_aeon(clips[:2], equal_length=False), list)


def test_aeon_and_tslearn_read_the_same_collections():
    convert = pytest.importorskip("aeon.utils.conversion").convert_collection
    tslearn_utils = pytest.importorskip("tslearn.utils")
    clips = _ragged(0)
    ours = to_aeon(clips)
    # aeon's own view of our np-list: its numpy-list checks accept it, and it pads the same way
    for a, b in zip(convert(ours, "np-list"), ours):
        np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(to_tslearn(clips), tslearn_utils.to_time_series_dataset(clips))
    padded = tslearn_utils.to_time_series_dataset(clips)
    assert [len(c) for c in from_tslearn(padded)] == [int(tslearn_utils.ts_size(x)) for x in padded]
    equal = to_aeon([c[:2] for c in clips])
    np.testing.assert_array_equal(convert(equal, "numpy3D"), equal)


def _dtw(a, b):
    """Dynamic time warping cost of two (n_frames, n_channels) clips, squared Euclidean steps."""
    cost = np.full((len(a) + 1, len(b) + 1), np.inf)
    cost[0, 0] = 0.0
    for i in range(1, len(a) + 1):
        for j in range(1, len(b) + 1):
            step = np.sum((a[i - 1] - b[j - 1]) ** 2)
            cost[i, j] = step + min(cost[i - 1, j], cost[i, j - 1], cost[i - 1, j - 1])
    return cost[-1, -1]


def test_an_aeon_classifier_follows_skmotion_steps_on_ragged_clips():
    neighbors = pytest.importorskip("aeon.classification.distance_based")
    data = make_motions(
        n_clips_per_class=4, classes=["walk", "squat", "wave"], duration=(0.5, 1.0), random_state=0
    )
    clips = [c[::3, 6:12] for c in data.clips]  # short and ragged: a hand-written DTW is quick
    assert len({len(c) for c in clips}) > 1
    train, test = np.arange(0, 12, 2), np.arange(1, 12, 2)
    model = make_pipeline(
        ToAeon(), neighbors.KNeighborsTimeSeriesClassifier(n_neighbors=1, distance="dtw")
    )
    model.fit([clips[i] for i in train], data.target[train])
    predicted = model.predict([clips[i] for i in test])
    # the truth: 1-NN under a DTW over time (not over channels), written out here
    expected = [
        data.target[train[np.argmin([_dtw(clips[i], clips[j]) for j in train])]] for i in test
    ]
    np.testing.assert_array_equal(predicted, expected)
    assert np.mean(predicted == data.target[test]) >= 0.5
    again = pickle.loads(pickle.dumps(model))
    np.testing.assert_array_equal(again.predict([clips[i] for i in test]), predicted)
    # and behind a skmotion step, in cross-validation
    resampled = make_pipeline(
        ResampleClips(n_frames=10), ToAeon(), neighbors.KNeighborsTimeSeriesClassifier()
    )
    scores = cross_val_score(resampled, clips, data.target, cv=2)
    folds = StratifiedKFold(2).split(clips, data.target)  # what cross_val_score uses
    direct = []
    for fit_on, score_on in folds:
        rows = [ResampleClips(n_frames=10).fit_transform([clips[i] for i in k]) for k in (fit_on,)]
        knn = neighbors.KNeighborsTimeSeriesClassifier().fit(to_aeon(rows[0]), data.target[fit_on])
        resampled_test = ResampleClips(n_frames=10).fit_transform([clips[i] for i in score_on])
        direct.append(np.mean(knn.predict(to_aeon(resampled_test)) == data.target[score_on]))
    np.testing.assert_allclose(scores, direct)


def test_to_aeon_refuses_a_pandas_output():
    with pytest.raises(ValueError, match="not tables"):
        ToAeon().set_output(transform="pandas")


@parametrize_with_clip_checks(
    [
        ClipCase(
            ToAeon(),
            skip={
                name: "an aeon collection is not a table: the scoring model needs an aeon "
                "classifier after ToAeon (test_an_aeon_classifier_follows_skmotion_steps_on_"
                "ragged_clips)"
                for name in ("check_cross_val_score", "check_grid_search")
            },
        )
    ]
)
def test_clip_conformance(check):
    check()
