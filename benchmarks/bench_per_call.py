"""Per-call costs: making a stream, and the encoder's transform of one clip against a batch.

On MSRC-12 repetitions as clips of virtual markers (``bench_live.msrc12_repetitions``:
odd people train, even people test) when ``../shared/data`` is present, else on
synthetic motions (joint angles without the root):

- ``MotionTreeHMM().stream()``: milliseconds to make the default (online) stream, the
  first time for a fitted model (its tables are made then) and after (shared tables);
  also ``stream(mode="exact")``;
- ``MotionTreeEncoder()``: milliseconds of ``transform`` per clip when all test clips
  go in one call, and when each goes in its own call, and their ratio; the two are
  timed in 21 alternated rounds (a change of load between them would enter the ratio):
  the ratio of the best times and the median of the rounds' ratios, both printed. The
  features of every test clip, one per call, are checked to be the batch's doubles
  (``np.array_equal``).

Times are CPU seconds of this process (``time.process_time``), the best of 5 repeats
(of the rounds, for the encoder), so a busy machine inflates them less than wall time
would. Results:
``results/per_call.{csv,md}``. Run: ``python benchmarks/bench_per_call.py``.
"""

import os
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import SHARED_DATA, write_results  # noqa: E402

from skmotion.datasets import make_motions  # noqa: E402
from skmotion.tree import MotionTreeEncoder, MotionTreeHMM  # noqa: E402

ROUNDS = 21  # alternated rounds of the encoder's batched and one-clip calls


def data():
    if (SHARED_DATA / "msrc12").is_dir():
        from bench_live import msrc12_repetitions

        Xtr, ytr, Xte, _ = msrc12_repetitions()
        return "MSRC-12 repetitions, virtual markers", Xtr, ytr, Xte
    motions = make_motions(n_clips_per_class=12, random_state=0)
    clips = [c[:, 6:] for c in motions.clips]
    return "synthetic motions", clips[::2], motions.target[::2], clips[1::2]


def best(call, repeats=5):
    times = []
    for _ in range(repeats):
        start = time.process_time()
        call()
        times.append(time.process_time() - start)
    return min(times)


def main():
    name, Xtr, ytr, Xte = data()
    load_at_start = os.getloadavg()[0]
    rows = []
    model = MotionTreeHMM().fit(Xtr, ytr)
    start = time.process_time()
    model.stream()
    first = time.process_time() - start
    for mode in ("online", "exact"):
        ms = 1e3 * best(lambda mode=mode: [model.stream(mode=mode) for _ in range(20)]) / 20
        rows.append(
            {
                "data": name,
                "call": f'MotionTreeHMM().stream(mode="{mode}")',
                "ms per call": ms,
                "first call of a fitted model, ms": 1e3 * first if mode == "online" else "",
                "batched ms per clip": "",
                "one clip / batched per clip": "",
                "median of the rounds' ratios": "",
                "one per call = batched": "",
            }
        )
    encoder = MotionTreeEncoder().fit(Xtr)
    batch = encoder.transform(Xte)
    identical = np.array_equal(batch, np.vstack([encoder.transform([c]) for c in Xte]))
    one_clip = Xte[:200]
    # alternated rounds, so a change of the machine's load between the two measurements
    # does not enter their ratio: the best of each, and the median of the rounds' ratios
    batched, single = [], []
    for _ in range(ROUNDS):
        batched.append(best(lambda: encoder.transform(Xte), repeats=1) / len(Xte))
        single.append(
            best(lambda: [encoder.transform([c]) for c in one_clip], repeats=1) / len(one_clip)
        )
    ratios = np.array(single) / np.array(batched)
    print(
        f"MotionTreeEncoder().transform: one clip per call {1e3 * min(single):.3f} ms, batched "
        f"{1e3 * min(batched):.3f} ms per clip; ratio of the best times "
        f"{min(single) / min(batched):.2f}, median of {ROUNDS} rounds' ratios "
        f"{np.median(ratios):.2f}; one per call = batched (np.array_equal, {len(Xte)} clips): "
        f"{identical}; load average {load_at_start:.1f} at the start"
    )
    rows.append(
        {
            "data": name,
            "call": "MotionTreeEncoder().transform([clip])",
            "ms per call": 1e3 * min(single),
            "first call of a fitted model, ms": "",
            "batched ms per clip": 1e3 * min(batched),
            "one clip / batched per clip": min(single) / min(batched),
            "median of the rounds' ratios": float(np.median(ratios)),
            "one per call = batched": identical,
        }
    )
    n_frames = sum(len(c) for c in Xte) / len(Xte)
    write_results(
        "per_call",
        rows,
        notes=(
            f"{len(Xtr)} training clips, {len(Xte)} test clips of {n_frames:.0f} frames on "
            f"average, {Xte[0].shape[1]} channels. CPU time (process_time), best of 5 (the "
            f"encoder: of {ROUNDS} alternated rounds, and the median of their ratios); "
            f"OPENBLAS/OMP/MKL threads = 1. Load average {load_at_start:.1f} at the start."
        ),
    )
    return rows


if __name__ == "__main__":
    main()
