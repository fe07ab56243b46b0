"""Subject-wise evaluation: GroupKFold with the loaders' groups, and nested searches with
routed groups.

The truth the tests check against does not come from the groups that sklearn routes:
each clip's subject is looked up from the clip itself (by identity, in the original
collection), so a routing mistake would show as a subject on both sides of a split.
"""

import numpy as np
import pytest
import sklearn
from sklearn.base import clone
from sklearn.model_selection import GridSearchCV, GroupKFold, cross_val_score, cross_validate
from sklearn.neighbors import KNeighborsClassifier
from sklearn.pipeline import make_pipeline

from skmotion.datasets import make_motions
from skmotion.neighbors import IntervalIndexNeighbors
from skmotion.preprocessing import FlattenClips, ResampleClips


@pytest.fixture(scope="module")
def motions():
    data = make_motions(
        n_clips_per_class=4,
        n_subjects=4,
        classes=["walk", "jump", "wave", "squat"],
        duration=(0.8, 1.2),
        random_state=0,
    )
    clips = [c[:, 6:] for c in data.clips]
    subject_of = {id(c): s for c, s in zip(clips, data.groups)}
    return clips, data.target, data.groups, subject_of


class RecordingGroupKFold(GroupKFold):
    """GroupKFold that records, for each split, the subjects of the clips on each side."""

    log = []
    subject_of = {}

    def split(self, X, y=None, groups=None):
        for train, test in super().split(X, y, groups):
            subjects = np.array([self.subject_of[id(clip)] for clip in X])
            RecordingGroupKFold.log.append((set(subjects[train]), set(subjects[test])))
            yield train, test


def _model():
    return make_pipeline(ResampleClips(n_frames=16), FlattenClips(), KNeighborsClassifier(1))


def test_cross_val_score_with_groups_is_leave_subjects_out(motions):
    clips, y, groups, _ = motions
    scores = cross_val_score(_model(), clips, y, groups=groups, cv=GroupKFold(4))
    # The reference: train on three subjects, score on the fourth, by hand.
    expected = []
    for subject in np.unique(groups):
        held = groups == subject
        model = _model().fit([c for c, h in zip(clips, held) if not h], y[~held])
        expected.append(model.score([c for c, h in zip(clips, held) if h], y[held]))
    np.testing.assert_array_equal(np.sort(scores), np.sort(expected))


def test_nested_search_routes_groups_to_the_inner_split(motions, monkeypatch):
    clips, y, groups, subject_of = motions
    monkeypatch.setattr(RecordingGroupKFold, "log", [])
    monkeypatch.setattr(RecordingGroupKFold, "subject_of", subject_of)
    search = GridSearchCV(
        IntervalIndexNeighbors(n_levels=3), {"epsilon": [0.5, 1.0]}, cv=RecordingGroupKFold(3)
    )
    with sklearn.config_context(enable_metadata_routing=True):
        result = cross_validate(
            search, clips, y, cv=GroupKFold(4), params={"groups": groups}, return_estimator=True
        )
    inner = RecordingGroupKFold.log
    assert len(inner) == 4 * 3, (
        "3 inner splits in each of the 4 outer folds (the refit does not split)"
    )
    for train_subjects, test_subjects in inner:
        assert train_subjects.isdisjoint(test_subjects), (
            f"subject on both sides: {train_subjects & test_subjects}"
        )
        assert (
            len(train_subjects) == 2 and len(test_subjects) == 1
        )  # 3 subjects per outer training set
    # Each outer fold's search saw only the three subjects of its training set.
    seen = [set().union(*(a | b for a, b in inner[3 * k : 3 * k + 3])) for k in range(4)]
    assert sorted(len(s) for s in seen) == [3, 3, 3, 3] and len(set(map(frozenset, seen))) == 4
    assert len(result["test_score"]) == 4 and np.isfinite(result["test_score"]).all()
    assert all(est.best_params_["epsilon"] in (0.5, 1.0) for est in result["estimator"])


def test_nested_search_without_routing_has_no_groups(motions):
    clips, y, groups, _ = motions
    search = GridSearchCV(
        IntervalIndexNeighbors(n_levels=3), {"epsilon": [0.5, 1.0]}, cv=GroupKFold(3)
    )
    # Without metadata routing the inner GroupKFold never receives the subjects.
    with pytest.raises(ValueError, match="groups"):
        cross_validate(
            clone(search), clips, y, groups=groups, cv=GroupKFold(4), error_score="raise"
        )
