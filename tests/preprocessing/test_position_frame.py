"""position_frame_features (the compiled loops) against a brute-force per-frame reference."""

import numpy as np
import pytest

from skmotion.kinematics import body_size
from skmotion.preprocessing import VirtualMarkerTransform, get_layout
from skmotion.preprocessing._position_frame import position_frame_features

UNIT = {"x": [1.0, 0, 0], "y": [0, 1.0, 0], "z": [0, 0, 1.0]}


def _reference_3d(points, root, lefts, rights, chain, up, floor, rate, outputs):
    """Frame by frame from the definition: left = horizontal part of the summed left-minus-
    right vectors, forward = left x up, origin on the floor below the mean of the root."""
    u = np.array(UNIT[up[-1]]) * (-1.0 if up.startswith("-") else 1.0)
    size = body_size(points, chain)
    level = np.min(points @ u) if floor == "lowest" else floor * u.sum()
    velocity = np.gradient(points, axis=0) * rate
    rows = []
    for p, v in zip(points, velocity):
        lateral = sum(p[a] - p[b] for a, b in zip(lefts, rights))
        left = lateral - (lateral @ u) * u
        left /= np.linalg.norm(left)
        forward = np.cross(left, u)
        basis = np.stack([forward, left, u])  # rows: the body frame's axes in the input
        origin = p[list(root)].mean(axis=0)
        position = (p[outputs] - origin) @ basis.T
        position[:, 2] = p[outputs] @ u - level
        rows.append(np.hstack([position, v[outputs] @ basis.T]) / size)
    return np.stack(rows)


def _reference_2d(points, root, lefts, rights, chain, up, floor, rate, outputs):
    """Image plane: horizontal offset from the root, signed so the median left-minus-right
    offset is positive; height above the lowest point (rows grow down when up='-y')."""
    size = body_size(points, chain)
    lateral = sum(points[:, a, 0] - points[:, b, 0] for a, b in zip(lefts, rights))
    sign = -1.0 if np.median(lateral) < 0 else 1.0
    height = points[..., 1] * (-1.0 if up == "-y" else 1.0)
    level = height.min() if floor == "lowest" else floor * (-1.0 if up == "-y" else 1.0)
    horizontal = sign * (points[..., 0] - points[:, list(root), 0].mean(axis=1)[:, None])
    velocity = np.gradient(np.stack([sign * points[..., 0], height], axis=-1), axis=0) * rate
    position = np.stack([horizontal, height - level], axis=-1)
    return np.concatenate([position, velocity], axis=-1)[:, outputs] / size


def _walk(n_frames, dim, seed):
    """A body wandering and turning: random-walk points around a moving root."""
    rng = np.random.default_rng(seed)
    return np.cumsum(rng.normal(size=(n_frames, 7, dim)), axis=0) + rng.normal(size=(7, dim)) * 5


@pytest.mark.parametrize("up", ["y", "-y", "z", "-z", "x", "-x"])
@pytest.mark.parametrize("floor", ["lowest", 0.7])
@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_3d_matches_the_per_frame_definition(up, floor, dtype):
    points = _walk(60, 3, seed=len(up)).astype(dtype)
    roles = dict(root=(0, 1), lefts=(2, 3), rights=(4, 5), outputs=[6, 1, 3, 3])
    reference = _reference_3d(
        points.astype(np.float64), chain=(6, 0, 2), up=up, floor=floor, rate=30.0, **roles
    )
    out = position_frame_features(
        points, size_chain=(6, 0, 2), up=up, floor=floor, frame_rate=30.0, chunk=16, **roles
    )
    rtol = 1e-12 if dtype == np.float64 else 1e-5
    np.testing.assert_allclose(out, reference.reshape(len(points), -1), rtol=rtol, atol=rtol)
    bare = position_frame_features(
        points, size_chain=(6, 0, 2), up=up, floor=floor, velocities=False, **roles
    )
    np.testing.assert_array_equal(bare, out.reshape(len(points), -1, 6)[..., :3].reshape(60, -1))


