"""Joint layouts and VirtualMarkerTransform(layout=): documented orders, invariances, agreement."""

import tracemalloc

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from skmotion.datasets import humanoid_skeleton, layout_markers, make_position_motions
from skmotion.kinematics import yaw_matrix
from skmotion.preprocessing import LAYOUTS, MARKER_NAMES, Layout, VirtualMarkerTransform, get_layout
from skmotion.preprocessing._position_frame import position_frame_features
from tests.clip_conformance import ClipCase, parametrize_with_clip_checks

# The joint orders as the systems document them (index: name), typed from the sources
# cited in docs/positions.md; the layouts must list exactly these, in this order.
DOCUMENTED = {
    "kinect_v1": "HipCenter=0 Spine=1 ShoulderCenter=2 Head=3 ShoulderLeft=4 ElbowLeft=5 "
    "WristLeft=6 HandLeft=7 ShoulderRight=8 ElbowRight=9 WristRight=10 HandRight=11 HipLeft=12 "
    "KneeLeft=13 AnkleLeft=14 FootLeft=15 HipRight=16 KneeRight=17 AnkleRight=18 FootRight=19",
    "kinect_v2": "SpineBase=0 SpineMid=1 Neck=2 Head=3 ShoulderLeft=4 ElbowLeft=5 WristLeft=6 "
    "HandLeft=7 ShoulderRight=8 ElbowRight=9 WristRight=10 HandRight=11 HipLeft=12 KneeLeft=13 "
    "AnkleLeft=14 FootLeft=15 HipRight=16 KneeRight=17 AnkleRight=18 FootRight=19 "
    "SpineShoulder=20 HandTipLeft=21 ThumbLeft=22 HandTipRight=23 ThumbRight=24",
    "azure_kinect": "PELVIS=0 SPINE_NAVEL=1 SPINE_CHEST=2 NECK=3 CLAVICLE_LEFT=4 SHOULDER_LEFT=5 "
    "ELBOW_LEFT=6 WRIST_LEFT=7 HAND_LEFT=8 HANDTIP_LEFT=9 THUMB_LEFT=10 CLAVICLE_RIGHT=11 "
    "SHOULDER_RIGHT=12 ELBOW_RIGHT=13 WRIST_RIGHT=14 HAND_RIGHT=15 HANDTIP_RIGHT=16 "
    "THUMB_RIGHT=17 HIP_LEFT=18 KNEE_LEFT=19 ANKLE_LEFT=20 FOOT_LEFT=21 HIP_RIGHT=22 "
    "KNEE_RIGHT=23 ANKLE_RIGHT=24 FOOT_RIGHT=25 HEAD=26 NOSE=27 EYE_LEFT=28 EAR_LEFT=29 "
    "EYE_RIGHT=30 EAR_RIGHT=31",
    "coco17": "nose=0 left_eye=1 right_eye=2 left_ear=3 right_ear=4 left_shoulder=5 "
    "right_shoulder=6 left_elbow=7 right_elbow=8 left_wrist=9 right_wrist=10 left_hip=11 "
    "right_hip=12 left_knee=13 right_knee=14 left_ankle=15 right_ankle=16",
    "openpose_body25": "Nose=0 Neck=1 RShoulder=2 RElbow=3 RWrist=4 LShoulder=5 LElbow=6 "
    "LWrist=7 MidHip=8 RHip=9 RKnee=10 RAnkle=11 LHip=12 LKnee=13 LAnkle=14 REye=15 LEye=16 "
    "REar=17 LEar=18 LBigToe=19 LSmallToe=20 LHeel=21 RBigToe=22 RSmallToe=23 RHeel=24",
    "mediapipe_pose33": "nose=0 left_eye_inner=1 left_eye=2 left_eye_outer=3 right_eye_inner=4 "
    "right_eye=5 right_eye_outer=6 left_ear=7 right_ear=8 mouth_left=9 mouth_right=10 "
    "left_shoulder=11 right_shoulder=12 left_elbow=13 right_elbow=14 left_wrist=15 "
    "right_wrist=16 left_pinky=17 right_pinky=18 left_index=19 right_index=20 left_thumb=21 "
    "right_thumb=22 left_hip=23 right_hip=24 left_knee=25 right_knee=26 left_ankle=27 "
    "right_ankle=28 left_heel=29 right_heel=30 left_foot_index=31 right_foot_index=32",
    "h36m17": "hip=0 right_hip=1 right_knee=2 right_ankle=3 left_hip=4 left_knee=5 left_ankle=6 "
    "spine=7 thorax=8 neck_nose=9 head=10 left_shoulder=11 left_elbow=12 left_wrist=13 "
    "right_shoulder=14 right_elbow=15 right_wrist=16",
    "smpl24": "pelvis=0 left_hip=1 right_hip=2 spine1=3 left_knee=4 right_knee=5 spine2=6 "
    "left_ankle=7 right_ankle=8 spine3=9 left_foot=10 right_foot=11 neck=12 left_collar=13 "
    "right_collar=14 head=15 left_shoulder=16 right_shoulder=17 left_elbow=18 right_elbow=19 "
    "left_wrist=20 right_wrist=21 left_hand=22 right_hand=23",
}


