"""Root velocity from body-frame markers, against rigid motions and synthetic walks of known velocity."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from skmotion.datasets import make_walks
from skmotion.io import as_motions
from skmotion.planning import (
    damped_ik, facing_pose, planar_step, plan_axes, rigid_root_velocity, skeleton_root_velocity,
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
        q0 = facing_pose(sk, ms, targets, root=ms.names.index("pelvis"), left=ms.names.index("left_hip"),
                         right=ms.names.index("right_hip"))
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

    arm = Skeleton(["a", "b", "c"], [-1, 0, 1], [[0, 0, 0], [1, 0, 0], [1, 0, 0]], [["Zrotation"], ["Zrotation"], []])
    tip = MarkerSet([("tip", "c", (0, 0, 0))])
    angles = np.array([[0.3, 0.5], [1.0, -0.7], [-0.4, 1.2]])
    targets = tip.positions(arm, angles)
    q, rms = damped_ik(arm, tip, targets, angles + 0.2)
    assert rms.max() < 1e-6
    np.testing.assert_allclose(tip.positions(arm, q), targets, atol=1e-6)
