"""match_joints and the 'matched' marker preset on rigs of many naming conventions.

The rigs are built here from one body plan (slots: pelvis, spine, chest, ...), each
convention giving its own names, its own extra joints (twist bones, fingers, spine
splits, a namespace) and, for some, no clavicle or no head end site. The truth is the
slot each joint was made for."""

import numpy as np
import pytest

from skmotion.kinematics import Skeleton, match_joints
from skmotion.preprocessing import VirtualMarkerTransform, detect_marker_preset, marker_preset

# slot: (parent slot, offset for a 1.75 m adult, y up, facing +z, left = +x)
BODY = {
    "pelvis": (None, (0, 0.95, 0)),
    "spine": ("pelvis", (0, 0.1, 0)),
    "chest": ("spine", (0, 0.2, 0)),
    "neck": ("chest", (0, 0.22, 0)),
    "head": ("neck", (0, 0.1, 0)),
    "head_end": ("head", (0, 0.18, 0)),
}
for _s, _x in (("left", 1), ("right", -1)):
    BODY.update(
        {
            f"{_s}_clavicle": ("chest", (_x * 0.03, 0.2, 0)),
            f"{_s}_shoulder": (f"{_s}_clavicle", (_x * 0.16, 0, 0)),
            f"{_s}_elbow": (f"{_s}_shoulder", (0, -0.29, 0)),
            f"{_s}_wrist": (f"{_s}_elbow", (0, -0.25, 0)),
            f"{_s}_hand_end": (f"{_s}_wrist", (0, -0.09, 0)),
            f"{_s}_hip": ("pelvis", (_x * 0.09, -0.05, 0)),
            f"{_s}_knee": (f"{_s}_hip", (0, -0.42, 0)),
            f"{_s}_ankle": (f"{_s}_knee", (0, -0.4, 0)),
            f"{_s}_toe": (f"{_s}_ankle", (0, -0.06, 0.13)),
        }
    )

_LIMB = ("clavicle", "shoulder", "elbow", "wrist", "hip", "knee", "ankle", "toe")


def _sided(fmt_left, fmt_right, names):
    """Slot names per side from a format with ``{}`` for the segment word."""
    out = {}
    for side, fmt in (("left", fmt_left), ("right", fmt_right)):
        out.update({f"{side}_{slot}": fmt.format(word) for slot, word in zip(_LIMB, names)})
    return out


