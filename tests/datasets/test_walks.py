"""make_walks: its stated root velocity is the one of its clips."""

import numpy as np
import pytest

from skmotion.datasets import make_walks


def test_root_velocity_is_the_clips_own():
    data = make_walks(1, turn=0.5, random_state=3)
    sk = data.skeleton
    for clip, truth in zip(data.clips, data.root_velocity):
        x, z = (
            clip[:, sk.channel_index("Hips", "Xposition")],
            clip[:, sk.channel_index("Hips", "Zposition")],
        )
        yaw = clip[:, sk.channel_index("Hips", "Yrotation")]
        vx, vz = np.diff(x) * data.frame_rate, np.diff(z) * data.frame_rate
        # Facing (sin yaw, cos yaw) and left (cos yaw, -sin yaw) in the world's (X, Z).
        forward = vx * np.sin(yaw[:-1]) + vz * np.cos(yaw[:-1])
        left = vx * np.cos(yaw[:-1]) - vz * np.sin(yaw[:-1])
        np.testing.assert_allclose(forward, truth[:-1, 0], atol=1e-9)
        np.testing.assert_allclose(left, truth[:-1, 1], atol=1e-9)
        np.testing.assert_allclose(np.diff(yaw) * data.frame_rate, truth[:-1, 2], atol=1e-9)


def test_directions_and_seed():
    a, b = (
        make_walks(1, directions=["backward"], random_state=0),
        make_walks(1, directions=["backward"], random_state=0),
    )
    np.testing.assert_array_equal(a.clips[0], b.clips[0])
    assert a.root_velocity[0][:, 0].max() < 0
    with pytest.raises(ValueError, match="directions"):
        make_walks(1, directions=["up"])
