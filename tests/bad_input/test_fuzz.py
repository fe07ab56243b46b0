"""Fuzz test of every reader: random byte mutations (bit flips, inserted control and odd
bytes, deletions, truncation, line edits, layout-only changes) of written and real files.

A fixed seed and a small budget keep it under 30 s; ``benchmarks/bench_fuzz.py`` runs
the same engine with a larger budget and writes the counts per reader.
"""

import time

import pytest

from tests.bad_input import fuzz

N_CASES = 120  # per source: 8 sources (4 written, 4 real) x 120 = 960 reads


def _report(tally):
    for name, row in sorted(tally.counts.items()):
        print(name, row)
    return "\n".join(tally.failures[:20])


def test_fuzz_written_files(tmp_path):
    start = time.perf_counter()
    tally = fuzz.fuzz(tmp_path, n_cases=N_CASES, seed=0)
    failures = _report(tally)
    assert not tally.failures, f"{len(tally.failures)} failures:\n{failures}"
    assert sum(row["tried"] for row in tally.counts.values()) == 4 * N_CASES
    # Each outcome occurs: the mutations reach both the errors and the accepted paths.
    for outcome in ("rejected", "agrees", "equal"):
        assert sum(row[outcome] for row in tally.counts.values()) > 0, outcome
    assert time.perf_counter() - start < 30


def test_fuzz_real_files(tmp_path, shared_data):
    tally = fuzz.fuzz(tmp_path, shared_data, n_cases=N_CASES, seed=1)
    failures = _report(tally)
    assert not tally.failures, f"{len(tally.failures)} failures:\n{failures}"
    assert {name for name in tally.counts if name.startswith("real")} == {
        "real-bvh",
        "real-asf",
        "real-amc",
        "real-ts",
    }


def test_a_reader_that_raises_another_type_or_hangs_is_caught(tmp_path):
    """The harness itself: a foreign exception and a hang are failures, not passes."""
    tally = fuzz.Tally()

    def crashes(path):
        raise AssertionError("unreachable")

    def hangs(path):
        while True:
            pass

    path = tmp_path / "x.bvh"
    fuzz.run_case(path, "fake-bvh", crashes, b"x", "crash", False, None, tally)
    fuzz.run_case(path, "fake-bvh", hangs, b"x", "hang", False, None, tally, time_limit=0.2)
    assert tally.counts["fake-bvh"]["failure"] == 2
    assert "AssertionError" in tally.failures[0] and "no answer within 0.2 s" in tally.failures[1]


@pytest.mark.parametrize("seed", [0, 1])
def test_mutations_are_reproducible(seed):
    import numpy as np

    data = b"HIERARCHY\nROOT a\n{\n OFFSET 0 0 0\n}\n"
    a = [fuzz.mutate(data, np.random.default_rng(seed)) for _ in range(1)]
    b = [fuzz.mutate(data, np.random.default_rng(seed)) for _ in range(1)]
    assert a == b