# name per slot (None: the rig has no such joint) and extra joints (name, parent slot, offset)
CONVENTIONS = {
    "mixamo": (
        {
            "pelvis": "mixamorig:Hips",
            "spine": "mixamorig:Spine",
            "chest": "mixamorig:Spine2",
            "neck": "mixamorig:Neck",
            "head": "mixamorig:Head",
            "head_end": "mixamorig:HeadTop_End",
            "left_hand_end": "mixamorig:LeftHandMiddle1",
            "right_hand_end": "mixamorig:RightHandMiddle1",
            **_sided(
                "mixamorig:Left{}",
                "mixamorig:Right{}",
                ["Shoulder", "Arm", "ForeArm", "Hand", "UpLeg", "Leg", "Foot", "ToeBase"],
            ),
        },
        [
            ("mixamorig:LeftHandIndex1", "left_wrist", (0.02, -0.08, 0.01)),
            ("mixamorig:RightHandIndex1", "right_wrist", (-0.02, -0.08, 0.01)),
        ],
    ),
    "unreal": (
        {
            "pelvis": "pelvis",
            "spine": "spine_01",
            "chest": "spine_03",
            "neck": "neck_01",
            "head": "head",
            "head_end": None,
            "left_hand_end": "middle_01_l",
            "right_hand_end": "middle_01_r",
            **_sided(
                "{}_l",
                "{}_r",
                ["clavicle", "upperarm", "lowerarm", "hand", "thigh", "calf", "foot", "ball"],
            ),
        },
        [
            ("upperarm_twist_01_l", "left_shoulder", (0.0, -0.1, 0)),
            ("upperarm_twist_01_r", "right_shoulder", (0.0, -0.1, 0)),
            ("thigh_twist_01_l", "left_hip", (0.0, -0.2, 0)),
            ("ik_foot_root", "pelvis", (0.0, -0.95, 0)),
        ],
    ),
    "humanik": (
        {
            "pelvis": "Character1_Hips",
            "spine": "Character1_Spine",
            "chest": "Character1_Spine1",
            "neck": "Character1_Neck",
            "head": "Character1_Head",
            "head_end": None,
            "left_hand_end": "Character1_LeftHandMiddle1",
            "right_hand_end": "Character1_RightHandMiddle1",
            **_sided(
                "Character1_Left{}",
                "Character1_Right{}",
                ["Shoulder", "Arm", "ForeArm", "Hand", "UpLeg", "Leg", "Foot", "ToeBase"],
            ),
        },
        [],
    ),
    "biped": (
        {
            "pelvis": "Bip01 Pelvis",
            "spine": "Bip01 Spine",
            "chest": "Bip01 Spine1",
            "neck": "Bip01 Neck",
            "head": "Bip01 Head",
            "head_end": "Bip01 HeadNub",
            "left_hand_end": "Bip01 L Finger2",
            "right_hand_end": "Bip01 R Finger2",
            **_sided(
                "Bip01 L {}",
                "Bip01 R {}",
                ["Clavicle", "UpperArm", "Forearm", "Hand", "Thigh", "Calf", "Foot", "Toe0"],
            ),
        },
        [
            ("Bip01 L Finger0", "left_wrist", (0.03, -0.05, 0.02)),
            ("Bip01 R Finger0", "right_wrist", (-0.03, -0.05, 0.02)),
        ],
    ),
    "xsens": (
        {
            "pelvis": "Pelvis",
            "spine": "L3",
            "chest": "T8",
            "neck": "Neck",
            "head": "Head",
            "head_end": None,
            "left_hand_end": None,
            "right_hand_end": None,
            **_sided(
                "Left{}",
                "Right{}",
                ["Shoulder", "UpperArm", "ForeArm", "Hand", "UpperLeg", "LowerLeg", "Foot", "Toe"],
            ),
        },
        [],
    ),
    "cmu_asf": (
        {
            "pelvis": "root",
            "spine": "lowerback",
            "chest": "thorax",
            "neck": "lowerneck",
            "head": "head",
            "head_end": None,
            "left_hand_end": "lhand",
            "right_hand_end": "rhand",
            **_sided(
                "l{}",
                "r{}",
                ["clavicle", "humerus", "radius", "wrist", "femur", "tibia", "foot", "toes"],
            ),
        },
        [],
    ),
    "suffix_no_clavicle": (  # the held-out rig's style: UpperArm_L, LowerLeg_R; no clavicle
        {
            "pelvis": "Hips",
            "spine": "Spine",
            "chest": "Chest",
            "neck": "Neck",
            "head": "Head",
            "head_end": None,
            "left_hand_end": None,
            "right_hand_end": None,
            **_sided(
                "{}_L",
                "{}_R",
                ["", "UpperArm", "LowerArm", "Hand", "UpperLeg", "LowerLeg", "Foot", "Toes"],
            ),
            "left_clavicle": None,
            "right_clavicle": None,
        },
        [],
    ),
    "smpl": (  # L_Shoulder is the shoulder joint, L_Collar the clavicle, L_Foot the toes
        {
            "pelvis": "Pelvis",
            "spine": "Spine1",
            "chest": "Spine3",
            "neck": "Neck",
            "head": "Head",
            "head_end": None,
            "left_hand_end": "L_Hand",
            "right_hand_end": "R_Hand",
            **_sided(
                "L_{}",
                "R_{}",
                ["Collar", "Shoulder", "Elbow", "Wrist", "Hip", "Knee", "Ankle", "Foot"],
            ),
        },
        [],
    ),
}


def make_rig(convention, scale=1.0, up="y"):
    """The rig of a convention: (skeleton, slot -> joint name)."""
    names, extras = CONVENTIONS[convention]
    slots = [s for s in BODY if names.get(s) is not None]
    joints = [names[s] for s in slots] + [e[0] for e in extras]
    parent_slot = {}
    for s in slots:
        p = BODY[s][0]
        while p is not None and names.get(p) is None:  # a missing slot: its child hangs higher
            p = BODY[p][0]
        parent_slot[s] = p
    offsets = [np.array(BODY[s][1], float) for s in slots]
    for s in slots:  # a missing clavicle's offset goes to the shoulder
        p = BODY[s][0]
        if p is not None and names.get(p) is None:
            offsets[slots.index(s)] = offsets[slots.index(s)] + np.array(BODY[p][1])
    parents = [slots.index(parent_slot[s]) if parent_slot[s] else -1 for s in slots]
    parents += [slots.index(e[1]) for e in extras]
    offsets = np.array(offsets + [np.array(e[2], float) for e in extras]) * scale
    if up == "z":  # the same body lying in a Z-up world: y -> z, z -> -y
        offsets = offsets[:, [0, 2, 1]] * [1, -1, 1]
    rot = ["Zrotation", "Xrotation", "Yrotation"]
    channels = [["Xposition", "Yposition", "Zposition", *rot]] + [rot] * (len(joints) - 1)
    if "head_end" in slots:  # an end site, as BVH writes one: no channels
        channels[slots.index("head_end")] = []
    return Skeleton(joints, parents, offsets, channels, up_axis=up), {s: names[s] for s in slots}


