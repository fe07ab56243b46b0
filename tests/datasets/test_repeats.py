"""make_repeated_motions: repetitions of one motion, in the paper's representation."""

import numpy as np

from skmotion.datasets import humanoid_skeleton, make_repeated_motions


def test_layout_and_determinism():
    data = make_repeated_motions(
        n_motions_per_class=2, n_repeats=3, classes=["walk", "squat"], random_state=0
    )
    assert len(data.clips) == 12
    np.testing.assert_array_equal(data.target, np.repeat(np.arange(4), 3))
    np.testing.assert_array_equal(data.class_names[data.motion_class], ["walk"] * 6 + ["squat"] * 6)
    lengths = [len(c) for c in data.clips]
    assert min(lengths) >= 60 and max(lengths) <= 120  # 2-4 s at 30 Hz
    assert data.clips[0].shape[1] == 75 == len(data.feature_names)
    again = make_repeated_motions(
        n_motions_per_class=2, n_repeats=3, classes=["walk", "squat"], random_state=0
    )
    for a, b in zip(data.clips, again.clips):
        np.testing.assert_array_equal(a, b)


def test_positions_are_pelvis_relative():
    data = make_repeated_motions(
        n_motions_per_class=1, n_repeats=2, classes=["walk"], noise=0, random_state=0
    )
    spine = data.feature_names.index("Spine_x")
    # Whatever the root does, the spine sits straight above the pelvis at its bone
    # length (0.10 m at scale 1; subjects are scaled by 0.88-1.12).
    for clip in data.clips:
        np.testing.assert_allclose(
            clip[:, spine : spine + 3],
            np.tile(clip[0, spine : spine + 3], (len(clip), 1)),
            atol=1e-12,
        )
        x, y, z = clip[0, spine : spine + 3]
        assert abs(x) < 1e-12 and abs(z) < 1e-12 and 0.088 <= y <= 0.112


def test_angles_are_the_source_without_the_root():
    data = make_repeated_motions(
        n_motions_per_class=1, n_repeats=2, classes=["kick"], output="angles", random_state=0
    )
    assert data.clips[0].shape[1] == 60
    assert data.feature_names[0] == humanoid_skeleton().channel_names[6]
    # The repetitions are consecutive pieces of one performance.
    np.testing.assert_array_equal(np.vstack(data.clips)[: len(data.clips[0])], data.clips[0])
