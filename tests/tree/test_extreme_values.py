"""Values too large for the motion tree's arithmetic: a finite, correct answer up to the
limits of ``skmotion/tree/_magnitude.py``, a ValueError naming clip and channel past
them, never a silent NaN, infinity or rounding noise (issue 29)."""

import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from skmotion.datasets import make_motions
from skmotion.tree import MotionTreeEncoder, MotionTreeHMM
from skmotion.tree._magnitude import (
    SCORE_LIMIT,
    check_magnitude,
    check_stacked_magnitude,
    overflow_limit,
)
from skmotion.utils import stack_clips


@pytest.fixture(scope="module")
def data():
    motions = make_motions(n_clips_per_class=4, random_state=0)
    return [c[:, 6:] for c in motions.clips], motions.target_names[motions.target]


@pytest.fixture(scope="module")
def hmm(data):
    X, y = data
    return MotionTreeHMM(max_depth=4, split="median").fit(X, y)


@pytest.fixture(scope="module")
def encoder(data):
    return MotionTreeEncoder(max_depth=4).fit(data[0])


def _scaled(X, clip, channel, factor):
    out = [c.copy() for c in X[:3]]
    if channel is None:
        out[clip] = out[clip] * factor
    else:
        out[clip][:, channel] *= factor
    return out


@pytest.mark.parametrize("channel", [None, 4])
@pytest.mark.parametrize("factor", [1e300, -1e300, 1e200])
def test_huge_values_are_refused_naming_clip_and_channel(data, hmm, encoder, channel, factor):
    X, y = data
    clips = _scaled(X, 1, channel, factor)
    where = rf"X: clip 1, channel {channel or 0} holds "
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no RuntimeWarning first: the check comes before
        with pytest.raises(ValueError, match=where + ".*training spreads"):
            hmm.score_samples(clips)
        with pytest.raises(ValueError, match=where + ".*overflow float64"):
            MotionTreeHMM(max_depth=4).fit(clips + X[3:], y)
        with pytest.raises(ValueError, match=where + ".*overflow float64"):
            MotionTreeEncoder(max_depth=4).fit(clips + X[3:])
        with pytest.raises(ValueError, match=where + ".*overflow float64"):
            encoder.transform(clips)


def test_nan_and_inf_are_refused_naming_clip_frame_and_channel(data, hmm, encoder):
    X, y = data
    for bad in (np.nan, np.inf, -np.inf):
        clips = [c.copy() for c in X[:3]]
        clips[2][7, 5] = bad
        match = r"clip 2 contains (NaN|inf|-inf) at frame 7, channel 5"
        for call in (
            hmm.score_samples,
            encoder.transform,
            lambda c: MotionTreeHMM(max_depth=4).fit(c + X[3:], y),
            lambda c: MotionTreeEncoder(max_depth=4).fit(c + X[3:]),
        ):
            with pytest.raises(ValueError, match=match):
                call(clips)


def _away(model, clip, distance):
    """``clip`` moved so that its deviations from the training mean are ``distance`` times
    larger (in training spreads)."""
    z = (clip - model.center_) / model.scale_
    return (z * distance) * model.scale_ + model.center_


def test_score_samples_up_to_the_limit_falls_as_a_clip_moves_away(data, hmm):
    """Below the limit the log-probabilities are numbers, not rounding noise: moving a
    clip away from the training data lowers them for every class, ever faster (the
    Gaussian's quadratic term dominates: score / distance^2 settles)."""
    clip = data[0][0]
    reach = np.abs((clip - hmm.center_) / hmm.scale_).max()
    distances = [1.0, 10.0, 100.0, 1e3, 0.9 * SCORE_LIMIT / reach]
    scores = np.array([hmm.score_samples([_away(hmm, clip, d)])[0] for d in distances])
    assert np.isfinite(scores).all()
    assert (np.diff(scores, axis=0) < 0).all()
    settle = scores[-2:] / np.square(distances[-2:])[:, None]
    np.testing.assert_allclose(settle[0], settle[1], rtol=0.1)
    with pytest.raises(ValueError, match="clip 0, channel .* training spreads"):
        hmm.score_samples([_away(hmm, clip, 1.2 * SCORE_LIMIT / reach)])
    # predict_proba and novelty_score keep answering there (tests/tree/test_hmm_probabilities.py)
    far = [_away(hmm, clip, 1e8)]
    assert np.isfinite(hmm.predict_proba(far)).all()


@settings(max_examples=15, deadline=None)
@given(st.floats(0.0, 140.0), st.integers(0, 2), st.integers(0, 59))
def test_encoder_features_are_finite_below_the_overflow_limit(encoder, data, exponent, k, channel):
    """Any value up to the limit encodes to finite features; the moment feature of a
    channel is the clip's mean in training spreads, computed here by hand."""
    clips = [c.copy() for c in data[0][:3]]
    clips[k][:, channel] = clips[k][:, channel] * 10.0**exponent
    assert np.abs(clips[k]).max() <= overflow_limit(clips)
    features = encoder.set_output(transform="default").transform(clips)
    assert np.isfinite(features).all()
    names = list(encoder.get_feature_names_out())
    column = names.index(f"mean_channel_{channel}")
    expected = (clips[k][:, channel].mean() - encoder.moment_center_[channel]) / (
        encoder.moment_scale_[channel]
    )
    np.testing.assert_allclose(features[k, column], expected, rtol=1e-9)


@given(
    lengths=st.lists(st.integers(0, 4), min_size=1, max_size=5),
    where=st.integers(0, 10**6),
    value=st.sampled_from([1e300, -1e300, 1e200, 3.0]),
    spread=st.sampled_from([1.0, 1e-160]),  # 1e-160: the second check fails
)
@settings(max_examples=60, deadline=None)
def test_the_stacked_check_names_what_the_per_clip_checks_name(lengths, where, value, spread):
    """One check of stacked clips under two limits = check_magnitude per limit, in turn:
    the same clip, channel and message (or none), empty clips included."""
    rng = np.random.default_rng(where)
    clips = [rng.normal(size=(n, 3)) for n in lengths]
    frames, offsets = stack_clips(clips)
    if len(frames):
        frames[where % len(frames), where % 3] = value
        clips = [frames[a:b] for a, b in zip(offsets[:-1], offsets[1:])]
    center, scale = np.array([0.5, -1.0, 0.0]), np.array([1.0, spread, 2.0])
    estimator = MotionTreeEncoder()

    def message(call):
        try:
            call()
        except ValueError as error:
            return str(error)
        return None

    def per_clip():
        check_magnitude(clips, estimator)
        check_magnitude(clips, estimator, center=center, scale=scale, why="in spreads")

    checks = [(0.0, 1.0, None), (center, scale, "in spreads")]
    stacked = message(lambda: check_stacked_magnitude(frames, offsets, estimator, checks))
    assert stacked == message(per_clip)