@pytest.mark.parametrize("convention", sorted(CONVENTIONS))
def test_every_convention_matches_its_slots(convention):
    skeleton, truth = make_rig(convention)
    match = match_joints(skeleton)
    for role in ("head", "pelvis", "chest"):
        assert match.roles[role] == truth[role], role
    for side in ("left", "right"):
        for part in ("shoulder", "elbow", "wrist", "hip", "knee", "ankle", "toe"):
            role = f"{side}_{part}"
            assert match.roles[role] == truth[role], role
        if f"{side}_clavicle" in truth:
            assert match.roles[f"{side}_clavicle"] == truth[f"{side}_clavicle"]
        else:
            assert f"{side}_clavicle" in match.missing
    assert match.up_axis == "y"
    assert "left_shoulder" in match.report()


@pytest.mark.parametrize("convention", sorted(CONVENTIONS))
def test_virtual_markers_work_without_a_marker_set(convention, rng):
    skeleton, _ = make_rig(convention)
    expected = "cmu_asf" if convention == "cmu_asf" else "matched"
    preset = detect_marker_preset(skeleton)
    assert preset in (expected, "matched")
    clip = rng.normal(scale=0.2, size=(40, skeleton.n_channels)).cumsum(axis=0) * 0.1
    out = VirtualMarkerTransform(skeleton=skeleton, frame_rate=30.0).fit_transform([clip])[0]
    assert out.shape == (40, 6 * 32) and np.isfinite(out).all()
    # The markers sit where their names say, in the rest pose: head top above the
    # pelvis above the knees above the ankles; left markers on the left (+x).
    markers = marker_preset(skeleton, "matched")
    rest = dict(
        zip(markers.names, markers.positions(skeleton, np.zeros((1, skeleton.n_channels)))[0])
    )
    heights = [rest[m][1] for m in ("head_top", "neck", "pelvis", "left_knee", "left_ankle")]
    assert heights == sorted(heights, reverse=True)
    assert all(rest[f"left_{p}"][0] > 0 > rest[f"right_{p}"][0] for p in ("hand", "hip", "toe"))


def test_up_axis_from_the_rest_pose():
    for convention in ("unreal", "biped"):
        skeleton, _ = make_rig(convention, up="z")
        assert match_joints(skeleton).up_axis == "z"


def _retarget(rig, truth, slot_angles, root_path):
    """Channels of ``rig`` for angles given per slot (n_frames, 3) and a root path."""
    clip = np.zeros((len(root_path), rig.n_channels))
    clip[:, :3] = root_path
    for slot, angles in slot_angles.items():
        start = rig.channel_index(truth[slot], "Zrotation")
        clip[:, start : start + 3] = angles
    return clip


def test_one_motion_on_two_rigs_gives_the_same_marker_motion():
    """A walk-like motion retargeted onto an Unreal rig and a 15% taller Biped rig (other
    names, extra joints, a head without an end site on one): marker features correlate."""
    t = np.linspace(0, 2 * np.pi * 2, 120)
    swing = 0.5 * np.sin(t)
    angles = {}
    for side, sign in (("left", 1), ("right", -1)):
        z = np.zeros_like(t)
        angles[f"{side}_hip"] = np.stack([z, sign * swing, z], axis=1)  # Xrotation: swing
        angles[f"{side}_knee"] = np.stack([z, 0.6 * np.maximum(0, -sign * np.sin(t)), z], axis=1)
        angles[f"{side}_shoulder"] = np.stack([z, -sign * 0.7 * swing, z], axis=1)
        angles[f"{side}_elbow"] = np.stack([z, -0.4 - 0.2 * np.sin(t), z], axis=1)
    angles["spine"] = np.stack([0.1 * np.sin(2 * t), np.zeros_like(t), 0.2 * np.sin(t)], axis=1)
    path = np.stack([np.zeros_like(t), 0.95 + 0.02 * np.sin(2 * t), np.linspace(0, 2, 120)], axis=1)
    features = []
    for convention, scale in (("unreal", 1.0), ("biped", 1.15)):
        rig, truth = make_rig(convention, scale=scale)
        clip = _retarget(rig, truth, angles, path * [1, scale, scale])
        vmt = VirtualMarkerTransform(skeleton=rig, frame_rate=60.0)
        features.append(vmt.fit_transform([clip])[0])
    assert features[0].shape == features[1].shape == (120, 192)
    r = np.corrcoef(features[0].ravel(), features[1].ravel())[0, 1]
    assert r >= 0.95, r


