"""check_layout and load_motion_folder(layout=): a joint order that does not fit is named.

The truth: clips written in one joint order and read in another. A folder of 40
keypoint files in another tracker's order must warn and name joints; the right order
must not warn. On synthetic data (make_position_motions) and on MSRC-12's real Kinect v1
recordings.
"""

import warnings

import numpy as np
import pytest

from skmotion.datasets import load_motion_folder, make_position_motions
from skmotion.kinematics import Layout, check_layout, get_layout

# Kinect v1's 20 joints in the order an OpenNI-style tracker writes them (head first):
# the same joints, another order.
OTHER_ORDER = [
    "Head", "ShoulderCenter", "Spine", "HipCenter", "ShoulderLeft", "ElbowLeft", "WristLeft",
    "HandLeft", "ShoulderRight", "ElbowRight", "WristRight", "HandRight", "HipLeft", "KneeLeft",
    "AnkleLeft", "FootLeft", "HipRight", "KneeRight", "AnkleRight", "FootRight",
]  # fmt: skip


def _reorder(clips, source, target):
    """Clips in joint order ``source`` rewritten in order ``target`` (3-D, joint-major)."""
    perm = [list(source).index(j) for j in target]
    return [c.reshape(len(c), len(source), 3)[:, perm].reshape(len(c), -1) for c in clips]


def _write_npy(folder, clips):
    folder.mkdir(parents=True, exist_ok=True)
    for k, clip in enumerate(clips):
        np.save(folder / f"take{k:02d}.npy", clip)
    return folder


def _load(folder, layout):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        data = load_motion_folder(folder, layout=layout, frame_rate=30.0)
    messages = [str(w.message) for w in caught if "joint order" in str(w.message)]
    return data, messages


def test_the_right_order_passes_every_named_3d_layout():
    for name in ("kinect_v1", "kinect_v2", "azure_kinect", "h36m17", "smpl24", "mediapipe_pose33"):
        data = make_position_motions(name, n_clips_per_class=1, random_state=1)
        assert check_layout(data.clips, name) == [], name


def test_a_tracker_read_in_another_trackers_order_is_named():
    # Kinect v2 positions read as OpenPose BODY_25 (both 25 joints, 3-D here).
    data = make_position_motions("kinect_v2", n_clips_per_class=1, random_state=0)
    problems = check_layout(data.clips, get_layout("openpose_body25", dim=3))
    text = " ".join(problems)
    assert "head Nose is above pelvis MidHip in only 0% of frames" in problems
    assert "left bone" in text and "LKnee-LAnkle" in text  # a named joint pair


def test_random_permutations_are_caught():
    data = make_position_motions("kinect_v2", n_clips_per_class=1, random_state=0)
    joints = get_layout("kinect_v2").joints
    rng = np.random.default_rng(0)
    for _ in range(20):
        order = list(rng.permutation(joints))
        assert check_layout(_reorder(data.clips, joints, order), "kinect_v2"), order


def test_a_folder_of_40_files_in_another_order_warns_naming_the_joints(tmp_path):
    data = make_position_motions("kinect_v1", n_clips_per_class=6, random_state=0)
    clips = data.clips[:40]
    assert len(clips) == 40
    joints = get_layout("kinect_v1").joints
    right, messages = _load(_write_npy(tmp_path / "right", clips), "kinect_v1")
    assert messages == [] and len(right.clips) == 40
    np.testing.assert_array_equal(right.clips[7], clips[7])
    wrong = _write_npy(tmp_path / "wrong", _reorder(clips, joints, OTHER_ORDER))
    _, messages = _load(wrong, "kinect_v1")
    assert len(messages) == 1
    assert "layout 'kinect_v1'" in messages[0]
    assert "head Head is above pelvis HipCenter in only 0% of frames" in messages[0]


def test_msrc12_kinect_v1_in_another_order_warns_and_in_its_own_does_not(shared_data, tmp_path):
    archive = np.load(shared_data / "msrc12" / "msrc12_sequences.npz")
    offsets, positions = archive["offsets"], archive["positions"]  # one read of each
    picks = [k for k in range(0, len(offsets) - 1, 14) if offsets[k + 1] - offsets[k] > 1][:40]
    clips = [positions[offsets[k] : offsets[k + 1]].astype(float) for k in picks]
    assert len(clips) == 40
    joints = get_layout("kinect_v1").joints
    _, messages = _load(_write_npy(tmp_path / "right", clips), "kinect_v1")
    assert messages == []
    _, messages = _load(
        _write_npy(tmp_path / "wrong", _reorder(clips, joints, OTHER_ORDER)), "kinect_v1"
    )
    assert len(messages) == 1 and "head Head is above pelvis HipCenter" in messages[0]
    # read in a user's layout whose order is the data's: no warning
    v1 = get_layout("kinect_v1")
    theirs = Layout(
        "openni_order", OTHER_ORDER, root=v1.root, left_hip="HipLeft", right_hip="HipRight",
        left_shoulder="ShoulderLeft", right_shoulder="ShoulderRight", size_chain=v1.size_chain,
        landmarks=v1.landmarks,
    )  # fmt: skip
    _, messages = _load(tmp_path / "wrong", theirs)
    assert messages == []


def test_a_wrong_width_is_a_clear_error():
    with pytest.raises(ValueError, match=r"clip 0: shape \(5, 9\), expected \(n_frames, 60\)"):
        check_layout([np.zeros((5, 9))], "kinect_v1")
