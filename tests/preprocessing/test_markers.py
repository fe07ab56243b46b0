"""MarkerSet and the marker presets: positions, validation, the same markers on every skeleton."""

import pickle

import numpy as np
import pytest

from skmotion.datasets import humanoid_skeleton
from skmotion.io import read_amc, read_asf, read_bvh
from skmotion.kinematics import Skeleton, euler_to_matrix
from skmotion.preprocessing import (
    MARKER_NAMES,
    MARKER_PRESETS,
    MarkerSet,
    detect_marker_preset,
    marker_preset,
)
from skmotion.preprocessing._marker_presets import _PRESETS


def test_marker_positions_follow_the_link(skeleton, rng):
    markers = MarkerSet(
        [("a", "arm", (0.1, 0.2, -0.3)), ("b", "root", (0, 0, 0)), ("c", "hand", (0, 0.05, 0))]
    )
    channels = rng.normal(size=(4, skeleton.n_channels))
    fk = skeleton.forward_kinematics(channels)
    expected = fk.positions[:, 3] + fk.rotations[:, 3] @ np.array([0.1, 0.2, -0.3])
    positions = markers.positions(skeleton, channels)
    np.testing.assert_allclose(positions[:, 0], expected, atol=1e-12)
    np.testing.assert_allclose(positions[:, 1], fk.positions[:, 0], atol=1e-12)
    np.testing.assert_allclose(
        positions[:, 2], fk.positions[:, 4] + fk.rotations[:, 4] @ [0, 0.05, 0], atol=1e-12
    )


def test_marker_set_validates_and_round_trips(skeleton):
    with pytest.raises(ValueError, match="'a' appears twice"):
        MarkerSet([("a", "root", (0, 0, 0)), ("a", "arm", (0, 0, 0))])
    with pytest.raises(ValueError, match="3 finite numbers"):
        MarkerSet([("a", "root", (0, 0))])
    with pytest.raises(ValueError, match="at least one"):
        MarkerSet([])
    markers = MarkerSet([("a", "elbow", (0, 0, 0)), ("b", "root", (1, 2, 3))])
    with pytest.raises(ValueError, match="Marker 'a' is on joint 'elbow'"):
        markers.joint_indices(skeleton)
    assert pickle.loads(pickle.dumps(markers)) == markers
    assert hash(MarkerSet(list(markers))) == hash(markers)
    assert [m.name for m in markers] == ["a", "b"] and len(markers) == 2


def test_every_preset_places_every_marker():
    for preset, specs in _PRESETS.items():
        assert sorted(specs) == sorted(MARKER_NAMES), preset
    assert len(MARKER_NAMES) == 32 and len(set(MARKER_NAMES)) == 32


def test_humanoid_preset_by_hand():
    sk = humanoid_skeleton()
    markers = marker_preset(sk)
    assert detect_marker_preset(sk) == "humanoid"
    rest = markers.positions(sk, np.zeros((1, sk.n_channels)))[0] + np.array([0, 0.95, 0])
    at = dict(zip(markers.names, rest))
    np.testing.assert_allclose(at["left_knee"], [0.09, 0.48, 0.0], atol=1e-12)
    np.testing.assert_allclose(
        at["left_thigh"], [0.09, 0.69, 0.0], atol=1e-12
    )  # half way down the femur
    np.testing.assert_allclose(at["head_top"], [0.0, 1.75, 0.0], atol=1e-12)
    np.testing.assert_allclose(at["right_elbow"], [-0.19, 1.42 - 0.29, 0.0], atol=1e-12)
    # Offsets follow a scaled subject.
    big = marker_preset(humanoid_skeleton(1.3))
    np.testing.assert_allclose(big.offsets, 1.3 * markers.offsets, atol=1e-12)


def test_detection_and_errors():
    bare = Skeleton(["a", "b"], [-1, 0], [[0, 0, 0], [0, 1, 0]], [["Xrotation"], []])
    with pytest.raises(ValueError, match="No marker preset fits"):
        detect_marker_preset(bare)
    with pytest.raises(ValueError, match="needs joints"):
        marker_preset(bare, "humanoid")
    with pytest.raises(ValueError, match="Unknown marker preset"):
        marker_preset(humanoid_skeleton(), "vicon")
    assert set(MARKER_PRESETS) == set(_PRESETS) | {"matched"}  # matched: any humanoid


