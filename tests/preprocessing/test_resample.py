import numpy as np
import pandas as pd
import pytest
from hypothesis import given
from hypothesis import strategies as st

from skmotion.preprocessing import FlattenClips, ResampleClips, resample_clip
from tests.clip_conformance import ClipCase, parametrize_with_clip_checks


def _ramps(lengths, n_channels=3):
    # Linear in time: any linear resampling must reproduce it exactly.
    return [np.outer(np.linspace(0, 1, n), np.arange(1, n_channels + 1)) + 5 for n in lengths]


def test_fixed_length_is_exact_on_linear_signals():
    clips = _ramps([7, 30, 101])
    out = ResampleClips(n_frames=11).fit_transform(clips)
    expected = np.outer(np.linspace(0, 1, 11), [1, 2, 3]) + 5
    for clip in out:
        np.testing.assert_allclose(clip, expected, atol=1e-12)


def test_cubic_is_exact_on_cubic_polynomials():
    t = np.arange(20, dtype=float)
    clip = np.c_[t**3 - 2 * t, 0.5 * t**2]
    out = ResampleClips(n_frames=39, kind="cubic").fit_transform([clip])[0]
    s = np.linspace(0, 19, 39)
    np.testing.assert_allclose(out, np.c_[s**3 - 2 * s, 0.5 * s**2], rtol=1e-9, atol=1e-9)


def test_frame_rate_conversion_keeps_times():
    rate, target = 120.0, 100.0
    t = np.arange(121) / rate  # one second
    clip = np.c_[np.sin(t), 3 * t]
    out = ResampleClips(frame_rate=rate, target_frame_rate=target).fit_transform([clip])[0]
    s = np.arange(101) / target
    assert len(out) == 101
    np.testing.assert_allclose(out[:, 1], 3 * s, atol=1e-12)
    np.testing.assert_allclose(out[:, 0], np.sin(s), atol=2e-5)


@given(st.integers(2, 300), st.floats(10, 240), st.floats(10, 240))
def test_frame_rate_output_length_property(n, rate, target):
    out = ResampleClips(frame_rate=rate, target_frame_rate=target).fit_transform(
        [np.zeros((n, 1))]
    )[0]
    duration = (n - 1) / rate
    # The last output frame lies within the clip and one more would not.
    assert (len(out) - 1) / target <= duration + 1e-9
    assert len(out) / target > duration - 1e-9


def test_single_frame_clip_is_repeated():
    out = ResampleClips(n_frames=4).fit_transform([np.array([[1.0, 2.0]])])[0]
    np.testing.assert_array_equal(out, [[1, 2]] * 4)
    np.testing.assert_array_equal(resample_clip(np.ones((1, 2)), np.array([0.0])), [[1, 1]])


@pytest.mark.parametrize(
    "params, match",
    [
        (dict(), "exactly one of n_frames"),
        (dict(n_frames=5, frame_rate=30, target_frame_rate=10), "exactly one of n_frames"),
        (dict(target_frame_rate=10), "needs the input's frame_rate"),
        (dict(n_frames=0), "n_frames"),
        (dict(n_frames=5, kind="quadratic"), "kind"),
    ],
)
def test_invalid_parameters(params, match):
    with pytest.raises(ValueError, match=match):
        ResampleClips(**params).fit([np.zeros((4, 2))])


def test_flatten_is_frame_major_and_named():
    clips = [np.arange(6.0).reshape(3, 2), np.arange(6.0, 12).reshape(3, 2)]
    df = pd.concat({k: pd.DataFrame(c, columns=["a", "b"]) for k, c in enumerate(clips)})
    flat = FlattenClips().fit(df)
    np.testing.assert_array_equal(flat.transform(clips)[1], [6, 7, 8, 9, 10, 11])
    assert flat.get_feature_names_out().tolist() == ["a@0", "b@0", "a@1", "b@1", "a@2", "b@2"]


def test_flatten_rejects_other_lengths():
    flat = FlattenClips().fit([np.zeros((3, 2))] * 2)
    with pytest.raises(ValueError, match="clip 1 has 4 frames, but fit has 3.*ResampleClips"):
        flat.transform([np.zeros((3, 2)), np.zeros((4, 2))])
    with pytest.raises(ValueError, match="clip 2 has 5 frames, but the first clip has 3"):
        FlattenClips().fit([np.zeros((3, 2))] * 2 + [np.zeros((5, 2))])


def _labelled(lengths):
    rng = np.random.default_rng(1)
    X = [rng.normal(size=(n, 3)) + (k % 2) for k, n in enumerate(lengths)]
    return X, np.array([k % 2 for k in range(len(lengths))])


@parametrize_with_clip_checks(
    [
        ClipCase(
            ResampleClips(n_frames=6),
            lambda: _labelled([9, 12, 15, 10, 8, 20, 11, 14, 13]),
            param_grid={"n_frames": [4, 6]},
        ),
        ClipCase(
            ResampleClips(frame_rate=30, target_frame_rate=20, kind="cubic"),
            lambda: _labelled([9, 12, 15, 10, 8, 20, 11, 14, 13]),
            param_grid={"kind": ["linear", "cubic"]},
        ),
        ClipCase(FlattenClips(), lambda: _labelled([7] * 9)),
    ]
)
def test_conformance(check):
    check()