def test_not_a_humanoid_is_refused_with_what_was_found():
    arm = Skeleton(
        ["base", "link1", "link2"],
        [-1, 0, 1],
        [[0, 0, 0], [0, 1, 0], [0, 1, 0]],
        [["Xrotation"], ["Xrotation"], []],
    )
    with pytest.raises(ValueError, match=r"No humanoid found .* no joint for \['head'"):
        match_joints(arm)
    with pytest.raises(ValueError, match="No marker preset fits this skeleton: No humanoid"):
        detect_marker_preset(arm)


def test_the_shared_bvh_and_asf_files(shared_data):
    from skmotion.io import read_asf, read_bvh

    walk = read_bvh(shared_data / "bvh-samples" / "AV_8Walk_Meredith_HVHA_Rep1.bvh")
    match = match_joints(walk.skeleton)
    assert (
        match.roles["left_shoulder"] == "LeftArm" and match.roles["left_clavicle"] == "LeftShoulder"
    )
    assert (
        match.roles["right_toe"] == "RightToeBase" and match.up_axis == walk.skeleton.up_axis == "y"
    )
    cc = read_bvh(sorted((shared_data / "cmu-bvh" / "07").glob("*.bvh"))[0])
    match = match_joints(cc.skeleton)
    assert match.roles["left_elbow"] == "CC_Base_L_Forearm"
    assert match.roles["right_knee"] == "CC_Base_R_Calf" and match.roles["head"] == "CC_Base_Head"
    asf = read_asf(shared_data / "cmu-asfamc" / "02" / "02.asf")
    match = match_joints(asf)
    assert [match.roles[f"left_{p}"] for p in ("shoulder", "elbow", "wrist", "knee")] == [
        "lhumerus",
        "lradius",
        "lwrist",
        "ltibia",
    ]
    # The matched markers and the fixed presets agree where both place a marker at a joint.
    for skeleton in (walk.skeleton, cc.skeleton, asf):
        fixed, matched = marker_preset(skeleton), marker_preset(skeleton, "matched")
        rest = np.zeros((1, skeleton.n_channels))
        a, b = fixed.positions(skeleton, rest)[0], matched.positions(skeleton, rest)[0]
        for name in ("left_knee", "right_elbow", "left_shoulder", "right_ankle", "pelvis"):
            k = fixed.names.index(name)
            np.testing.assert_allclose(a[k], b[k], atol=1e-3, err_msg=name)  # CC: Hip vs Pelvis


@pytest.mark.parametrize("convention", ["mixamo", "biped", "xsens", "suffix_no_clavicle"])
def test_topology_alone_when_the_names_say_nothing(convention):
    """Every joint renamed ``bone_<k>`` in a shuffled order: the tree and the rest pose
    find the same limbs, and left from up x forward (the feet point forward). Topology
    alone cannot tell a hand joint below the wrist (CMU's lhand, SMPL's L_Hand, a lone
    finger with channels) from the
    wrist, nor a helper branch as long as a leg (Unreal's ik_foot_root) from a leg: those
    rigs need their names."""
    skeleton, truth = make_rig(convention)
    order = np.random.default_rng(3).permutation(skeleton.n_joints - 1) + 1
    renamed = {name: f"bone_{k:02d}" for name, k in zip(skeleton.joints, [0, *order])}
    anonymous = Skeleton(
        [renamed[j] for j in skeleton.joints],
        skeleton.parents,
        skeleton.offsets,
        skeleton.channels,
    )
    match = match_joints(anonymous)
    assert set(match.how.values()) == {"topology"}
    for side in ("left", "right"):
        for part in ("shoulder", "elbow", "wrist", "knee", "ankle"):
            role = f"{side}_{part}"
            assert match.roles[role] == renamed[truth[role]], role
    assert match.roles["head"] == renamed[truth["head"]] and match.up_axis == "y"
    out = VirtualMarkerTransform(skeleton=anonymous, frame_rate=30.0).fit_transform(
        [np.zeros((3, anonymous.n_channels))]
    )[0]
    assert out.shape == (3, 192)
