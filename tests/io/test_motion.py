import pickle

import numpy as np
import pytest

from skmotion.datasets import humanoid_skeleton, make_motions
from skmotion.io import Motion, as_motions
from skmotion.utils import check_clips


def test_motion_is_a_clip(skeleton, rng):
    channels = rng.normal(size=(12, skeleton.n_channels))
    motion = Motion(skeleton, channels, frame_rate=50, source="x.bvh")
    assert motion.n_frames == 12 and motion.duration == pytest.approx(12 / 50)
    assert motion.channel_names == skeleton.channel_names
    np.testing.assert_array_equal(np.asarray(motion), channels)
    assert np.asarray(motion, dtype=np.float32).dtype == np.float32
    clips = check_clips([motion, Motion(skeleton, channels[:5], frame_rate=50)])
    assert [len(c) for c in clips] == [12, 5] and clips.n_channels == skeleton.n_channels
    restored = pickle.loads(pickle.dumps(motion))
    np.testing.assert_array_equal(restored.channels, channels)
    assert restored.skeleton == skeleton and restored.source == "x.bvh"
    np.testing.assert_allclose(
        motion.forward_kinematics().positions, skeleton.forward_kinematics(channels).positions
    )


def test_motion_validates(skeleton):
    with pytest.raises(ValueError, match=r"shape \(n_frames, 14\)"):
        Motion(skeleton, np.zeros((3, 5)), frame_rate=30)
    with pytest.raises(ValueError, match="frame_rate"):
        Motion(skeleton, np.zeros((3, 14)), frame_rate=0)
    with pytest.raises(TypeError, match="Skeleton"):
        Motion("skeleton", np.zeros((3, 14)), frame_rate=30)


def test_as_motions_gives_each_clip_its_skeleton():
    data = make_motions(n_clips_per_class=4, classes=["wave"], random_state=1)
    motions = as_motions(data.clips, data.skeletons, data.frame_rate)
    assert [m.skeleton for m in motions] == data.skeletons
    assert len({m.skeleton for m in motions}) == 4  # four subjects, four sizes
    single = as_motions(data.clips, humanoid_skeleton(), 30.0, sources=["a", "b", "c", "d"])
    assert single[2].source == "c" and single[0].skeleton == humanoid_skeleton()
    with pytest.raises(ValueError, match="2 skeletons for 4 clips"):
        as_motions(data.clips, data.skeletons[:2], 30.0)
    with pytest.raises(ValueError, match="clip 1"):
        as_motions([data.clips[0], data.clips[1][:, :5]], humanoid_skeleton(), 30.0)
