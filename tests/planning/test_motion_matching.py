"""follow_path: a zig-zag followed on the built-in walks and on CMU walks, blended switches, BVH."""

import dataclasses
from collections import Counter

import numpy as np
import pytest

from skmotion.datasets import make_walks
from skmotion.io import Motion, as_motions, read_bvh, write_bvh
from skmotion.neighbors import MotionMatcher
from skmotion.planning import follow_path, path_distance, path_from_velocities

#: Four metres forward in four legs, 0.25 m to either side.
ZIGZAG = np.array([[0.0, 0.0], [1.0, 0.25], [2.0, -0.25], [3.0, 0.25], [4.0, 0.0]])


@pytest.fixture(scope="module")
def database():
    data = make_walks(8, turn=1.5, random_state=0)
    takes = as_motions(data.clips, data.skeleton, data.frame_rate)
    return takes, MotionMatcher().fit(takes)


def test_follows_the_zigzag_on_the_walks(database, tmp_path):
    takes, matcher = database
    result = follow_path(matcher, takes, ZIGZAG)
    assert result.root_error.max() <= 0.2
    assert np.hypot(*(result.root[-1, :2] - ZIGZAG[-1])) <= 0.2
    # The root error is the distance to the path of the motion's own root, on the floor.
    hips = result.motion.forward_kinematics().positions[:, 0]
    np.testing.assert_allclose(path_distance(hips[:, [2, 0]], ZIGZAG), result.root_error, atol=0.05)
    # Inertialisation removes most of the jump a plain switch makes.
    assert len(result.switches) >= 3
    assert result.jump.mean() < 0.6 * result.jump_unblended.mean()
    path = tmp_path / "zigzag.bvh"
    write_bvh(result.motion, path)
    back = read_bvh(path)
    np.testing.assert_allclose(back.channels, result.motion.channels, atol=1e-4)


def test_no_blend_is_the_baseline(database):
    takes, matcher = database
    result = follow_path(matcher, takes, ZIGZAG, blend_halflife=0)
    np.testing.assert_array_equal(result.jump, result.jump_unblended)


def test_without_adjustment_the_database_alone_moves_the_root(database):
    takes, matcher = database
    result = follow_path(matcher, takes, ZIGZAG, adjust_halflife=None)
    assert result.adjustment == 0.0
    # Root steps are the database's own: each frame's travel is a database frame's travel.
    steps = np.hypot(*np.diff(result.root[:, :2], axis=0).T)
    source_steps = [
        np.hypot(*(matcher.origin_[t][f + 1] - matcher.origin_[t][f]))
        for t, f in result.source[:-1]
    ]
    np.testing.assert_allclose(steps, source_steps, atol=1e-12)


def test_follows_the_zigzag_on_cmu_walks(shared_data):
    files = sorted((shared_data / "cmu-bvh" / "07").glob("*.bvh"))
    if not files:
        pytest.skip("cmu-bvh/07 absent")
    motions = [read_bvh(f) for f in files]
    # One skeleton for the database: the channel layout most files share.
    common = Counter(m.n_channels for m in motions).most_common(1)[0][0]
    motions = [m for m in motions if m.n_channels == common]
    # The files state no unit; the body is about 172 units tall: centimetres.
    skeleton = dataclasses.replace(motions[0].skeleton, meters_per_unit=0.01, units="cm")
    takes = [Motion(skeleton, m.channels, frame_rate=m.frame_rate) for m in motions]
    matcher = MotionMatcher().fit(takes)
    result = follow_path(matcher, takes, ZIGZAG)
    assert result.root_error.max() <= 0.2
    assert result.jump.mean() < 0.5 * result.jump_unblended.mean()


def test_a_velocity_command_is_a_path(database):
    takes, matcher = database
    # 1.2 m/s forward for 1.5 s, then 1.2 m/s turning left at 0.5 rad/s for 1.5 s.
    heading = np.concatenate([np.zeros(45), 0.5 * np.arange(45) / 30.0])
    command = 1.2 * np.column_stack([np.cos(heading), np.sin(heading)])
    path = path_from_velocities(command, 30.0)
    np.testing.assert_allclose(path[45], [1.8, 0.0])
    result = follow_path(matcher, takes, path)
    assert result.root_error.max() <= 0.2


def test_bad_input_is_named(database):
    takes, matcher = database
    with pytest.raises(ValueError, match="two distinct points"):
        follow_path(matcher, takes, [[0.0, 0.0], [0.0, 0.0]])
    with pytest.raises(ValueError, match="fitted on"):
        follow_path(matcher, takes[:3], ZIGZAG)
    with pytest.raises(ValueError, match="finite"):
        path_from_velocities(np.array([[1.0, np.nan]]), 30.0)
