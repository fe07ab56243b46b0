"""The named joint layouts of trackers and pose estimators, with their sources.

Joint orders follow each system's documentation (see the ``source`` of each
layout and ``docs/positions.md``): Kinect v1/v2 ``JointType``, Azure Kinect
``k4abt_joint_id_t``, the COCO person keypoints, OpenPose ``BODY_25``, MediaPipe
``PoseLandmark``, the Human3.6M 17-joint subset and the SMPL joints.
"""

from dataclasses import replace

from skmotion.kinematics._layouts import Layout

__all__ = ["LAYOUTS", "get_layout"]


def _sided(left, right, parts):
    """Landmarks of both sides: ``parts`` maps a joint pattern to a part name."""
    out = {}
    for pattern, part in parts.items():
        for side, tag in (("left", left), ("right", right)):
            out[pattern.format(s=tag)] = part.format(side=side)
    return out


_LIMB = {
    "Shoulder{s}": "{side}_shoulder",
    "Elbow{s}": "{side}_elbow",
    "Wrist{s}": "{side}_wrist",
    "Hand{s}": "{side}_hand",
    "Hip{s}": "{side}_hip",
    "Knee{s}": "{side}_knee",
    "Ankle{s}": "{side}_ankle",
    "Foot{s}": "{side}_toe",
}
_KINECT_V1 = (
    "HipCenter Spine ShoulderCenter Head ShoulderLeft ElbowLeft WristLeft HandLeft "
    "ShoulderRight ElbowRight WristRight HandRight HipLeft KneeLeft AnkleLeft FootLeft "
    "HipRight KneeRight AnkleRight FootRight"
).split()
_KINECT_V2 = (
    "SpineBase SpineMid Neck Head ShoulderLeft ElbowLeft WristLeft HandLeft ShoulderRight "
    "ElbowRight WristRight HandRight HipLeft KneeLeft AnkleLeft FootLeft HipRight KneeRight "
    "AnkleRight FootRight SpineShoulder HandTipLeft ThumbLeft HandTipRight ThumbRight"
).split()
_AZURE = (
    "PELVIS SPINE_NAVEL SPINE_CHEST NECK CLAVICLE_LEFT SHOULDER_LEFT ELBOW_LEFT WRIST_LEFT "
    "HAND_LEFT HANDTIP_LEFT THUMB_LEFT CLAVICLE_RIGHT SHOULDER_RIGHT ELBOW_RIGHT "
    "WRIST_RIGHT HAND_RIGHT HANDTIP_RIGHT THUMB_RIGHT HIP_LEFT KNEE_LEFT ANKLE_LEFT "
    "FOOT_LEFT HIP_RIGHT KNEE_RIGHT ANKLE_RIGHT FOOT_RIGHT HEAD NOSE EYE_LEFT EAR_LEFT "
    "EYE_RIGHT EAR_RIGHT"
).split()
_COCO = (
    "nose left_eye right_eye left_ear right_ear left_shoulder right_shoulder left_elbow "
    "right_elbow left_wrist right_wrist left_hip right_hip left_knee right_knee left_ankle "
    "right_ankle"
).split()
_BODY25 = (
    "Nose Neck RShoulder RElbow RWrist LShoulder LElbow LWrist MidHip RHip RKnee RAnkle "
    "LHip LKnee LAnkle REye LEye REar LEar LBigToe LSmallToe LHeel RBigToe RSmallToe RHeel"
).split()
_MEDIAPIPE = (
    "nose left_eye_inner left_eye left_eye_outer right_eye_inner right_eye right_eye_outer "
    "left_ear right_ear mouth_left mouth_right left_shoulder right_shoulder left_elbow "
    "right_elbow left_wrist right_wrist left_pinky right_pinky left_index right_index "
    "left_thumb right_thumb left_hip right_hip left_knee right_knee left_ankle right_ankle "
    "left_heel right_heel left_foot_index right_foot_index"
).split()
_H36M17 = (
    "hip right_hip right_knee right_ankle left_hip left_knee left_ankle spine thorax "
    "neck_nose head left_shoulder left_elbow left_wrist right_shoulder right_elbow "
    "right_wrist"
).split()
_SMPL = (
    "pelvis left_hip right_hip spine1 left_knee right_knee spine2 left_ankle right_ankle "
    "spine3 left_foot right_foot neck left_collar right_collar head left_shoulder "
    "right_shoulder left_elbow right_elbow left_wrist right_wrist left_hand right_hand"
).split()