@pytest.mark.parametrize("up", ["y", "-y"])
@pytest.mark.parametrize("mirror", [False, True])
@pytest.mark.parametrize("floor", ["lowest", 0.5])
def test_2d_matches_the_per_frame_definition(up, mirror, floor):
    points = _walk(50, 2, seed=3)
    points[:, 2:4, 0] += -20.0 if mirror else 20.0  # the left joints on one side of the right
    roles = dict(root=(0,), lefts=(2, 3), rights=(4, 5), outputs=[6, 0, 2])
    reference = _reference_2d(points, chain=(6, 0, 2), up=up, floor=floor, rate=25.0, **roles)
    out = position_frame_features(
        points, size_chain=(6, 0, 2), up=up, floor=floor, frame_rate=25.0, chunk=7, **roles
    )
    np.testing.assert_allclose(out, reference.reshape(len(points), -1), rtol=1e-12, atol=1e-12)


def test_the_transform_of_a_long_kinect_clip_matches_the_definition():
    """Through VirtualMarkerTransform, across chunk boundaries (4096 frames) of a real layout."""
    layout = get_layout("kinect_v2")
    rng = np.random.default_rng(0)
    base = _walk(9000, 3, seed=1)[:, rng.integers(7, size=layout.n_joints)]
    base += rng.normal(size=base.shape) * 0.3  # each joint its own path
    vmt = VirtualMarkerTransform(layout="kinect_v2", markers="all", frame_rate=30.0)
    out = vmt.fit_transform([base.reshape(len(base), -1)])[0]
    roles = dict(root=vmt.root_index_, lefts=vmt.facing_indices_[0])
    roles.update(rights=vmt.facing_indices_[1], chain=vmt.size_indices_)
    reference = _reference_3d(
        base, up=layout.up, floor="lowest", rate=30.0, outputs=np.arange(25), **roles
    )
    np.testing.assert_allclose(out, reference.reshape(len(base), -1), rtol=1e-11, atol=1e-11)


def test_bad_indices_and_missing_rate_are_clear_errors():
    points = _walk(10, 3, seed=0)
    roles = dict(root=(0,), lefts=(2,), rights=(4,))
    with pytest.raises(IndexError, match=r"outputs \[7\] out of range for 7 points"):
        position_frame_features(points, outputs=[7], velocities=False, **roles)
    with pytest.raises(IndexError, match=r"size_chain \[0, -1\] out of range"):
        position_frame_features(points, size_chain=(0, -1), velocities=False, **roles)
    with pytest.raises(ValueError, match="lefts names no point"):
        position_frame_features(points, root=(0,), lefts=(), rights=(), velocities=False)
    with pytest.raises(ValueError, match="velocities need frame_rate"):
        position_frame_features(points, **roles)
    with pytest.raises(ValueError, match="points need 2 or 3 coordinates each; got 4"):
        position_frame_features(np.zeros((10, 7, 4)), velocities=False, **roles)


def test_read_only_strided_and_integer_inputs_give_the_same_features():
    points = _walk(40, 3, seed=2)
    kw = dict(root=(0,), lefts=(2,), rights=(4,), size_chain=(6, 0), frame_rate=10.0)
    expected = position_frame_features(points, **kw)
    frozen = points.copy()
    frozen.flags.writeable = False
    np.testing.assert_array_equal(position_frame_features(frozen, **kw), expected)
    strided = np.zeros((40, 7, 6))
    strided[..., ::2] = points
    np.testing.assert_array_equal(position_frame_features(strided[..., ::2], **kw), expected)
    whole = np.round(points * 10).astype(np.int64)
    np.testing.assert_array_equal(
        position_frame_features(whole, **kw), position_frame_features(whole * 1.0, **kw)
    )
