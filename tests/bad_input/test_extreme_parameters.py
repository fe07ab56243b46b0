"""Issue 18 items 7 and 9 (this branch's part): mixed label types, a missing clip id
in a DataFrame, a Butterworth cutoff double precision cannot hold, ResampleClips sizes."""

import numpy as np
import pandas as pd
import pytest
from scipy.signal import butter, freqz_sos

from skmotion.preprocessing import LowPassFilter, ResampleClips, _resample, lowpass_filter
from skmotion.utils import check_clips
from tests.bad_input.estimators import ENTRIES, fit

CLASSIFIERS = [name for name, entry in ENTRIES.items() if entry.classifier]


def _mixed(n, kind):
    labels = [1 if i % 2 else "walk" for i in range(n)]
    return {
        "list": labels,
        "object array": np.array(labels, dtype=object),
        "Series": pd.Series(labels),
    }[kind]


@pytest.mark.parametrize("kind", ["list", "object array", "Series"])
@pytest.mark.parametrize("name", CLASSIFIERS)
def test_labels_mixing_int_and_str_are_one_clear_type_error(name, kind):
    """Before: a list became the strings '1' and 'walk' (predict answered '1' for 1), and an
    object array failed inside np.unique with "'<' not supported"."""
    X, _ = ENTRIES[name].data()
    with pytest.raises(
        TypeError,
        match=r"y mixes label types: str \('walk' at clip 0\) and "
        r"number \(1 at clip 1\)",
    ):
        fit(ENTRIES[name], X, _mixed(len(X), kind))


@pytest.mark.parametrize("name", CLASSIFIERS)
def test_labels_of_one_type_keep_their_type(name):
    X, _ = ENTRIES[name].data()
    y = [3 if i % 2 else 7 for i in range(len(X))]
    estimator = fit(ENTRIES[name], X, y)
    assert sorted(estimator.classes_.tolist()) == [3, 7]
    assert set(np.asarray(estimator.predict(X)).tolist()) <= {3, 7}


@pytest.mark.parametrize("level, row, what", [(0, 2, "clip"), (1, 1, "frame")])
@pytest.mark.parametrize("missing", [np.nan, None])
def test_a_missing_clip_or_frame_id_in_a_dataframe(level, row, what, missing):
    clips = [["a", "a", "b", "b"], [0, 1, 0, 1]]
    clips[level] = list(clips[level])
    clips[level][row] = missing
    index = pd.MultiIndex.from_arrays(clips, names=["clip", "frame"])
    X = pd.DataFrame(np.arange(8.0).reshape(4, 2), index=index)
    with pytest.raises(ValueError, match=f"X: row {row} of the DataFrame has a missing {what} "):
        check_clips(X)
    with pytest.raises(ValueError, match=f"missing {what} label"):
        LowPassFilter(order=1).fit(X)


@pytest.mark.parametrize("cutoff", [1e-9, 1e-7, 1e-6])
@pytest.mark.parametrize("order", [2, 10])
def test_a_cutoff_double_precision_cannot_hold_is_refused(cutoff, order):
    clips = [np.random.default_rng(0).normal(size=(400, 3))]
    with pytest.raises(ValueError, match=f"cutoff={cutoff!r} is too low for an order-{order}"):
        LowPassFilter(order, cutoff=cutoff).fit(clips)
    with pytest.raises(ValueError, match="too low"):
        lowpass_filter(clips[0], order=order, cutoff=cutoff)


@pytest.mark.parametrize("cutoff", [1e-4, 1e-3, 0.05, 0.25, 0.9, 0.999])
@pytest.mark.parametrize("order", [1, 2, 6, 10])
def test_usable_cutoffs_still_filter_as_designed(cutoff, order):
    """The refusal does not reach usable designs: a constant passes unchanged (gain 1 at
    0 Hz) and the gain at the cutoff is 1/2 (forward-backward Butterworth), as scipy says."""
    clip = np.full((20_000 if cutoff < 1e-3 else 400, 2), 3.0)
    out = LowPassFilter(order, cutoff=cutoff).fit_transform([clip])[0]
    np.testing.assert_allclose(out, clip, rtol=1e-6)
    _, response = freqz_sos(butter(order, cutoff, output="sos"), worN=[cutoff * np.pi])
    assert abs(abs(response[0]) ** 2 - 0.5) < 1e-6


def test_n_frames_true_is_not_one_frame():
    with pytest.raises(TypeError, match="n_frames.* not a bool"):
        ResampleClips(n_frames=True).fit([np.zeros((5, 2))])
    assert ResampleClips(n_frames=np.int64(3)).fit_transform([np.zeros((5, 2))])[0].shape == (3, 2)


def test_an_output_larger_than_memory_is_refused_before_allocating(monkeypatch):
    calls = []
    monkeypatch.setattr(_resample, "resample_clip", lambda *a: calls.append(a))
    clips = [np.zeros((10, 6)), np.zeros((12, 6))]
    # 8 bytes x (2 clips x 1e9 frames x 6 channels + 4 temporaries x 1e9 x 7) = 298.0 GiB
    with pytest.raises(
        ValueError,
        match=r"would need 298\.0 GiB \(clip 0 alone becomes "
        r"1000000000 frames x 6 channels\)",
    ) as info:
        ResampleClips(n_frames=10**9).fit_transform(clips)
    assert "memory" in str(info.value) and calls == []  # nothing was computed
    # The limit is the machine's memory: with 1 MiB, 20,000 frames x 6 channels is refused.
    monkeypatch.setattr(_resample, "_memory_bytes", lambda: 2**20)
    with pytest.raises(ValueError, match="more than this machine's 0.0 GiB"):
        ResampleClips(frame_rate=1.0, target_frame_rate=2000.0).fit_transform(clips)
    monkeypatch.undo()
    out = ResampleClips(frame_rate=1.0, target_frame_rate=2.0).fit_transform(clips)
    assert [len(c) for c in out] == [19, 23]