# Landmarks of joints whose names are already anatomical snake_case (COCO, MediaPipe, H36M, SMPL).
_SNAKE = _sided(
    "left",
    "right",
    {
        "{s}_shoulder": "{side}_shoulder",
        "{s}_elbow": "{side}_elbow",
        "{s}_wrist": "{side}_wrist",
        "{s}_hip": "{side}_hip",
        "{s}_knee": "{side}_knee",
        "{s}_ankle": "{side}_ankle",
        "{s}_eye": "{side}_eye",
        "{s}_ear": "{side}_ear",
        "{s}_eye_inner": "{side}_eye_inner",
        "{s}_eye_outer": "{side}_eye_outer",
        "mouth_{s}": "mouth_{side}",
        "{s}_pinky": "{side}_pinky",
        "{s}_index": "{side}_index",
        "{s}_thumb": "{side}_thumb",
        "{s}_heel": "{side}_heel",
        "{s}_foot_index": "{side}_foot_index",
        "{s}_collar": "{side}_clavicle",
        "{s}_foot": "{side}_toe",
        "{s}_hand": "{side}_hand",
    },
)


def _pick(joints, table):
    return {j: table[j] for j in joints if j in table}


_SRC_K1 = "Kinect for Windows SDK 1.8, NUI_SKELETON_POSITION_INDEX / JointType (Microsoft Learn)"
_SRC_K2 = "Kinect for Windows SDK 2.0, JointType enumeration (Microsoft Learn)"
_SRC_AZ = "Azure Kinect Body Tracking SDK, k4abt_joint_id_t in k4abttypes.h"
_SRC_COCO = "COCO keypoints: person category 'keypoints' list (cocodataset.org, Lin et al. 2014)"
_SRC_OP = "OpenPose output format, POSE_BODY_25_BODY_PARTS (doc/02_output.md)"
_SRC_MP = "MediaPipe Pose Landmarker, PoseLandmark enumeration (33 landmarks)"
_SRC_H36M = "Human3.6M 17-joint subset as used by VideoPose3D (Pavllo et al. 2019)"
_SRC_SMPL = "SMPL joint order, JOINT_NAMES of the smplx package (Loper et al. 2015)"