@pytest.mark.parametrize("name", sorted(DOCUMENTED))
def test_joint_order_is_the_documented_one(name):
    pairs = [item.split("=") for item in DOCUMENTED[name].split()]
    documented = [joint for joint, _ in sorted(pairs, key=lambda p: int(p[1]))]
    assert list(get_layout(name).joints) == documented


def test_every_named_layout_is_documented_and_sided():
    assert set(LAYOUTS) == set(DOCUMENTED)
    sk = humanoid_skeleton()
    for layout in LAYOUTS.values():
        # Every joint is placed on the body; left joints lie on the subject's left (+x).
        rest = layout_markers(sk, get_layout(layout, dim=3)).positions(sk, np.zeros((1, 66)))[0]
        left, right = layout.index(layout.left_hip), layout.index(layout.right_hip)
        assert rest[left, 0] > 0 > rest[right, 0]
        shared = [m for _, m in layout.shared_markers]
        assert shared == [m for m in MARKER_NAMES if m in shared]


def _positions(layout, random_state=0, **kw):
    data = make_position_motions(
        layout,
        n_clips_per_class=1,
        classes=["walk", "wave"],
        duration=(1.0, 1.4),
        random_state=random_state,
        **kw,
    )
    return data.clips, data


def _turn_about_up(clip, layout, angle, shift, factor):
    """Rotate about the layout's vertical, shift on the floor, scale: a rigid similarity."""
    up = layout.up[-1]
    points = clip.reshape(len(clip), -1, 3)
    axes = {"y": [0, 1, 2], "z": [0, 2, 1], "x": [1, 0, 2]}[up]  # bring up to y for yaw_matrix
    as_y = points[..., axes] @ yaw_matrix(angle).T
    as_y = as_y + np.array([shift[0], 0.0, shift[1]])
    return (as_y[..., np.argsort(axes)] * factor).reshape(clip.shape)


@settings(max_examples=12, deadline=None)
@given(
    st.sampled_from(["kinect_v2", "azure_kinect", "h36m17", "smpl24"]),
    st.floats(-np.pi, np.pi),
    st.tuples(st.floats(-5, 5), st.floats(-5, 5)),
    st.floats(0.2, 5.0),
)
def test_turning_moving_and_scaling_the_body_changes_nothing(name, angle, shift, factor):
    clips, data = _positions(name)
    vmt = VirtualMarkerTransform(layout=name, markers="all", frame_rate=30.0).fit(clips)
    moved = [_turn_about_up(c, data.layout, angle, shift, factor) for c in clips]
    for a, b in zip(vmt.transform(moved), vmt.transform(clips)):
        np.testing.assert_allclose(a, b, atol=1e-9)


@settings(max_examples=12, deadline=None)
@given(
    st.sampled_from(["coco17", "openpose_body25"]),
    st.booleans(),
    st.tuples(st.floats(-500, 500), st.floats(-500, 500)),
    st.floats(0.2, 5.0),
)
def test_2d_mirroring_moving_and_scaling_the_image_changes_nothing(name, mirror, shift, factor):
    """A half turn about the vertical mirrors the image; the horizontal sign undoes it."""
    clips, _ = _positions(name)
    vmt = VirtualMarkerTransform(layout=name, markers="all", frame_rate=30.0).fit(clips)
    sign = np.array([-1.0 if mirror else 1.0, 1.0])
    moved = [((c.reshape(len(c), -1, 2) * sign + shift) * factor).reshape(c.shape) for c in clips]
    for a, b in zip(vmt.transform(moved), vmt.transform(clips)):
        np.testing.assert_allclose(a, b, atol=1e-9)


def test_layouts_agree_on_the_shared_markers_of_the_same_motion():
    reference = None
    outputs = {}
    for name, layout in LAYOUTS.items():
        clips, _ = _positions(name, noise=0.0)
        # The floor is fixed: "lowest" depends on which joints a system has (heels, toes).
        floor = 0.0 if layout.dim == 3 else 360.0 + 1000.0 * 1.2 / 6.0
        vmt = VirtualMarkerTransform(layout=name, frame_rate=30.0, floor=floor).fit(clips)
        outputs[name] = (list(vmt.marker_names_), vmt.transform(clips), layout.dim)
    reference = outputs["smpl24"]
    for name, (names, out, dim) in outputs.items():
        ref_names = outputs["coco17"][0] if dim == 2 else reference[0]
        ref_out = outputs["coco17"][1] if dim == 2 else reference[1]
        common = [m for m in names if m in ref_names]
        assert len(common) >= 12, name
        k = 2 * dim
        for a, b in zip(out, ref_out):
            a = a.reshape(len(a), -1, k)[:, [names.index(m) for m in common]]
            b = b.reshape(len(b), -1, k)[:, [ref_names.index(m) for m in common]]
            np.testing.assert_allclose(a, b, atol=1e-9, err_msg=name)


