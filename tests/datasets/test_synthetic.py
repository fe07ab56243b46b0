import numpy as np
import pytest
from sklearn.linear_model import LogisticRegression
from sklearn.model_selection import GroupKFold, StratifiedKFold, cross_val_score
from sklearn.neighbors import KNeighborsClassifier
from sklearn.pipeline import make_pipeline
from sklearn.preprocessing import StandardScaler

from skmotion.datasets import MOTION_CLASSES, humanoid_skeleton, make_motions
from skmotion.kinematics import forward_kinematics
from skmotion.preprocessing import FlattenClips, ResampleClips


@pytest.fixture(scope="module")
def data():
    return make_motions(random_state=0)


def test_same_seed_same_clips_and_different_seeds_differ():
    a = make_motions(n_clips_per_class=3, random_state=7)
    b = make_motions(n_clips_per_class=3, random_state=7)
    c = make_motions(n_clips_per_class=3, random_state=8)
    assert all(np.array_equal(x, y) for x, y in zip(a.clips, b.clips))
    assert not any(x.shape == y.shape and np.allclose(x, y) for x, y in zip(a.clips, c.clips))


def test_every_class_and_subject_is_present(data):
    assert data.target_names.tolist() == list(MOTION_CLASSES)
    pairs = set(zip(data.target.tolist(), data.groups.tolist()))
    assert pairs == {(c, s) for c in range(7) for s in range(4)}
    assert np.bincount(data.target).tolist() == [12] * 7
    assert all(c.shape[1] == 66 for c in data.clips)
    assert data.feature_names == data.skeleton.channel_names


def test_durations_and_frame_rate():
    d = make_motions(n_clips_per_class=5, frame_rate=60, duration=(1.0, 1.5), random_state=1)
    lengths = np.array([len(c) for c in d.clips])
    assert d.frame_rate == 60.0
    assert lengths.min() >= 60 and lengths.max() <= 90
    assert len(set(lengths.tolist())) > 5


def test_subject_sizes_match_their_skeletons(data):
    for i in range(0, len(data.clips), 5):
        scale = data.subject_scale[data.groups[i]]
        assert data.skeletons[i].height() == pytest.approx(1.75 * scale)
    assert 0.88 <= data.subject_scale.min() and data.subject_scale.max() <= 1.12
    assert data.skeleton == humanoid_skeleton()


def _world(data, i):
    return forward_kinematics(data.skeletons[i], data.clips[i]).positions


def test_feet_stay_on_the_floor_and_jumps_leave_it():
    d = make_motions(n_clips_per_class=4, noise=0.0, random_state=3)
    feet = [
        d.skeleton.joint_index(j) for j in ("LeftToe_end", "RightToe_end", "LeftFoot", "RightFoot")
    ]
    for i, clip in enumerate(d.clips):
        pos = forward_kinematics(d.skeletons[i], clip).positions
        lowest = pos[:, :, 1].min(axis=1)
        name = d.target_names[d.target[i]]
        if name in ("jump", "jog"):
            assert lowest.max() > (0.1 if name == "jump" else 0.01), name
        else:
            # The sole (ankle height 0.08 below the ankle joint) touches y = 0.
            sole = np.minimum(
                pos[:, feet[:2], 1].min(axis=1),
                pos[:, feet[2:], 1].min(axis=1) - 0.08 * d.subject_scale[d.groups[i]],
            )
            np.testing.assert_allclose(sole, 0.0, atol=1e-9)
        assert lowest.min() > -0.05


def test_locomotion_travels_and_other_motions_stay(data):
    speeds = {}
    for i, clip in enumerate(data.clips):
        root = clip[:, [0, 2]]
        duration = (len(clip) - 1) / data.frame_rate
        path = np.linalg.norm(np.diff(root, axis=0), axis=1).sum()
        speeds.setdefault(data.target_names[data.target[i]], []).append(path / duration)
    walk, jog = np.median(speeds["walk"]), np.median(speeds["jog"])
    assert 0.9 < walk < 1.8
    assert jog > 1.5 * walk
    assert np.median(speeds["wave"]) < 0.25


@pytest.mark.parametrize("label", range(7))
def test_clips_of_one_class_vary(label):
    clean = make_motions(noise=0.0, random_state=0)
    resampled = ResampleClips(n_frames=32).fit_transform(clean.clips)
    same = np.stack([resampled[i][:, 6:] for i in np.flatnonzero(clean.target == label)])
    diffs = np.abs(same[:, None] - same[None]).mean(axis=(2, 3))
    off_diagonal = diffs[~np.eye(len(same), dtype=bool)]
    # Without noise, no two clips of a class are alike: at least 0.3 degrees
    # apart on average over all joints and frames, typically several degrees.
    assert off_diagonal.min() > np.deg2rad(0.3)
    assert np.median(off_diagonal) > np.deg2rad(1.5)


def test_noise_scale():
    clean = make_motions(n_clips_per_class=2, noise=0.0, random_state=5)
    noisy = make_motions(n_clips_per_class=2, noise=1.0, random_state=5)
    rough = lambda clips: np.mean([np.abs(np.diff(c[:, 6:], 2, axis=0)).mean() for c in clips])  # noqa: E731
    assert rough(noisy.clips) > 3 * rough(clean.clips)


def test_not_trivial_for_one_nearest_neighbour(data):
    # The criterion: plain 1-NN on resampled clips does not reach 100%.
    knn = make_pipeline(ResampleClips(n_frames=32), FlattenClips(), KNeighborsClassifier(1))
    cv = StratifiedKFold(4, shuffle=True, random_state=0)
    accuracy = cross_val_score(knn, data.clips, data.target, cv=cv).mean()
    assert 1 / 7 < accuracy < 0.9


def _summary(clips):
    return np.array(
        [
            np.r_[c[:, 6:].mean(0), c[:, 6:].std(0), np.abs(np.diff(c[:, 6:], axis=0)).mean(0)]
            for c in clips
        ]
    )


def test_classes_are_distinguishable_across_subjects(data):
    model = make_pipeline(StandardScaler(), LogisticRegression(max_iter=3000))
    accuracy = cross_val_score(
        model, _summary(data.clips), data.target, groups=data.groups, cv=GroupKFold(4)
    ).mean()
    assert accuracy > 0.85


def test_return_X_y():
    X, y = make_motions(
        n_clips_per_class=2, classes=["wave", "squat"], return_X_y=True, random_state=0
    )
    assert len(X) == 4 and y.tolist() == [0, 0, 1, 1]


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(classes=["walk", "fly"]), "classes must be distinct names"),
        (dict(classes=["walk", "walk"]), "classes must be distinct names"),
        (dict(duration=(3.0, 1.0)), "duration"),
        (dict(n_subjects=0), "n_subjects"),
        (dict(frame_rate=-1), "frame_rate"),
    ],
)
def test_invalid_arguments(kwargs, match):
    with pytest.raises(ValueError, match=match):
        make_motions(**kwargs)