_LAYOUT_LIST = [
    Layout(
        "kinect_v1",
        _KINECT_V1,
        root=("HipLeft", "HipRight"),
        left_hip="HipLeft",
        right_hip="HipRight",
        left_shoulder="ShoulderLeft",
        right_shoulder="ShoulderRight",
        size_chain=("AnkleLeft", "KneeLeft", "HipLeft", "ShoulderLeft"),
        landmarks={
            "HipCenter": "pelvis",
            "Spine": "spine",
            "ShoulderCenter": "chest",
            "Head": "head",
            **_pick(_KINECT_V1, _sided("Left", "Right", _LIMB)),
        },
        source=_SRC_K1,
    ),
    Layout(
        "kinect_v2",
        _KINECT_V2,
        root=("HipLeft", "HipRight"),
        left_hip="HipLeft",
        right_hip="HipRight",
        left_shoulder="ShoulderLeft",
        right_shoulder="ShoulderRight",
        size_chain=("AnkleLeft", "KneeLeft", "HipLeft", "ShoulderLeft"),
        landmarks={
            "SpineBase": "pelvis",
            "SpineMid": "spine",
            "Neck": "neck",
            "Head": "head",
            "SpineShoulder": "chest",
            **_pick(_KINECT_V2, _sided("Left", "Right", _LIMB)),
            **_sided("Left", "Right", {"HandTip{s}": "{side}_hand_tip"}),
            **_sided("Left", "Right", {"Thumb{s}": "{side}_thumb"}),
        },
        groups=[(f"Wrist{s}", f"Hand{s}", f"HandTip{s}", f"Thumb{s}") for s in ("Left", "Right")],
        source=_SRC_K2,
    ),
    Layout(
        "azure_kinect",
        _AZURE,
        root=("HIP_LEFT", "HIP_RIGHT"),
        left_hip="HIP_LEFT",
        right_hip="HIP_RIGHT",
        left_shoulder="SHOULDER_LEFT",
        right_shoulder="SHOULDER_RIGHT",
        size_chain=("ANKLE_LEFT", "KNEE_LEFT", "HIP_LEFT", "SHOULDER_LEFT"),
        up="-y",
        landmarks={
            "PELVIS": "pelvis",
            "SPINE_NAVEL": "spine",
            "SPINE_CHEST": "chest",
            "NECK": "neck",
            "HEAD": "head",
            "NOSE": "nose",
            **_sided(
                "LEFT",
                "RIGHT",
                {
                    "CLAVICLE_{s}": "{side}_clavicle",
                    "SHOULDER_{s}": "{side}_shoulder",
                    "ELBOW_{s}": "{side}_elbow",
                    "WRIST_{s}": "{side}_wrist",
                    "HAND_{s}": "{side}_hand",
                    "HANDTIP_{s}": "{side}_hand_tip",
                    "THUMB_{s}": "{side}_thumb",
                    "HIP_{s}": "{side}_hip",
                    "KNEE_{s}": "{side}_knee",
                    "ANKLE_{s}": "{side}_ankle",
                    "FOOT_{s}": "{side}_toe",
                    "EYE_{s}": "{side}_eye",
                    "EAR_{s}": "{side}_ear",
                },
            ),
        },
        groups=[
            ("HEAD", "NOSE", "EYE_LEFT", "EAR_LEFT", "EYE_RIGHT", "EAR_RIGHT"),
            *[(f"WRIST_{s}", f"HAND_{s}", f"HANDTIP_{s}", f"THUMB_{s}") for s in ("LEFT", "RIGHT")],
        ],
        source=_SRC_AZ,
    ),
    Layout(
        "coco17",
        _COCO,
        root=("left_hip", "right_hip"),
        left_hip="left_hip",
        right_hip="right_hip",
        left_shoulder="left_shoulder",
        right_shoulder="right_shoulder",
        size_chain=("left_ankle", "left_knee", "left_hip", "left_shoulder"),
        dim=2,
        up="-y",
        landmarks={"nose": "nose", **_pick(_COCO, _SNAKE)},
        groups=[("nose", "left_eye", "right_eye", "left_ear", "right_ear")],
        source=_SRC_COCO,
    ),
    Layout(
        "openpose_body25",
        _BODY25,
        root=("LHip", "RHip"),
        left_hip="LHip",
        right_hip="RHip",
        left_shoulder="LShoulder",
        right_shoulder="RShoulder",
        size_chain=("LAnkle", "LKnee", "LHip", "LShoulder"),
        dim=2,
        up="-y",
        landmarks={
            "Nose": "nose",
            "Neck": "chest",
            "MidHip": "pelvis",
            **_sided(
                "L",
                "R",
                {
                    "{s}Shoulder": "{side}_shoulder",
                    "{s}Elbow": "{side}_elbow",
                    "{s}Wrist": "{side}_wrist",
                    "{s}Hip": "{side}_hip",
                    "{s}Knee": "{side}_knee",
                    "{s}Ankle": "{side}_ankle",
                    "{s}Eye": "{side}_eye",
                    "{s}Ear": "{side}_ear",
                    "{s}BigToe": "{side}_big_toe",
                    "{s}SmallToe": "{side}_small_toe",
                    "{s}Heel": "{side}_heel",
                },
            ),
        },
        groups=[
            ("Nose", "REye", "LEye", "REar", "LEar"),
            *[(f"{s}Ankle", f"{s}BigToe", f"{s}SmallToe", f"{s}Heel") for s in ("L", "R")],
        ],
        source=_SRC_OP,
    ),
    Layout(
        "mediapipe_pose33",
        _MEDIAPIPE,
        root=("left_hip", "right_hip"),
        left_hip="left_hip",
        right_hip="right_hip",
        left_shoulder="left_shoulder",
        right_shoulder="right_shoulder",
        size_chain=("left_ankle", "left_knee", "left_hip", "left_shoulder"),
        up="-y",
        landmarks={"nose": "nose", **_pick(_MEDIAPIPE, _SNAKE)},
        groups=[
            tuple(_MEDIAPIPE[:11]),
            *[(f"{s}_wrist", f"{s}_pinky", f"{s}_index", f"{s}_thumb") for s in ("left", "right")],
        ],
        source=_SRC_MP,
    ),
    Layout(
        "h36m17",
        _H36M17,
        root=("left_hip", "right_hip"),
        left_hip="left_hip",
        right_hip="right_hip",
        left_shoulder="left_shoulder",
        right_shoulder="right_shoulder",
        size_chain=("left_ankle", "left_knee", "left_hip", "left_shoulder"),
        up="z",
        landmarks={
            "hip": "pelvis",
            "spine": "spine",
            "thorax": "chest",
            "neck_nose": "neck",
            "head": "head_top",
            **_pick(_H36M17, _SNAKE),
        },
        source=_SRC_H36M,
    ),
    Layout(
        "smpl24",
        _SMPL,
        root=("left_hip", "right_hip"),
        left_hip="left_hip",
        right_hip="right_hip",
        left_shoulder="left_shoulder",
        right_shoulder="right_shoulder",
        size_chain=("left_ankle", "left_knee", "left_hip", "left_shoulder"),
        landmarks={
            "pelvis": "pelvis",
            "spine1": "spine",
            "spine2": "spine_mid",
            "spine3": "chest",
            "neck": "neck",
            "head": "head",
            **_pick(_SMPL, _SNAKE),
        },
        source=_SRC_SMPL,
    ),
]
#: The named layouts, by name.
LAYOUTS = {layout.name: layout for layout in _LAYOUT_LIST}


