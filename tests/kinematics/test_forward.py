import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from skmotion.kinematics._forward_loops import marker_pass

from skmotion.kinematics import Skeleton, euler_to_matrix, forward_kinematics, matrix_to_euler

DEG = np.pi / 180


def _elementary(axis, angle):
    c, s = np.cos(angle), np.sin(angle)
    return {
        "X": np.array([[1, 0, 0], [0, c, -s], [0, s, c]]),
        "Y": np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]]),
        "Z": np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]]),
    }[axis]


def slow_forward_kinematics(skeleton, channels):
    """Frame by frame, joint by joint, with hand-written rotation matrices."""
    channels = np.atleast_2d(channels)
    n_frames, n_joints = len(channels), skeleton.n_joints
    positions = np.zeros((n_frames, n_joints, 3))
    rotations = np.zeros((n_frames, n_joints, 3, 3))
    for f in range(n_frames):
        col = 0
        for j in range(n_joints):
            values = {}
            for name in skeleton.channels[j]:
                values[name] = channels[f, col]
                col += 1
            local = np.eye(3)
            for axis in skeleton.rotation_orders[j]:
                local = local @ _elementary(axis, values.get(f"{axis}rotation", 0.0))
            if skeleton.axes is not None:
                local = skeleton.axes[j] @ local @ skeleton.axes[j].T
            translation = np.array(skeleton.offsets[j], dtype=float)
            for k, axis in enumerate("XYZ"):
                if f"{axis}position" in values:
                    translation[k] = values[f"{axis}position"]
            p = skeleton.parents[j]
            if p < 0:
                rotations[f, j], positions[f, j] = local, translation
            else:
                rotations[f, j] = rotations[f, p] @ local
                positions[f, j] = positions[f, p] + rotations[f, p] @ translation
    return positions, rotations


def _arm():
    return Skeleton(
        joints=["shoulder", "elbow", "hand"],
        parents=[-1, 0, 1],
        offsets=[[0, 0, 0], [0.3, 0, 0], [0.25, 0, 0]],
        channels=[["Zrotation"], ["Zrotation"], []],
    )


def test_two_link_arm_at_known_angles():
    t1, t2 = 30 * DEG, 45 * DEG
    fk = forward_kinematics(_arm(), [[t1, t2]])
    # elbow = L1 (cos t1, sin t1); hand = elbow + L2 (cos(t1 + t2), sin(t1 + t2))
    elbow = [0.3 * np.sqrt(3) / 2, 0.3 * 0.5, 0.0]
    hand = [elbow[0] + 0.25 * np.cos(75 * DEG), elbow[1] + 0.25 * np.sin(75 * DEG), 0.0]
    np.testing.assert_allclose(fk.positions[0], [[0, 0, 0], elbow, hand], atol=1e-12)
    np.testing.assert_allclose(fk.rotations[0, 2], _elementary("Z", 75 * DEG), atol=1e-12)


def test_two_link_arm_folded_back():
    fk = forward_kinematics(_arm(), [[90 * DEG, 180 * DEG]])
    np.testing.assert_allclose(fk.positions[0, 2], [0.0, 0.3 - 0.25, 0.0], atol=1e-12)


def test_root_turned_90_degrees_about_vertical():
    sk = Skeleton(
        joints=["hips", "head", "nose"],
        parents=[-1, 0, 1],
        offsets=[[0, 0, 0], [0, 0.7, 0], [0, 0, 0.1]],
        channels=[["Xposition", "Yposition", "Zposition", "Yrotation"], [], []],
    )
    fk = forward_kinematics(sk, [[2.0, 1.0, -3.0, 90 * DEG]])
    # Ry(90) takes +Z to +X: the nose now points along +X.
    np.testing.assert_allclose(
        fk.positions[0], [[2, 1, -3], [2, 1.7, -3], [2.1, 1.7, -3]], atol=1e-12
    )
    np.testing.assert_allclose(fk.rotations[0, 0], [[0, 0, 1], [0, 1, 0], [-1, 0, 0]], atol=1e-12)


def _two_axis(order):
    return Skeleton(
        joints=["base", "tip"],
        parents=[-1, 0],
        offsets=[[0, 0, 0], [1, 0, 0]],
        channels=[["Zrotation", "Xrotation"], []],
        rotation_orders=[order, "XYZ"],
    )


def test_rotation_order_matters_hand_computed():
    angles = [[90 * DEG, 90 * DEG]]  # Z then X channel values
    # Intrinsic ZXY: Rz(90) @ Rx(90) takes +X to +Y.
    np.testing.assert_allclose(
        forward_kinematics(_two_axis("ZXY"), angles).positions[0, 1], [0, 1, 0], atol=1e-12
    )
    # Intrinsic XZY: Rx(90) @ Rz(90) takes +X to +Z.
    np.testing.assert_allclose(
        forward_kinematics(_two_axis("XZY"), angles).positions[0, 1], [0, 0, 1], atol=1e-12
    )