def test_2d_output_is_close_to_the_frontal_plane_of_3d():
    """Perspective changes the picture a little; the 2-D features follow the 3-D (y, z)."""
    clips3, _ = _positions("kinect_v1", noise=0.0)
    clips2, _ = _positions("coco17", noise=0.0)
    out3 = VirtualMarkerTransform(layout="kinect_v1", velocities=False).fit_transform(clips3)
    out2 = VirtualMarkerTransform(layout="coco17", velocities=False).fit_transform(clips2)
    names3 = VirtualMarkerTransform(layout="kinect_v1", velocities=False).fit(clips3).marker_names_
    names2 = VirtualMarkerTransform(layout="coco17", velocities=False).fit(clips2).marker_names_
    k = [list(names3).index(m) for m in names2]
    wave = out3[1].reshape(len(out3[1]), -1, 3)[:, k, 1:]  # the wave hardly turns
    lateral = np.abs(wave[..., 0] - out2[1].reshape(len(out2[1]), -1, 2)[..., 0])
    assert np.median(lateral) < 0.05


def test_a_user_layout_in_a_few_lines():
    clips, _ = _positions("kinect_v1")
    mine = Layout(
        "lab",
        get_layout("kinect_v1").joints,
        root="HipCenter",
        left_hip="HipLeft",
        right_hip="HipRight",
        left_shoulder="ShoulderLeft",
        right_shoulder="ShoulderRight",
        size_chain=["AnkleLeft", "KneeLeft", "HipLeft", "ShoulderLeft"],
        landmarks={"HipCenter": "pelvis", "KneeLeft": "left_knee"},
    )
    vmt = VirtualMarkerTransform(layout=mine, frame_rate=30.0).fit(clips)
    assert vmt.marker_names_.tolist() == ["pelvis", "left_knee"]  # MARKER_NAMES order
    out = vmt.transform(clips)[0].reshape(-1, 2, 6)
    np.testing.assert_allclose(out[:, 0, :2], 0.0, atol=1e-12)  # the origin is below the root
    with pytest.raises(ValueError, match="'Knee' is not one of its joints"):
        Layout("bad", ["a", "b"], root="a", left_hip="a", right_hip="b", left_shoulder="a",
               right_shoulder="Knee", size_chain=["a", "b"])  # fmt: skip
    with pytest.raises(ValueError, match="fewer than 4 joints"):
        Layout("bad", ["a", "b"], root="a", left_hip="a", right_hip="b", left_shoulder="a",
               right_shoulder="b", size_chain=["a", "b"], groups=[["a", "b"]])  # fmt: skip


def test_velocities_off_gives_the_positions_only():
    clips, _ = _positions("azure_kinect")
    full = VirtualMarkerTransform(layout="azure_kinect", frame_rate=30.0).fit(clips)
    bare = VirtualMarkerTransform(layout="azure_kinect", velocities=False).fit(clips)
    a, b = full.transform(clips)[0], bare.transform(clips)[0]
    np.testing.assert_array_equal(b, a.reshape(len(a), -1, 6)[..., :3].reshape(len(a), -1))
    assert bare.get_feature_names_out()[:3].tolist() == ["head_px", "head_py", "head_pz"]


@pytest.mark.parametrize("factor", [1e150, 1e-150, 1e160, 2.0**-1000])
def test_extreme_scales_give_the_same_output(factor):
    clips, _ = _positions("kinect_v2")
    vmt = VirtualMarkerTransform(layout="kinect_v2", frame_rate=30.0).fit(clips)
    np.testing.assert_allclose(
        vmt.transform([c * factor for c in clips])[0], vmt.transform(clips)[0], atol=1e-12, rtol=0
    )
    unscaled = VirtualMarkerTransform(layout="kinect_v2", size_markers=None, frame_rate=30.0)
    out = unscaled.fit_transform([clips[0] * factor])[0]
    np.testing.assert_allclose(out / factor, unscaled.transform([clips[0]])[0], atol=1e-12)


