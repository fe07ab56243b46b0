import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from skmotion.preprocessing import (
    energy_segments,
    movement_energy,
    zero_velocity_crossings,
    zvc_segments,
)


def minimum_jerk(n_frames):
    """Position profile of a minimum-jerk reach from 0 to 1 over ``n_frames`` steps."""
    s = np.linspace(0.0, 1.0, n_frames + 1)[1:]
    return 10 * s**3 - 15 * s**4 + 6 * s**5


def reaches(poses, durations, holds=None):
    """A clip of minimum-jerk reaches between rest poses; returns it and each reach's frames.

    Reach ``k`` runs from frame ``starts[k]`` (at pose k) to ``ends[k]`` (at pose k+1),
    both included. With ``holds``, pose k is held for ``holds[k]`` extra frames first.
    """
    holds = holds or [0] * len(durations)
    frames = [np.asarray(poses[0], dtype=float)[None]]
    starts, ends, n = [], [], 1
    for k, (d, h) in enumerate(zip(durations, holds)):
        here = frames[-1][-1]
        frames.append(np.repeat(here[None], h, axis=0))
        n += h
        starts.append(n - 1)
        frames.append(here + (np.asarray(poses[k + 1]) - here) * minimum_jerk(d)[:, None])
        n += d
        ends.append(n - 1)
    return np.concatenate(frames), np.array(starts), np.array(ends)


# Every channel reverses at every via-point: out and back.
ZIGZAG = [
    [0, 0, 0, 0],
    [1.0, 0.5, -0.5, 0.8],
    [0.2, -0.3, 0.4, 0.1],
    [1.2, 0.6, -0.2, 1.0],
    [0.0, 0.1, 0.3, 0.2],
]


def test_movement_energy_by_hand():
    clip = np.array([[0.0, 0.0], [1.0, 2.0], [4.0, 2.0]])
    # central differences inside, one-sided at the ends: v = [[1, 2], [2, 1], [3, 0]]
    np.testing.assert_allclose(movement_energy(clip, frame_rate=2.0), 4 * np.array([5.0, 5.0, 9.0]))


def test_zero_velocity_crossings_are_turning_points():
    t = np.linspace(0, 4 * np.pi, 81)
    frames, channels = zero_velocity_crossings(np.c_[np.sin(t), np.cos(t)])
    np.testing.assert_array_equal(frames, [10, 20, 30, 40, 50, 60, 70])
    np.testing.assert_array_equal(channels, [0, 1, 0, 1, 0, 1, 0])


def test_a_stop_without_reversal_is_no_crossing_and_flat_tops_cross_in_the_middle():
    ramp_hold_ramp = np.r_[np.linspace(0, 1, 10), np.ones(5), np.linspace(1, 2, 10)]
    up_hold_down = np.r_[np.linspace(0, 1, 10), np.ones(5), np.linspace(1, 0, 10)]
    frames, channels = zero_velocity_crossings(np.c_[ramp_hold_ramp, up_hold_down])
    assert channels.tolist() == [1]
    assert frames.tolist() == [12]  # the flat top spans frames 9..15 (values 1.0)


def test_small_turns_below_the_movement_threshold_are_ignored():
    t = np.arange(120) / 30
    clip = np.c_[np.sin(np.pi * t) + 0.01 * np.random.default_rng(0).normal(size=120)]
    assert len(zero_velocity_crossings(clip)[0]) > 4
    frames, _ = zero_velocity_crossings(clip, min_movement=0.1)
    assert np.abs(frames - [15, 45, 75, 105]).max() <= 1


def test_zvc_boundaries_are_the_via_points_of_reaches():
    clip, starts, ends = reaches(ZIGZAG, [30, 25, 35, 28])
    segments = zvc_segments(clip, frame_rate=30)
    # The first reach starts and the last ends at the clip's ends, where no
    # crossing can be seen: SEG-1 keeps what lies between via-points.
    np.testing.assert_array_equal(segments, np.c_[starts[1:], ends[1:] + 1][:-1])
    np.testing.assert_array_equal(segments[:, 0], ends[:-2])


def test_energy_segments_are_the_reaches():
    clip, starts, ends = reaches(ZIGZAG, [30, 25, 35, 28])
    np.testing.assert_array_equal(energy_segments(clip), np.c_[starts, ends + 1])


