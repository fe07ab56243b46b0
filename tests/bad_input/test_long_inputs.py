"""Long clips through MotionTreeHMM and long files through the readers: finite, consistent.

The sizes here are moderate (about 5000 frames through MotionTreeHMM, 2 x 10^4
through the readers) to keep the suite fast; the
benchmark ``benchmarks/bench_long_inputs.py`` runs 10^5 frames and more and
reports time and peak memory against the input's own size.
"""

import tracemalloc

import numpy as np
import pytest

from skmotion.io import MotionFileError, read_amc, read_asf, read_bvh
from tests.bad_input.long_inputs import fitted_hmm, long_clip, write_long_amc, write_long_bvh


@pytest.fixture(scope="module")
def hmm():
    return fitted_hmm()


def test_long_clip_log_likelihood_is_finite_and_grows_linearly(hmm):
    model, base = hmm
    repeats = 6  # about 5000 frames
    short, long = base, long_clip(base, repeats * len(base))
    per_frame_short = model.score_samples([short])[0] / len(short)
    log_lik = model.score_samples([long])[0]
    assert np.isfinite(log_lik).all() and (log_lik < 0).all()
    # The same frames repeated: each class's log-likelihood per frame stays the same
    # (no underflow to -inf, no drift), up to the transitions where repeats meet.
    np.testing.assert_allclose(log_lik / len(long), per_frame_short, rtol=0.01)
    proba = model.predict_proba([long])
    assert np.isfinite(proba).all()
    np.testing.assert_allclose(proba.sum(axis=1), 1.0)
    assert model.classes_[proba.argmax()] == model.predict([short])[0]


def test_long_clip_decodes_like_its_parts(hmm):
    model, base = hmm
    repeats = 6
    states = model.decode([long_clip(base, repeats * len(base))])[1][0]
    assert states.shape == (repeats * len(base),) and states.dtype.kind == "i"
    assert ((states >= 0) & (states < len(model.tree_.node_ids(model.layer_)))).all()
    # Each repeat of the same frames decodes (almost) as the short clip alone.
    alone = model.decode([base])[1][0]
    agreement = (states.reshape(repeats, len(base)) == alone).mean(axis=1)
    assert agreement.min() >= 0.9, agreement


def _traced(func):
    tracemalloc.start()
    try:
        result = func()
        return result, tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


def test_long_bvh_round_trip(tmp_path):
    n_frames = 20_000
    channels = write_long_bvh(tmp_path / "long.bvh", n_frames)
    motion, peak = _traced(lambda: read_bvh(tmp_path / "long.bvh"))
    assert motion.channels.shape == channels.shape and np.isfinite(motion.channels).all()
    np.testing.assert_allclose(motion.channels, channels, atol=1e-5)
    # Memory is a small multiple of the result (measured: about 9x), not of frames squared.
    assert peak < 25 * motion.channels.nbytes, peak / motion.channels.nbytes


def test_long_amc_round_trip(tmp_path):
    n_frames = 20_000
    asf, amc, values = write_long_amc(tmp_path, n_frames)
    skeleton = read_asf(asf)
    motion, peak = _traced(lambda: read_amc(amc, skeleton))
    assert motion.channels.shape == (n_frames, 12) and np.isfinite(motion.channels).all()
    expected = values.copy()
    rotations = np.array([name.endswith("rotation") for name in skeleton.channel_names])
    expected[:, rotations] = np.deg2rad(expected[:, rotations])
    np.testing.assert_allclose(motion.channels, expected, rtol=1e-12, atol=1e-12)
    assert peak < 25 * motion.channels.nbytes * (1 + 5 * 8 / 12), peak / motion.channels.nbytes


@pytest.mark.parametrize(
    "edit",
    ["a word in the last frame", "1_000 in the last frame", "the last frame one value short"],
)
def test_the_error_path_of_a_long_bvh_costs_what_reading_it_does(tmp_path, edit):
    """The error is located in the ~4 MB piece that fails, not by re-parsing the whole
    file token by token (issue 18: 49 s and 2.4 GB for a 100 MB file, 6.2 s valid)."""
    path = tmp_path / "long.bvh"
    write_long_bvh(path, 20_000, precision=4)
    text = path.read_bytes()
    _, valid_peak = _traced(lambda: read_bvh(path, up_axis="y"))
    head, last = text.rstrip(b"\n").rsplit(b"\n", 1)
    values = last.split(b" ")
    values = {
        "a word in the last frame": [b"ninety"] + values[1:],
        "1_000 in the last frame": [b"1_000"] + values[1:],
        "the last frame one value short": values[1:],
    }[edit]
    path.write_bytes(head + b"\n" + b" ".join(values) + b"\n")
    n_lines = text.count(b"\n")

    def read():
        with pytest.raises(MotionFileError) as info:
            read_bvh(path, up_axis="y")
        return info.value

    error, error_peak = _traced(read)
    assert error.line == n_lines
    assert error_peak < 1.5 * valid_peak, (error_peak, valid_peak)
