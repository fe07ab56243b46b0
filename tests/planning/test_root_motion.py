"""Root velocity from body-frame markers, against rigid motions and walks of known velocity."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from skmotion.datasets import make_walks
from skmotion.io import as_motions
from skmotion.planning import (
    damped_ik,
    facing_pose,
    plan_axes,
    planar_step,
    rigid_root_velocity,
    skeleton_root_velocity,
)
from skmotion.preprocessing import VirtualMarkerTransform, marker_preset


@given(st.floats(-2, 2), st.floats(-2, 2), st.floats(-3, 3), st.integers(0, 1000))
def test_rigid_fit_is_exact_for_a_rigid_body(ux, uy, w, seed):
    p = np.random.default_rng(seed).normal(size=(1, 10, 3))
    v = np.stack([ux - w * p[..., 1], uy + w * p[..., 0], np.zeros_like(p[..., 0])], axis=-1)
    np.testing.assert_allclose(rigid_root_velocity(p, v, damping=0.0), [[ux, uy, w]], atol=1e-9)


def test_planar_step_matches_fine_integration():
    u = np.array([[1.2, -0.4, 0.9]])
    n = 20000
    x = y = h = 0.0
    for _ in range(n):  # Euler integration of the body twist with a tiny step
        x += (np.cos(h) * u[0, 0] - np.sin(h) * u[0, 1]) * 0.5 / n
        y += (np.sin(h) * u[0, 0] + np.cos(h) * u[0, 1]) * 0.5 / n
        h += u[0, 2] * 0.5 / n
    np.testing.assert_allclose(planar_step(u, 0.5)[0], [x, y, h], atol=1e-4)


@pytest.fixture(scope="module")
def turning_walks():
    data = make_walks(1, turn=0.6, random_state=0)
    motions = as_motions(data.clips, data.skeletons, data.frame_rate)
    markers = VirtualMarkerTransform(size_markers=None).fit_transform(motions)
    return data, [m.reshape(len(m), -1, 6) for m in markers]


def test_skeleton_jacobian_recovers_the_true_root_velocity(turning_walks):
    data, states = turning_walks
    for i, f in enumerate(states):
        sk = data.skeletons[i]
        ms = marker_preset(sk)
        every = f[2:-2:8]  # central differences are one-sided at the ends
        targets = every[..., :3] @ plan_axes("y").T
        q0 = facing_pose(
            sk,
            ms,
            targets,
            root=ms.names.index("pelvis"),
            left=ms.names.index("left_hip"),
            right=ms.names.index("right_hip"),
        )
        q, rms = damped_ik(sk, ms, targets, q0)
        assert rms.max() < 1e-4  # real poses: IK puts every marker back
        u = skeleton_root_velocity(sk, ms, q, every[..., 3:])
        truth = data.root_velocity[i][2:-2:8]
        # Central differences of a speed that varies within the stride: ~1% of the speed.
        assert np.abs(u[:, :2] - truth[:, :2]).mean() < 0.02, data.target_names[data.target[i]]
        assert np.abs(u[:, 2] - truth[:, 2]).mean() < 0.05


def test_rigid_fit_is_unbiased_over_a_stride(turning_walks):
    data, states = turning_walks
    for i, f in enumerate(states):
        u = rigid_root_velocity(f[..., :3], f[..., 3:])
        bias = (u - data.root_velocity[i])[2:-2].mean(axis=0)
        # The limbs' own motion stays in the residual frame by frame, but cancels over strides.
        assert np.abs(bias[:2]).max() < 0.02
        assert abs(bias[2]) < 0.06


def test_ik_reaches_two_link_targets_exactly():
    from skmotion.kinematics import Skeleton
    from skmotion.preprocessing import MarkerSet

    arm = Skeleton(
        ["a", "b", "c"],
        [-1, 0, 1],
        [[0, 0, 0], [1, 0, 0], [1, 0, 0]],
        [["Zrotation"], ["Zrotation"], []],
    )
    tip = MarkerSet([("tip", "c", (0, 0, 0))])
    angles = np.array([[0.3, 0.5], [1.0, -0.7], [-0.4, 1.2]])
    targets = tip.positions(arm, angles)
    q, rms = damped_ik(arm, tip, targets, angles + 0.2)
    assert rms.max() < 1e-6
    np.testing.assert_allclose(tip.positions(arm, q), targets, atol=1e-6)


def test_rigid_fit_on_a_real_cmu_walk(shared_data):
    """CMU subject 07 (Character Creator BVH): the truth is in the markers themselves.

    The body frame's origin lies below the pelvis marker, so the pelvis marker's
    horizontal velocity is the origin's; its turning rate is how fast the
    hip-to-hip line turns.
    """
    from skmotion.io import read_bvh

    motion = read_bvh(shared_data / "cmu-bvh" / "07" / "07_01.bvh")
    transformer = VirtualMarkerTransform(size_markers=None).fit([motion])
    f = transformer.transform([motion])[0].reshape(motion.n_frames, -1, 6)[5:-5]
    names = list(transformer.marker_names_)
    pelvis, left, right = (names.index(n) for n in ("pelvis", "left_hip", "right_hip"))
    width = f[:, left, 1] - f[:, right, 1]
    truth = np.column_stack(
        [f[:, pelvis, 3], f[:, pelvis, 4], -(f[:, left, 3] - f[:, right, 3]) / width]
    )
    u = rigid_root_velocity(f[..., :3], f[..., 3:])
    speed = np.hypot(truth[:, 0], truth[:, 1]).mean()
    # Over the clip (several strides) the limbs' motion cancels: the mean velocity is the root's.
    assert np.abs((u - truth)[:, :2].mean(axis=0)).max() < 0.05 * speed
    # Turning is the rigid fit's weak point on real walks (0.15 rad/s of bias here, from
    # arm and trunk rotation): the reason plan prefers a skeleton's Jacobian when it has one.
    assert abs((u - truth)[:, 2].mean()) < 0.2
