"""The similarity-search pipeline: virtual markers into the interval index, grid-searched."""

import numpy as np
import pytest
from sklearn.base import clone
from sklearn.model_selection import GridSearchCV, GroupKFold
from sklearn.pipeline import make_pipeline

from skmotion.datasets import make_motions
from skmotion.io import as_motions
from skmotion.metrics import make_search_scorer, pruning_efficiency, recall
from skmotion.neighbors import IntervalIndexNeighbors
from skmotion.preprocessing import VirtualMarkerTransform

N_REPEATS = 3
GRID = {"intervalindexneighbors__epsilon": [0.3, 1.0], "intervalindexneighbors__n_levels": [3, 6]}


@pytest.fixture(scope="module")
def repeated():
    """Each of 10 joint-angle performances cut into 3 consecutive 1.5 s repetitions.

    Returns the segments, their skeletons (one per subject), the frame rate,
    the motion of each segment (similar = the same motion) and its repetition
    number (the CV groups: every motion is in every fold).
    """
    data = make_motions(
        n_clips_per_class=2,
        n_subjects=2,
        classes=["walk", "jump", "wave", "kick", "squat"],
        duration=(4.5, 4.5),
        random_state=0,
    )
    n = int(1.5 * data.frame_rate)
    segments, skeletons, motion, repetition = [], [], [], []
    for m, clip in enumerate(data.clips):
        for r in range(N_REPEATS):
            segments.append(clip[r * n : (r + 1) * n])
            skeletons.append(data.skeletons[m])
            motion.append(m)
            repetition.append(r)
    return segments, skeletons, data.frame_rate, np.array(motion), np.array(repetition)


def _search(pipe, X, y, groups):
    return GridSearchCV(
        pipe,
        GRID,
        scoring=make_search_scorer(0.9),
        refit="pruning_at_recall",
        cv=GroupKFold(N_REPEATS),
    ).fit(X, y, groups=groups)


def _by_params(results, key):
    return {
        (p["intervalindexneighbors__epsilon"], p["intervalindexneighbors__n_levels"]): results[key][
            i
        ]
        for i, p in enumerate(results["params"])
    }


def test_grid_search_over_the_marker_pipeline_on_motions(repeated):
    segments, skeletons, rate, motion, repetition = repeated
    motions = as_motions(segments, skeletons, rate)  # each clip with its subject's skeleton
    pipe = make_pipeline(VirtualMarkerTransform(), IntervalIndexNeighbors(epsilon=0.8))
    search = _search(pipe, motions, motion, repetition)
    pruning = _by_params(search.cv_results_, "mean_test_pruning")
    found = _by_params(search.cv_results_, "mean_test_recall")
    bounded = _by_params(search.cv_results_, "mean_test_pruning_at_recall")
    # The grid changes the outcome: wider entries keep more of a motion's
    # repetitions and prune less; more levels prune more.
    for levels in (3, 6):
        assert pruning[(0.3, levels)] > pruning[(1.0, levels)] + 0.1
        assert found[(0.3, levels)] < found[(1.0, levels)]
    for epsilon in (0.3, 1.0):
        assert pruning[(epsilon, 6)] > pruning[(epsilon, 3)]
    # The refit setting is the best bounded score, and it differs from the worst.
    best = max(bounded, key=bounded.get)
    assert (
        search.best_params_["intervalindexneighbors__epsilon"],
        search.best_params_["intervalindexneighbors__n_levels"],
    ) == best
    assert bounded[best] > min(bounded.values())
    # An independent recomputation of the best setting's scores, fold by fold.
    scores = []
    for train, test in GroupKFold(N_REPEATS).split(motions, motion, repetition):
        model = (
            clone(pipe)
            .set_params(**search.best_params_)
            .fit([motions[i] for i in train], motion[train])
        )
        markers = model[0].transform([motions[i] for i in test])
        candidates = model[-1].candidates(markers)
        scores.append(
            (
                pruning_efficiency(candidates, motion[test], motion[train]),
                recall(candidates, motion[test], motion[train]),
            )
        )
    np.testing.assert_allclose(np.mean(scores, axis=0), [pruning[best], found[best]])
    # The refit pipeline takes Motions and finds repetitions of the same motion.
    refit = search.best_estimator_
    assert refit[-1].n_samples_fit_ == len(motions)
    assert np.mean(refit.predict(motions) == motion) == 1.0  # each clip finds itself


def test_plain_arrays_with_a_skeleton_give_the_same_search(repeated):
    segments, skeletons, rate, motion, repetition = repeated
    one = skeletons[0]
    on_arrays = _search(
        make_pipeline(
            VirtualMarkerTransform(skeleton=one, frame_rate=rate), IntervalIndexNeighbors()
        ),
        segments,
        motion,
        repetition,
    )
    on_motions = _search(
        make_pipeline(VirtualMarkerTransform(), IntervalIndexNeighbors()),
        as_motions(segments, [one] * len(segments), rate),
        motion,
        repetition,
    )
    for key in ("mean_test_pruning", "mean_test_recall", "mean_test_pruning_at_recall"):
        np.testing.assert_array_equal(on_arrays.cv_results_[key], on_motions.cv_results_[key])
    assert on_arrays.best_params_ == on_motions.best_params_
    assert np.ptp(on_arrays.cv_results_["mean_test_pruning"]) > 0.1