def test_energy_segments_skip_held_poses():
    poses = [[0, 0, 0], [0.8, 0.2, -0.4], [1.0, 0.9, 0.0], [0.1, 0.3, 0.5]]
    clip, starts, ends = reaches(poses, [30, 24, 36], holds=[10, 12, 15])
    segments = energy_segments(clip)
    assert len(segments) == 3
    # Central differences spread a stop over one frame on each side.
    assert np.abs(segments[:, 0] - starts).max() <= 1
    assert np.abs(segments[:, 1] - 1 - ends).max() <= 1
    held = np.ones(len(clip), dtype=bool)
    for a, b in segments:
        held[a:b] = False
    assert held[: starts[0] - 1].all() and held[ends[0] + 2 : starts[1] - 1].all()


@given(scale=st.floats(0.01, 100.0), frame_rate=st.floats(10.0, 500.0))
def test_automatic_energy_threshold_ignores_units_and_frame_rate(scale, frame_rate):
    clip, _, _ = reaches(ZIGZAG, [30, 25, 35, 28])
    np.testing.assert_array_equal(energy_segments(scale * clip), energy_segments(clip))
    seconds = movement_energy(clip, frame_rate=frame_rate)
    threshold = 0.1 * seconds.mean()
    np.testing.assert_array_equal(
        energy_segments(clip, threshold=threshold, frame_rate=frame_rate), energy_segments(clip)
    )


def test_an_explicit_energy_threshold_needs_the_frame_rate():
    with pytest.raises(ValueError, match="needs frame_rate"):
        energy_segments(np.zeros((10, 2)), threshold=1.0)


def test_energy_threshold_controls_what_counts_as_movement():
    # A big reach then a small one: a high threshold sees only the big one.
    clip, starts, ends = reaches([[0.0], [2.0], [1.2]], [30, 30], holds=[5, 5])
    assert len(energy_segments(clip, ratio=0.1)) == 2
    z = movement_energy(clip, frame_rate=30)
    small_peak = z[starts[1] : ends[1] + 1].max()
    segments = energy_segments(clip, threshold=1.01 * small_peak, frame_rate=30)
    assert len(segments) == 1 and segments[0, 0] <= starts[0] + 1 and segments[0, 1] >= ends[0]


def test_min_movement_drops_small_segments():
    clip, _, _ = reaches([[0.0], [2.0], [1.4], [3.0]], [30, 30, 30], holds=[5, 5, 5])
    assert len(energy_segments(clip)) == 3
    kept = energy_segments(clip, min_movement=0.8)
    assert len(kept) == 2
    assert all(np.ptp(clip[a:b]) > 0.8 for a, b in kept)


def test_zvc_needs_channels_to_cross_together():
    t = np.arange(150) / 30
    one = np.cos(np.pi * t)
    clip = np.c_[one, np.linspace(0, 1, 150)]  # only channel 0 turns
    assert len(zvc_segments(clip, frame_rate=30)) == 0
    assert len(zvc_segments(clip, frame_rate=30, min_channels=1)) == 3


@pytest.mark.parametrize(
    "lag, window, frame_rate, expected",
    [
        (6, 0.3, 30, 4),  # 0.2 s apart: together
        (6, 0.1, 30, 0),  # the window is shorter than the lag
        (6, 0.3, 10, 0),  # at 10 Hz six frames are 0.6 s
        (12, 0.3, 30, 0),  # 0.4 s apart
    ],
)
def test_zvc_window_is_in_seconds(lag, window, frame_rate, expected):
    t = np.arange(180) / 30
    clip = np.c_[np.cos(np.pi * t), np.cos(np.pi * (t - lag / 30))]
    segments = zvc_segments(clip, frame_rate=frame_rate, window=window)
    assert len(segments) == expected
    if expected:
        # A boundary is the mean frame of the crossings it groups.
        np.testing.assert_array_equal(segments[:, 0], np.array([30, 60, 90, 120]) + lag // 2)


def test_segments_are_slices_sharing_their_boundaries():
    clip, _, _ = reaches(ZIGZAG, [30, 25, 35, 28])
    for segments in (energy_segments(clip), zvc_segments(clip, frame_rate=30)):
        assert segments.dtype.kind == "i" and segments.shape[1] == 2
        assert (segments[1:, 0] == segments[:-1, 1] - 1).all()
