"""VirtualMarkerTransform: invariances, exact velocities, skeletons per clip, sklearn
citizenship."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from sklearn.base import clone
from sklearn.linear_model import RidgeClassifier
from sklearn.model_selection import GridSearchCV, GroupKFold, cross_val_score
from sklearn.pipeline import make_pipeline
from sklearn.preprocessing import StandardScaler

from skmotion.datasets import humanoid_skeleton, make_motions
from skmotion.io import Motion, as_motions, read_bvh, write_bvh
from skmotion.kinematics import Skeleton, yaw_matrix
from skmotion.preprocessing import (
    MARKER_NAMES,
    FlattenClips,
    MarkerSet,
    ResampleClips,
    VirtualMarkerTransform,
    body_frame_features,
    body_size,
    detect_marker_preset,
    marker_preset,
    to_markers,
)
from tests.clip_conformance import ClipCase, parametrize_with_clip_checks

SK = humanoid_skeleton()


def small_data(random_state=0):
    data = make_motions(
        n_clips_per_class=3,
        n_subjects=3,
        classes=["walk", "wave", "squat"],
        duration=(0.6, 1.0),
        random_state=random_state,
    )
    return data


def joint_angle_case():
    data = small_data()
    return data.clips, data.target


def marker_case():
    data = small_data()
    markers = marker_preset(SK)
    return [markers.positions(SK, c).reshape(len(c), -1) for c in data.clips], data.target


@parametrize_with_clip_checks(
    [
        ClipCase(
            VirtualMarkerTransform(SK, frame_rate=30.0),
            joint_angle_case,
            param_grid={"floor": ["lowest", 0.0]},
        ),
        ClipCase(
            VirtualMarkerTransform(frame_rate=30.0),
            marker_case,
            param_grid={"size_markers": ["auto", None]},
        ),
    ]
)
def test_conformance(check):
    check()


def _walk(random_state=0):
    data = make_motions(
        n_clips_per_class=1, classes=["walk"], duration=(1.0, 1.0), random_state=random_state
    )
    return data.clips[0], data.skeletons[0]


def _moved(clip, angle, shift):
    """The same clip turned by ``angle`` about the vertical and shifted on the floor."""
    moved = clip.copy()
    cols = {
        c: SK.channel_index("Hips", c) for c in ("Xposition", "Yposition", "Zposition", "Yrotation")
    }
    xyz = clip[:, [cols["Xposition"], cols["Yposition"], cols["Zposition"]]] @ yaw_matrix(angle).T
    moved[:, cols["Xposition"]] = xyz[:, 0] + shift[0]
    moved[:, cols["Zposition"]] = xyz[:, 2] + shift[1]
    moved[:, cols["Yrotation"]] += angle  # the root turns yaw first (intrinsic Y X Z)
    return moved


@settings(max_examples=10)
@given(st.floats(-np.pi, np.pi), st.tuples(st.floats(-5, 5), st.floats(-5, 5)))
def test_translation_on_the_floor_and_turning_change_nothing(angle, shift):
    clip, skeleton = _walk()
    vmt = VirtualMarkerTransform(skeleton, frame_rate=30.0).fit([clip])
    moved = _moved(clip, angle, shift)
    # The joint positions really moved ...
    assert np.abs(
        skeleton.forward_kinematics(moved).positions - skeleton.forward_kinematics(clip).positions
    ).max() > 0.01 or (abs(angle) < 1e-3 and max(map(abs, shift)) < 1e-2)
    # ... but not the markers in the body frame.
    np.testing.assert_allclose(vmt.transform([moved])[0], vmt.transform([clip])[0], atol=1e-9)


def test_a_bigger_subject_gives_the_same_output():
    clip, skeleton = _walk()
    big = skeleton.scaled(1.3)
    scaled = clip.copy()
    for c in ("Xposition", "Yposition", "Zposition"):
        scaled[:, skeleton.channel_index("Hips", c)] *= 1.3
    small_out = VirtualMarkerTransform(skeleton, frame_rate=30.0).fit_transform([clip])[0]
    big_out = VirtualMarkerTransform(big, frame_rate=30.0).fit_transform([scaled])[0]
    np.testing.assert_allclose(big_out, small_out, atol=1e-9)
    unnormalised = VirtualMarkerTransform(big, frame_rate=30.0, size_markers=None).fit_transform(
        [scaled]
    )[0]
    assert not np.allclose(unnormalised, small_out, atol=1e-3)


@pytest.mark.parametrize("frame_rate", [30.0, 120.0])
@pytest.mark.parametrize("turn", [0.0, 0.4])
def test_velocity_of_a_marker_at_constant_world_velocity_is_exact(frame_rate, turn):
    """Marker positions as input (skeleton=None), y up; facing may turn, the marker moves
    straight."""
    n = 9
    t = np.arange(n) / frame_rate
    heading = 0.3 + turn * t  # the subject turns at ``turn`` rad/s
    left = np.stack([np.cos(heading), np.zeros(n), -np.sin(heading)], axis=1) * 0.1
    root = np.column_stack([2.0 + t, np.full(n, 0.9), -1.0 + 0.5 * t])
    velocity = np.array([0.7, -0.2, 1.1])
    marker = np.array([0.5, 1.4, 0.3]) + t[:, None] * velocity
    positions = np.stack([root, root + left, root - left, marker], axis=1)
    vmt = VirtualMarkerTransform(
        markers=["pelvis", "left_hip", "right_hip", "hand"],
        frame_rate=frame_rate,
        size_markers=None,
        floor=0.0,
    )
    out = vmt.fit_transform([positions.reshape(n, -1)])[0].reshape(n, 4, 6)
    e_left = left / 0.1
    e_forward = np.cross(e_left, [0.0, 1.0, 0.0])
    expected = np.stack([e_forward @ velocity, e_left @ velocity, np.full(n, velocity[1])], axis=1)
    np.testing.assert_allclose(out[:, 3, 3:], expected, atol=1e-12)
    # Positions: relative to the floor point below the root, in (forward, left, up).
    offset = marker - root * [1, 0, 1]
    expected_p = np.stack(
        [(e_forward * offset).sum(1), (e_left * offset).sum(1), offset[:, 1]], axis=1
    )
    np.testing.assert_allclose(out[:, 3, :3], expected_p, atol=1e-12)


def test_body_frame_axes_by_hand():
    # Facing +x (left is -z... for y up, left x up = forward): left marker at z=-0.1.
    positions = np.array([[[3.0, 1.0, 4.0], [3.0, 1.0, 3.9], [3.0, 1.0, 4.1], [4.0, 2.0, 4.0]]] * 2)
    out = body_frame_features(positions, frame_rate=1.0, root=0, left=1, right=2, floor=0.5)
    np.testing.assert_allclose(
        out[0].reshape(4, 6)[3, :3], [1.0, 0.0, 1.5]
    )  # 1 ahead, 1.5 above the floor
    np.testing.assert_allclose(
        out[0].reshape(4, 6)[1, :3], [0.0, 0.1, 0.5]
    )  # the left hip is on the left
    with pytest.raises(ValueError, match="vertically aligned at frame 0"):
        body_frame_features(positions[:, [0, 0, 0]], frame_rate=1.0, root=0, left=1, right=2)
    assert body_size(positions, [0, 1, 2]) == pytest.approx(0.3)


def test_marker_positions_input_equals_joint_angle_input():
    clip, skeleton = _walk(3)
    positions = marker_preset(skeleton).positions(skeleton, clip).reshape(len(clip), -1)
    from_angles = VirtualMarkerTransform(skeleton, frame_rate=30.0).fit_transform([clip])[0]
    from_markers = VirtualMarkerTransform(frame_rate=30.0).fit_transform([positions])[0]
    np.testing.assert_allclose(from_markers, from_angles, atol=1e-12)


def test_bvh_round_trip_gives_the_same_markers(tmp_path):
    clip, skeleton = _walk(4)
    motion = Motion(skeleton, clip, frame_rate=30.0)
    write_bvh(motion, tmp_path / "walk.bvh")
    back = read_bvh(tmp_path / "walk.bvh")
    vmt = VirtualMarkerTransform().fit([motion])
    np.testing.assert_allclose(vmt.transform([back])[0], vmt.transform([motion])[0], atol=1e-9)


def test_each_motion_uses_its_own_skeleton():
    data = small_data(5)
    motions = as_motions(data.clips, data.skeletons, data.frame_rate)
    out = VirtualMarkerTransform().fit_transform(motions)
    for i in (0, 4, 8):
        own = VirtualMarkerTransform(data.skeletons[i], frame_rate=30.0).fit_transform(
            [data.clips[i]]
        )[0]
        np.testing.assert_array_equal(out[i], own)
    reference = VirtualMarkerTransform(data.skeleton, frame_rate=30.0).fit_transform(
        [data.clips[1]]
    )[0]
    assert data.subject_scale[data.groups[1]] != 1.0
    assert not np.allclose(out[1], reference, atol=1e-3)
    # Plain arrays next to Motions take the skeleton parameter.
    mixed = VirtualMarkerTransform(data.skeletons[1], frame_rate=30.0).fit_transform(
        [data.clips[1], motions[0]]
    )
    np.testing.assert_array_equal(mixed[0], out[1])
    np.testing.assert_array_equal(mixed[1], out[0])


def test_clips_of_different_skeleton_families_share_the_markers():
    """The humanoid renamed to the common BVH naming gets the common_bvh preset: same names,
    same body parts."""
    clip, sk = _walk(6)
    renamed = {
        "LeftToe": "LeftToeBase",
        "RightToe": "RightToeBase",
        "LeftHand_end": "LeftHand_End",
        "RightHand_end": "RightHand_End",
    }
    other = Skeleton(
        [renamed.get(j, j) for j in sk.joints],
        sk.parents,
        sk.offsets,
        sk.channels,
        up_axis=sk.up_axis,
    )
    assert detect_marker_preset(other) == "common_bvh"
    vmt = VirtualMarkerTransform(size_markers=None, floor=0.0)
    ours = vmt.fit_transform([Motion(sk, clip, frame_rate=30.0)])[0].reshape(len(clip), 32, 6)
    theirs = vmt.fit_transform([Motion(other, clip, frame_rate=30.0)])[0].reshape(len(clip), 32, 6)
    assert list(vmt.marker_names_) == list(MARKER_NAMES)
    for name in (
        "head_top",
        "pelvis",
        "left_knee",
        "right_elbow",
        "left_wrist",
        "right_toe",
        "left_shoulder",
    ):
        k = MARKER_NAMES.index(name)
        np.testing.assert_allclose(theirs[:, k], ours[:, k], atol=1e-12)
    # Where the two presets place a marker differently (the hand: tip vs middle), it stays close.
    k = MARKER_NAMES.index("left_hand")
    assert 0.0 < np.abs(theirs[:, k, :3] - ours[:, k, :3]).max() < 0.1


def test_pipeline_and_grid_search_recognise_motions():
    data = make_motions(
        n_clips_per_class=6,
        n_subjects=3,
        classes=["walk", "jump", "wave", "squat"],
        duration=(1.0, 1.5),
        random_state=0,
    )
    motions = as_motions(data.clips, data.skeletons, data.frame_rate)
    pipe = make_pipeline(
        VirtualMarkerTransform(),
        ResampleClips(n_frames=8),
        FlattenClips(),
        StandardScaler(),
        RidgeClassifier(),
    )
    search = GridSearchCV(
        pipe,
        {"virtualmarkertransform__floor": ["lowest", 0.0], "resampleclips__n_frames": [4, 8]},
        cv=GroupKFold(3),
    )
    search.fit(motions, data.target, groups=data.groups)
    # Raw joint angles carry each clip's position and heading; the body frame removes them.
    raw = make_pipeline(
        ResampleClips(n_frames=8), FlattenClips(), StandardScaler(), RidgeClassifier()
    )
    raw_score = cross_val_score(
        raw, data.clips, data.target, groups=data.groups, cv=GroupKFold(3)
    ).mean()
    assert search.best_score_ > 0.8 and search.best_score_ > raw_score + 0.1


def test_errors_name_what_and_where():
    data = small_data()
    with pytest.raises(ValueError, match="clip 0 is a plain array; give frame_rate="):
        VirtualMarkerTransform(SK).fit(data.clips)
    motions = as_motions(data.clips[:2], data.skeletons[:2], 30.0)
    with pytest.raises(ValueError, match="clip 1 is a plain array while other clips are Motions"):
        VirtualMarkerTransform().fit([motions[0], data.clips[1]])
    with pytest.raises(ValueError, match="Motion at 30 Hz, but frame_rate=60"):
        VirtualMarkerTransform(frame_rate=60.0).fit(motions)
    with pytest.raises(ValueError, match="3 per marker"):
        VirtualMarkerTransform(frame_rate=30.0).fit([np.zeros((5, 7))])
    with pytest.raises(ValueError, match="2 markers .* but markers names 32"):
        VirtualMarkerTransform(frame_rate=30.0).fit([np.zeros((5, 6))])
    with pytest.raises(ValueError, match="root_marker 'sacrum' is not a marker"):
        VirtualMarkerTransform(SK, frame_rate=30.0, root_marker="sacrum").fit(data.clips)
    tiny = Skeleton(["a", "b"], [-1, 0], [[0, 0, 0], [0, 1, 0]], [["Xrotation"], []])
    with pytest.raises(ValueError, match="clip 0 has 66 channels, but its skeleton has 1"):
        VirtualMarkerTransform(tiny, frame_rate=30.0).fit(data.clips)
    custom = MarkerSet(
        [
            ("top", "Head_end", (0, 0, 0)),
            ("l", "LeftUpLeg", (0, 0, 0)),
            ("r", "RightUpLeg", (0, 0, 0)),
            ("base", "Hips", (0, 0, 0)),
        ]
    )
    vmt = VirtualMarkerTransform(
        SK,
        markers=custom,
        root_marker="base",
        facing_markers=("l", "r"),
        size_markers=("l", "top"),
        frame_rate=30.0,
    ).fit(data.clips)
    assert vmt.get_feature_names_out()[:2].tolist() == ["top_px", "top_py"] and vmt.n_markers_ == 4
    with pytest.raises(ValueError, match="size marker 'left_ankle'"):
        VirtualMarkerTransform(
            SK, markers=custom, root_marker="base", facing_markers=("l", "r"), frame_rate=30.0
        ).fit(data.clips)


def test_to_markers_mixes_channel_layouts_in_input_order():
    data = small_data(7)
    motions = as_motions(data.clips[:4], data.skeletons[:4], data.frame_rate)
    sk = motions[1].skeleton
    keep = [j for j, name in enumerate(sk.joints) if "Toe" not in name]
    bare = Skeleton(
        [sk.joints[j] for j in keep],
        [keep.index(sk.parents[j]) if j else -1 for j in keep],
        sk.offsets[keep],
        [sk.channels[j] for j in keep],
        up_axis="y",
    )
    columns = [c for c, name in enumerate(sk.channel_names) if "Toe" not in name]
    motions[1] = Motion(bare, motions[1].channels[:, columns], frame_rate=30.0)
    custom = VirtualMarkerTransform(
        markers=[
            ("pelvis", "Hips", (0, 0, 0)),
            ("left_hip", "LeftUpLeg", (0, 0, 0)),
            ("right_hip", "RightUpLeg", (0, 0, 0)),
            ("top", "Head_end", (0, 0, 0)),
        ],
        size_markers=["pelvis", "top"],
    )
    clips, names = to_markers(motions, custom)
    assert names.tolist()[:2] == ["pelvis_px", "pelvis_py"] and len(clips) == 4
    for i in (0, 1, 3):
        np.testing.assert_array_equal(clips[i], clone(custom).fit_transform([motions[i]])[0])
    from skmotion.preprocessing import detect_marker_preset

    # Without toes no fixed preset fits; the joint matcher places the 32 markers anyway
    # (the toe marker past the ankle).
    assert detect_marker_preset(bare) == "matched"
    assert {c.shape[1] for c in to_markers(motions)[0]} == {6 * 32}
    with pytest.raises(TypeError, match="item 0 is a ndarray, not a Motion"):
        to_markers([data.clips[0]])