def _standing_heights(motion, frame, preset):
    """Marker heights above the lowest marker, over the head-top height, in one frame."""
    markers = marker_preset(motion.skeleton)
    assert detect_marker_preset(motion.skeleton) == preset
    positions = markers.positions(motion.skeleton, motion.channels[frame : frame + 1])[0]
    up = "xyz".index(motion.skeleton.up_axis)
    heights = positions[:, up] - positions[:, up].min()
    return markers, positions, heights / heights[markers.names.index("head_top")]


def test_same_marker_lands_on_the_same_body_part_on_every_skeleton(shared_data):
    """A wrong joint mapping is the classic silent error: compare four skeletons numerically."""
    sk = humanoid_skeleton()
    from skmotion.io import Motion

    cases = {
        "humanoid": (Motion(sk, np.zeros((1, sk.n_channels)), frame_rate=30), 0),
        "cmu_asf": (
            read_amc(
                shared_data / "cmu-asfamc/02/02_01.amc",
                read_asf(shared_data / "cmu-asfamc/02/02.asf"),
            ),
            0,
        ),
        "common_bvh": (read_bvh(shared_data / "bvh-samples/AV_8Walk_Meredith_HVHA_Rep1.bvh"), 0),
        "character_creator": (read_bvh(shared_data / "cmu-bvh/07/07_05.bvh"), 30),
    }
    heights = {}
    for preset, (motion, frame) in cases.items():
        markers, positions, heights[preset] = _standing_heights(motion, frame, preset)
        names = markers.names
        # Left markers are on the subject's left: +x in all four files (they face +z, y up),
        # and on the same side of the body as the left hip.
        across = positions[names.index("left_hip")] - positions[names.index("right_hip")]
        assert across[0] > 0, preset
        for part in ("clavicle", "shoulder", "elbow", "wrist", "hip", "thigh", "knee"):
            left, right = (
                positions[names.index(f"left_{part}")],
                positions[names.index(f"right_{part}")],
            )
            assert (left - right) @ across > 0, (preset, part)
        # Along the body the markers keep their anatomical order.
        h = dict(zip(names, heights[preset]))
        assert (
            h["head_top"]
            > h["head"]
            > h["neck"]
            > h["chest"]
            > h["spine"]
            > h["pelvis"]
            > h["left_knee"]
        )
        assert h["left_hip"] > h["left_thigh"] > h["left_knee"] > h["left_shin"] > h["left_ankle"]
        assert h["left_shoulder"] > h["left_elbow"] > h["left_wrist"]
    table = np.array(list(heights.values()))
    spread = table.max(axis=0) - table.min(axis=0)
    trunk = [
        MARKER_NAMES.index(n)
        for n in ("head", "neck", "chest", "spine", "pelvis", "left_hip", "left_knee")
    ]
    assert spread[trunk].max() < 0.08, dict(zip(np.array(MARKER_NAMES)[trunk], spread[trunk]))
    assert spread.max() < 0.15


def test_cmu_preset_on_a_constructed_asf_frame():
    """Bone axes do not move markers at rest: a CMU-named chain at zero angles."""
    names = ["root", "lhipjoint", "lfemur", "ltibia", "lfoot", "ltoes", "ltoes_end"]
    offsets = [[0, 0, 0], [0, 0, 0], [1, -1, 0], [0, -4, 0], [0, -4, 0], [0, -0.5, 1], [0, 0, 0.5]]
    axes = euler_to_matrix(np.array([[0.3, 0.2, 0.1]] * len(names)), "ZYX")
    sk = Skeleton(names, [-1, 0, 1, 2, 3, 4, 5], offsets, [["Xrotation"]] * 6 + [[]], axes=axes)
    markers = MarkerSet(
        [("knee", "ltibia", (0, 0, 0)), ("thigh", "lfemur", 0.5 * np.array(offsets[3]))]
    )
    positions = markers.positions(sk, np.zeros((1, sk.n_channels)))[0]
    np.testing.assert_allclose(positions, [[1, -5, 0], [1, -3, 0]], atol=1e-12)