def test_chain_with_mixed_rotation_orders_hand_computed():
    sk = Skeleton(
        joints=["a", "b", "c"],
        parents=[-1, 0, 1],
        offsets=[[0, 0, 0], [0, 0, 1], [1, 0, 0]],
        channels=[["Yrotation", "Xrotation"], ["Xrotation", "Zrotation"], []],
    )
    assert sk.rotation_orders == ("YXZ", "XZY", "XYZ")
    fk = forward_kinematics(sk, [[90 * DEG, 90 * DEG, 90 * DEG, 90 * DEG]])
    # a: Ry(90) Rx(90) = [[0,1,0],[0,0,-1],[-1,0,0]]; b at a @ (0,0,1) = (0,-1,0).
    # b: Rx(90) Rz(90) = [[0,-1,0],[0,0,-1],[1,0,0]]; world G_b = G_a @ L_b
    #    = [[0,0,-1],[-1,0,0],[0,1,0]]; c at b + G_b @ (1,0,0) = (0,-1,0) + (0,-1,0).
    np.testing.assert_allclose(fk.positions[0, 1], [0, -1, 0], atol=1e-12)
    np.testing.assert_allclose(fk.positions[0, 2], [0, -2, 0], atol=1e-12)
    np.testing.assert_allclose(fk.rotations[0, 1], [[0, 0, -1], [-1, 0, 0], [0, 1, 0]], atol=1e-12)


def test_bone_axis_conjugates_the_motion_rotation():
    # With C = Rz(90), a rotation about the bone's local X is one about world Y.
    axes = np.stack([np.eye(3), _elementary("Z", 90 * DEG), np.eye(3)])
    sk = Skeleton(
        joints=["root", "bone", "end"],
        parents=[-1, 0, 1],
        offsets=[[0, 0, 0], [0, 0, 0], [0, 0, 1]],
        channels=[[], ["Xrotation"], []],
        axes=axes,
    )
    fk = forward_kinematics(sk, [[90 * DEG]])
    np.testing.assert_allclose(fk.rotations[0, 1], _elementary("Y", 90 * DEG), atol=1e-12)
    np.testing.assert_allclose(fk.positions[0, 2], [1, 0, 0], atol=1e-12)


def test_position_channels_replace_offset_components():
    sk = Skeleton(
        ["root", "child"], [-1, 0], [[5, 6, 7], [0, 1, 0]], [["Yposition"], ["Xposition"]]
    )
    fk = forward_kinematics(sk, [[2.0, 3.0]])
    # root: (5, 2, 7) with Y replaced; child: root + (3, 1, 0) with X replaced.
    np.testing.assert_allclose(fk.positions[0], [[5, 2, 7], [8, 3, 7]])


def test_matches_slow_reference_on_random_poses(skeleton, rng):
    channels = rng.uniform(-np.pi, np.pi, size=(50, skeleton.n_channels))
    fk = forward_kinematics(skeleton, channels)
    positions, rotations = slow_forward_kinematics(skeleton, channels)
    np.testing.assert_allclose(fk.positions, positions, atol=1e-12)
    np.testing.assert_allclose(fk.rotations, rotations, atol=1e-12)


def test_matches_slow_reference_on_the_humanoid(rng):
    from skmotion.datasets import humanoid_skeleton

    sk = humanoid_skeleton(1.1)
    channels = rng.uniform(-np.pi, np.pi, size=(20, sk.n_channels))
    positions, rotations = slow_forward_kinematics(sk, channels)
    fk = sk.forward_kinematics(channels)
    np.testing.assert_allclose(fk.positions, positions, atol=1e-12)
    np.testing.assert_allclose(fk.rotations, rotations, atol=1e-12)


@given(
    st.permutations("XYZ").map("".join),
    st.lists(st.floats(-np.pi, np.pi), min_size=3, max_size=3),
    st.booleans(),
)
def test_random_orders_and_axes_match_reference(order, angles, with_axis):
    axes = None
    if with_axis:
        axes = np.stack([np.eye(3), euler_to_matrix([0.3, -0.7, 1.1], "XYZ"), np.eye(3)])
    sk = Skeleton(
        ["root", "joint", "end"],
        [-1, 0, 1],
        [[0, 0, 0], [0.1, 0.2, 0.3], [0.5, -0.1, 0.2]],
        [[], ["Xrotation", "Yrotation", "Zrotation"], []],
        rotation_orders=["XYZ", order, "XYZ"],
        axes=axes,
    )
    positions, rotations = slow_forward_kinematics(sk, [angles])
    fk = forward_kinematics(sk, [angles])
    np.testing.assert_allclose(fk.positions, positions, atol=1e-12)
    np.testing.assert_allclose(fk.rotations, rotations, atol=1e-12)


