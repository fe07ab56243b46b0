"""Fuzz test of the binary readers: structure-aware mutations of C3D files (header fields,
parameter bytes, data bytes, truncation), .npy headers and data, .npz archives, and text
mutations of keypoint CSV files, with a fixed seed and a small budget;
``benchmarks/bench_fuzz.py`` runs the same engine with a larger one."""

import numpy as np

from skmotion.io import read_c3d
from tests.bad_input import binary_fuzz

N_CASES = 40  # per source


def test_binary_fuzz_written_files(tmp_path):
    tally = binary_fuzz.fuzz(tmp_path, n_cases=N_CASES, seed=0)
    assert not tally.failures, "\n".join(tally.failures[:20])
    assert set(tally.counts) == {"written-c3d", "written-npy", "written-npz", "written-csv"}
    for source, row in tally.counts.items():
        assert row["tried"] == N_CASES and row["rejected"] > 0 and row["agrees"] > 0, source


def test_binary_fuzz_real_c3d(tmp_path, shared_data):
    tally = binary_fuzz.fuzz(tmp_path, shared_data, n_cases=N_CASES, seed=1)
    assert not tally.failures, "\n".join(tally.failures[:20])
    assert tally.counts["real-c3d"]["agrees"] > 0


def test_the_judges_can_fail(tmp_path, rng):
    """A read that ignores a flipped data byte, or accepts a cut file, is called wrong."""
    data = binary_fuzz.written_c3d(np.random.default_rng(0))
    (tmp_path / "o.c3d").write_bytes(data)
    original = read_c3d(tmp_path / "o.c3d")
    start, frame_bytes, _ = binary_fuzz._c3d_layout(data)
    flipped = bytearray(data)
    flipped[start + 3] ^= 0x40  # the x of point 0 in frame 0
    outcome, _ = binary_fuzz.judge_c3d(original, original, data, "data", bytes(flipped))
    assert outcome == "wrong"
    (tmp_path / "f.c3d").write_bytes(bytes(flipped))
    read = read_c3d(tmp_path / "f.c3d")
    assert binary_fuzz.judge_c3d(read, original, data, "data", bytes(flipped))[0] == "agrees"
    assert binary_fuzz.judge_c3d(original, original, data, "cut", data[:-600])[0] == "agrees"
    shorter = read_c3d(tmp_path / "o.c3d")
    shorter.channels = shorter.channels[:-1]
    assert binary_fuzz.judge_c3d(shorter, original, data, "cut", data[:-600])[0] == "wrong"