def test_a_body_lost_in_rounding_is_a_clear_error():
    clips, _ = _positions("kinect_v2")
    far = clips[0] + 1e150  # every joint 1e150 from the origin: the body rounds away
    with pytest.raises(ValueError, match="clip 0: the body size .* lost in floating-point"):
        VirtualMarkerTransform(layout="kinect_v2", frame_rate=30.0).fit_transform([far])


def test_chunks_give_the_same_features_as_one_pass():
    rng = np.random.default_rng(0)
    points = np.cumsum(rng.normal(size=(50, 5, 3)), axis=0)
    kw = dict(root=(0,), lefts=(1,), rights=(2,), size_chain=(3, 4), frame_rate=10.0)
    one = position_frame_features(points, chunk=4096, **kw)
    np.testing.assert_array_equal(position_frame_features(points, chunk=7, **kw), one)
    np.testing.assert_array_equal(position_frame_features(points, chunk=1, **kw), one)


def test_memory_stays_near_the_output_size():
    n = 20_000
    clip = np.tile(_positions("kinect_v2")[0][0], (n // 30 + 1, 1))[:n]
    vmt = VirtualMarkerTransform(layout="kinect_v2", markers="all", frame_rate=30.0).fit([clip])
    tracemalloc.start()
    out = vmt.transform([clip])[0]
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert peak < 1.5 * out.nbytes + 20e6


def test_layout_errors_name_what_and_where():
    clips, _ = _positions("kinect_v2")
    with pytest.raises(ValueError, match="layout 'coco17' has 17 joints x 2 coordinates = 34"):
        VirtualMarkerTransform(layout="coco17", frame_rate=30.0).fit(clips)
    with pytest.raises(ValueError, match="root_marker='HipCenter' would be ignored"):
        VirtualMarkerTransform(layout="kinect_v2", root_marker="HipCenter", frame_rate=30).fit(
            clips
        )
    with pytest.raises(ValueError, match="give frame_rate="):
        VirtualMarkerTransform(layout="kinect_v2").fit(clips)
    with pytest.raises(ValueError, match="layout= is for joint-position clips"):
        VirtualMarkerTransform(humanoid_skeleton(), layout="kinect_v2", frame_rate=30).fit(clips)
    with pytest.raises(ValueError, match="'Elbow' is not a joint of layout 'kinect_v2'"):
        VirtualMarkerTransform(layout="kinect_v2", markers=["Elbow"], frame_rate=30).fit(clips)
    with pytest.raises(ValueError, match="Unknown layout 'kinect'"):
        get_layout("kinect")


def _case(name):
    def make():
        data = make_position_motions(
            name, n_clips_per_class=3, classes=["walk", "wave"], duration=(0.6, 0.9), random_state=0
        )
        return data.clips, data.target

    return make


@parametrize_with_clip_checks(
    [
        ClipCase(
            VirtualMarkerTransform(layout="kinect_v2", frame_rate=30.0),
            _case("kinect_v2"),
            param_grid={"velocities": [True, False]},
        ),
        ClipCase(VirtualMarkerTransform(layout="coco17", frame_rate=30.0), _case("coco17")),
    ]
)
def test_conformance(check):
    check()


def test_joint_angle_clips_times_1e150_raise_a_clear_error():
    """Angles x 1e150 put the root 1e150 away while the bones stay 1 long: no body left."""
    data = make_position_motions("kinect_v2", n_clips_per_class=1, classes=["walk"], random_state=0)
    skeleton, angles = data.skeletons[0], data.angles[0]
    vmt = VirtualMarkerTransform(skeleton, frame_rate=30.0).fit([angles])
    with pytest.raises(ValueError, match="clip 0: the body size .* lost in floating-point"):
        vmt.transform([angles * 1e150])


@pytest.mark.parametrize("name", sorted(LAYOUTS))
def test_layout_bones_join_the_body_into_one_tree_or_torso(name):
    """Bones join joints of the layout; the joints on the shared markers form one connected body."""
    layout = get_layout(name)
    bones = layout.bones
    assert all(a in layout.joints and b in layout.joints and a != b for a, b in bones)
    on_markers = {j for j, _ in layout.shared_markers}
    joined = {j for bone in bones for j in bone}
    assert joined <= on_markers
    # connected: a walk over the bones from any joint reaches every joined joint
    seen, todo = set(), [bones[0][0]]
    while todo:
        joint = todo.pop()
        if joint not in seen:
            seen.add(joint)
            todo += [b if a == joint else a for a, b in bones if joint in (a, b)]
    assert seen == joined
    # limbs run from the body outwards: each wrist and ankle is a bone's child, never a parent
    for end in ("left_wrist", "right_wrist", "left_ankle", "right_ankle"):
        joint = {m: j for j, m in layout.shared_markers}.get(end)
        if joint is not None:
            assert any(b == joint for _, b in bones)
