import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy.signal import butter, sosfreqz

from skmotion.preprocessing import LowPassFilter, filter_min_frames, lowpass_filter
from tests.clip_conformance import ClipCase, parametrize_with_clip_checks


def _clips():
    rng = np.random.default_rng(3)
    t = np.arange(80)
    X = [
        np.c_[np.sin(t / (5 + i)), np.cos(t / 7)] + 0.1 * rng.normal(size=(80, 2)) for i in range(6)
    ]
    return X, np.array([0, 1] * 3)


@parametrize_with_clip_checks([ClipCase(LowPassFilter(order=4), _clips)])
def test_conformance(check):
    check()


@pytest.mark.parametrize("order", [2, 6, 10])
@pytest.mark.parametrize("period", [4.0, 6.0, 12.0, 40.0])
def test_gain_on_a_sinusoid_is_the_squared_butterworth_response(order, period):
    # Forward-backward filtering applies |H|^2 and no phase: in the steady state a
    # sinusoid comes out scaled by |H(w)|^2 and not shifted.
    n = 2000
    t = np.arange(n)
    x = np.sin(2 * np.pi * t / period)
    y = lowpass_filter(x[:, None], order=order, cutoff=0.25)[:, 0]
    w = 2 * np.pi / period
    _, h = sosfreqz(butter(order, 0.25, output="sos"), worN=[w])
    middle = slice(500, 1500)
    expected = np.abs(h[0]) ** 2 * x[middle]
    np.testing.assert_allclose(y[middle], expected, atol=1e-6)


def test_constant_signals_pass_unchanged_and_ramps_inside_the_clip():
    # DC gain is exactly 1; a zero-phase response has no first-order term, so a
    # ramp passes too once the end transients have decayed.
    t = np.arange(200.0)
    clip = np.c_[np.full(200, 3.0), 0.5 * t - 2]
    out = lowpass_filter(clip)
    np.testing.assert_allclose(out[:, 0], 3.0, atol=1e-9)
    np.testing.assert_allclose(out[60:-60, 1], clip[60:-60, 1], atol=2e-5)


@given(st.integers(min_value=0, max_value=10_000))
def test_zero_phase_commutes_with_time_reversal(seed):
    # Equal away from the ends, where the start-up transients of the two passes differ.
    clip = np.random.default_rng(seed).normal(size=(120, 3))
    forward = lowpass_filter(clip, order=4, cutoff=0.3)
    backward = lowpass_filter(clip[::-1], order=4, cutoff=0.3)[::-1]
    np.testing.assert_allclose(forward[30:-30], backward[30:-30], atol=1e-5)


def test_noise_is_reduced_and_the_peak_does_not_move():
    rng = np.random.default_rng(0)
    t = np.arange(200)
    bump = np.exp(-0.5 * ((t - 90) / 12.0) ** 2)
    noisy = bump + 0.1 * rng.normal(size=200)
    out = lowpass_filter(noisy[:, None], order=10, cutoff=0.15)[:, 0]
    rms = lambda e: np.sqrt(np.mean(e**2))  # noqa: E731
    assert rms(out - bump) < 0.6 * rms(noisy - bump)
    assert abs(int(np.argmax(out)) - 90) <= 2


def test_short_clips_get_a_clear_error():
    needed = filter_min_frames(10, 0.25)
    assert needed == 34
    with pytest.raises(
        ValueError, match="33 frames; a zero-phase Butterworth filter of order 10 needs at least 34"
    ):
        lowpass_filter(np.zeros((33, 2)))
    X = [np.zeros((50, 2)), np.zeros((50, 2)), np.zeros((20, 2))]
    with pytest.raises(ValueError, match="clip 2 has 20 frame"):
        LowPassFilter().fit(X)
    assert LowPassFilter(order=2).__skmotion_tags__().min_frames == filter_min_frames(2, 0.25)


def test_float32_clips_stay_float32():
    X = [np.random.default_rng(0).normal(size=(50, 2)).astype(np.float32)]
    assert LowPassFilter(order=2).fit_transform(X)[0].dtype == np.float32