def get_layout(name, *, dim=None):
    """A named layout, or a user's :class:`Layout` passed through.

    Parameters
    ----------
    name : str or Layout
        One of :data:`LAYOUTS` (``kinect_v1``, ``kinect_v2``,
        ``azure_kinect``, ``coco17``, ``openpose_body25``,
        ``mediapipe_pose33``, ``h36m17``, ``smpl24``), or a Layout.
    dim : {2, 3}, default=None
        Override the layout's dimension: ``dim=2`` for the image keypoints of
        a 3-D system (MediaPipe's normalised image landmarks, say), ``dim=3``
        for 3-D keypoints in a 2-D system's joint order. In 2-D the up axis
        becomes ``"-y"`` (image rows grow downward) unless the layout is 2-D.

    Returns
    -------
    layout : Layout

    Examples
    --------
    >>> from skmotion.preprocessing import get_layout
    >>> kinect = get_layout("kinect_v2")
    >>> kinect.n_joints, kinect.joints[:4], kinect.dim
    (25, ('SpineBase', 'SpineMid', 'Neck', 'Head'), 3)
    >>> get_layout("mediapipe_pose33", dim=2).up
    '-y'
    """
    if isinstance(name, Layout):
        layout = name
    elif isinstance(name, str) and name in LAYOUTS:
        layout = LAYOUTS[name]
    else:
        raise ValueError(f"Unknown layout {name!r}; the named layouts are {sorted(LAYOUTS)}.")
    if dim is None or dim == layout.dim:
        return layout
    if dim not in (2, 3):
        raise ValueError(f"dim must be 2 or 3, got {dim!r}.")
    up = "-y" if dim == 2 else "y"
    return replace(layout, dim=dim, up=up, name=f"{layout.name}_{dim}d")