@given(st.integers(0, 2**32 - 1))
def test_any_channel_subset_tree_matches_reference(seed):
    """Random trees whose joints carry any subset of rotation and position channels,
    in any listed order, with random rotation orders and bone axes."""
    rng = np.random.default_rng(seed)
    n_joints = int(rng.integers(1, 7))
    parents = [-1] + [int(rng.integers(0, j)) for j in range(1, n_joints)]
    channels = []
    for _ in range(n_joints):
        names = [f"{a}rotation" for a in "XYZ"] + [f"{a}position" for a in "XYZ"]
        channels.append([names[i] for i in rng.permutation(6)[: int(rng.integers(0, 7))]])
    axes = None
    if rng.random() < 0.5:
        axes = euler_to_matrix(rng.uniform(-np.pi, np.pi, size=(n_joints, 3)), "XYZ")
    sk = Skeleton(
        [f"j{j}" for j in range(n_joints)],
        parents,
        rng.normal(size=(n_joints, 3)),
        channels,
        rotation_orders=["".join(rng.permutation(list("XYZ"))) for _ in range(n_joints)],
        axes=axes,
    )
    values = rng.uniform(-np.pi, np.pi, size=(4, sk.n_channels))
    positions, rotations = slow_forward_kinematics(sk, values)
    fk = forward_kinematics(sk, values)
    np.testing.assert_allclose(fk.positions, positions, atol=1e-12)
    np.testing.assert_allclose(fk.rotations, rotations, atol=1e-12)


def test_rotations_are_proper(skeleton, rng):
    fk = forward_kinematics(skeleton, rng.normal(size=(30, skeleton.n_channels)))
    gram = np.einsum("fjab,fjac->fjbc", fk.rotations, fk.rotations)
    np.testing.assert_allclose(gram, np.broadcast_to(np.eye(3), gram.shape), atol=1e-12)
    np.testing.assert_allclose(np.linalg.det(fk.rotations), 1.0, atol=1e-12)


def test_single_frame_as_1d_and_shape_errors(skeleton):
    fk = forward_kinematics(skeleton, np.zeros(skeleton.n_channels))
    assert fk.positions.shape == (1, 5, 3)
    with pytest.raises(ValueError, match=r"shape \(n_frames, 14\)"):
        forward_kinematics(skeleton, np.zeros((3, 13)))


@pytest.mark.parametrize("order", ["XYZ", "ZXY", "YZX", "ZYX"])
def test_euler_round_trip(order, rng):
    angles = rng.uniform(-1.2, 1.2, size=(10, 3))
    np.testing.assert_allclose(
        matrix_to_euler(euler_to_matrix(angles, order), order), angles, atol=1e-10
    )


@pytest.mark.parametrize("order", ["XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX"])
def test_euler_to_matrix_matches_scipy_intrinsic(order, rng):
    from scipy.spatial.transform import Rotation

    angles = rng.uniform(-np.pi, np.pi, size=(200, 3))
    np.testing.assert_allclose(
        euler_to_matrix(angles, order), Rotation.from_euler(order, angles).as_matrix(), atol=1e-14
    )


@given(
    n_frames=st.integers(0, 5),
    n_joints=st.integers(1, 4),
    joints=st.lists(st.integers(0, 3), max_size=6),
    seed=st.integers(0, 2**32 - 1),
)
def test_marker_pass_is_the_joint_pose_applied_to_each_offset(n_frames, n_joints, joints, seed):
    """``p_joint + R_joint @ offset`` per frame and point, against a loop of matrix products
    (NumPy's einsum, which it replaced in ``MarkerSet.positions``, may fuse its products
    into FMAs: the same to rounding, not always to the bit)."""
    rng = np.random.default_rng(seed)
    joints = np.array([j % n_joints for j in joints], dtype=np.intp)
    positions = rng.normal(size=(n_frames, n_joints, 3))
    rotations = rng.normal(size=(n_frames, n_joints, 3, 3))
    offsets = rng.normal(size=(len(joints), 3))
    out = np.empty((n_frames, len(joints), 3))
    marker_pass(positions, rotations, joints, offsets, out)
    for f in range(n_frames):
        for m, j in enumerate(joints):
            np.testing.assert_allclose(
                out[f, m], positions[f, j] + rotations[f, j] @ offsets[m], rtol=1e-13, atol=1e-13
            )


def test_marker_pass_names_a_joint_out_of_range():
    with pytest.raises(ValueError, match="point 1's joint 2 is not among the 2"):
        marker_pass(
            np.zeros((1, 2, 3)),
            np.zeros((1, 2, 3, 3)),
            np.array([0, 2]),
            np.zeros((2, 3)),
            np.empty((1, 2, 3)),
        )
