"""Fuzzing every reader with a large budget, and the cost of read_bvh's error path.

Part 1 runs the engine of ``tests/bad_input/test_fuzz.py`` (random byte mutations of
written and real files, each read with a time limit) with many more cases, and writes
per source how many mutated files were tried, rejected with the reader's own
``MotionFileError``, read in agreement with a plain-text reference, read equal to the
original after a layout-only change, and failed (any other outcome: must be 0).

Part 2 (``bench_fuzz_binary``) runs ``tests/bad_input/binary_fuzz.py``: structure-aware
mutations of C3D files (header fields, parameter bytes, data bytes, truncation; a
written file and a real Plug-in Gait file), .npy headers and data, .npz archives and
keypoint CSV text, each read with a time limit and allocation tracing, and writes per
source: rejected, agrees (equal to an independent reference), read as the edited file
states (no independent truth), crashes outside the library's errors, hangs, peak
allocations past 2x the file's size (plus 1 MB), silent wrong reads (all four must be 0).

Part 2b (``--per-reader``, ``bench_fuzz_readers``) runs ``tests/bad_input/reader_fuzz.py``:
mutations of the real files only, counted per reader (C3D, BVH, ASF, AMC, keypoints),
the issue's budget being 10,000 per reader. The budget is split in jobs of 1,000 cases
over ``--workers`` processes (default 2, one per core), each with its address space
capped (``resource.setrlimit``) so that a forged size fails as a MemoryError (a crash)
instead of taking the shared machine down; every case has its own time limit
(``signal.setitimer``) and allocation tracing (``tracemalloc``). Failing cases are
written to ``results/fuzz_failures/`` for regression tests, and each job's counts to
``results/fuzz_jobs/``: ``--collect`` makes the table of a run cut short.

Part 3 writes a large BVH file (``--mb``, default 20; the issue's figure is 100) and
reads it valid and with one error near its end (a word, ``1_000``, a short frame line,
missing frames, a NUL byte), each in a fresh process, recording seconds and peak
memory: the error path should cost about what the valid path does.

    python benchmarks/bench_fuzz.py                  # 1,500 (binary: 2,500) cases per source
    python benchmarks/bench_fuzz.py --per-reader 10000 --binary-cases 0 --cases 0 --mb 0
                                                     # the issue's budget: real files per reader
    python benchmarks/bench_fuzz.py --cases 200 --mb 5   # quick
    python benchmarks/bench_fuzz.py --mb 100         # the issue's size
"""

import argparse
import json
import multiprocessing
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _common import SHARED_DATA, write_results

from tests.bad_input import binary_fuzz, fuzz, reader_fuzz
from tests.bad_input.long_inputs import write_long_bvh

_READ = """
import json, sys, time
from skmotion.io import MotionFileError, read_bvh
start = time.perf_counter()
try:
    read_bvh(sys.argv[1], up_axis="y")
    outcome = "read"
except MotionFileError as error:
    outcome = f"MotionFileError at line {error.line}: {error.message[:60]}"
seconds = time.perf_counter() - start
# VmHWM: this process's peak resident memory (ru_maxrss would include the parent's,
# which Linux carries across exec).
status = open("/proc/self/status").read()
peak = int(status.split("VmHWM:")[1].split()[0]) / 1024
print(json.dumps({"seconds": seconds, "peak_mb": peak, "outcome": outcome}))
"""


def _shared_data():
    folder = Path(os.environ.get("SKMOTION_SHARED_DATA", SHARED_DATA))
    return folder if (folder / "cmu-asfamc" / "01").is_dir() else None


def fuzz_counts(n_cases, seed):
    shared = _shared_data()
    with tempfile.TemporaryDirectory() as folder:
        start = time.perf_counter()
        tally = fuzz.fuzz(Path(folder), shared, n_cases=n_cases, seed=seed)
        seconds = time.perf_counter() - start
    rows = [{"source": name, **row} for name, row in sorted(tally.counts.items())]
    rows.append(
        {
            "source": "all",
            **{
                k: sum(r[k] for r in rows)
                for k in ("tried", "rejected", "agrees", "equal", "failure")
            },
        }
    )
    notes = (
        f"{n_cases} random mutations per source, seed {seed}, {seconds:.0f} s. rejected: the "
        "reader's MotionFileError naming file and line; agrees: read, equal to a plain-text "
        "reference; equal: a layout-only change read equal to the original; failure: anything "
        "else (another exception type, a hang, a disagreement)."
    )
    if shared is None:
        notes += " Real files not found: written files only."
    write_results("bench_fuzz", rows, notes=notes)
    for failure in tally.failures[:20]:
        print("FAILURE", failure)
    return tally


def _edits(text):
    """The large file with one error near its end: (name, bytes)."""
    head, last = text.rstrip(b"\n").rsplit(b"\n", 1)
    values = last.split(b" ")
    frames = text.split(b"Frames: ", 1)[1].split(b"\n", 1)[0]
    return [
        ("valid", text),
        ("a word in the last frame", head + b"\n" + b" ".join([b"ninety"] + values[1:]) + b"\n"),
        ("1_000 in the last frame", head + b"\n" + b" ".join([b"1_000"] + values[1:]) + b"\n"),
        ("last frame one value short", head + b"\n" + b" ".join(values[1:]) + b"\n"),
        ("10 frames missing (truncated)", b"\n".join(text.split(b"\n")[:-11]) + b"\n"),
        ("a NUL byte in the last frame", head + b"\n" + b"\x00" + last + b"\n"),
        (
            "Frames: one more than written",
            text.replace(b"Frames: " + frames, b"Frames: %d" % (int(frames) + 1), 1),
        ),
    ]


def error_path(megabytes):
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        base = Path(folder) / "large.bvh"
        write_long_bvh(base, int(megabytes * 1e6 / 480), precision=4)
        text = base.read_bytes()
        for name, data in _edits(text):
            path = Path(folder) / "case.bvh"
            path.write_bytes(data)
            result = subprocess.run(
                [sys.executable, "-c", _READ, str(path)], capture_output=True, text=True, check=True
            )
            row = json.loads(result.stdout)
            rows.append({"file": name, "MB": len(data) / 1e6, **row})
    valid = rows[0]
    for row in rows:
        row["time / valid"] = row["seconds"] / valid["seconds"]
        row["memory / valid"] = row["peak_mb"] / valid["peak_mb"]
    write_results(
        "bench_fuzz_error_path",
        rows,
        notes="read_bvh of one large file, valid and with one error near its end; each read in "
        "a fresh process (peak = VmHWM, the process's peak resident memory, imports "
        "included). The machine was shared: compare the ratios.",
    )


def binary_counts(n_cases, seed):
    shared = _shared_data()
    with tempfile.TemporaryDirectory() as folder:
        start = time.perf_counter()
        tally = binary_fuzz.fuzz(Path(folder), shared, n_cases=n_cases, seed=seed)
        seconds = time.perf_counter() - start
    rows = [{"source": name, **row} for name, row in sorted(tally.counts.items())]
    rows.append({"source": "all", **{k: sum(r[k] for r in rows) for k in binary_fuzz.OUTCOMES}})
    notes = (
        f"{n_cases} structure-aware mutations per source, seed {seed}, {seconds:.0f} s. "
        "crash: an exception other than MotionFileError naming the file; hang: no answer in "
        "5 s; allocation: a peak past 2x the file's size + 1 MB (tracemalloc); wrong: read, "
        "and different from an independent reference (a plain decode of the data block, "
        "numpy.load, or the original)."
    )
    write_results("bench_fuzz_binary", rows, notes=notes)
    for failure in tally.failures[:20]:
        print(failure)
    return tally


_MEMORY_CAP = 4 << 30  # bytes of address space per worker
_CHUNK = 1000  # cases per job: a reader's budget is split over the workers
_JOBS = Path(__file__).parent / "results" / "fuzz_jobs"


def _fuzz_one_chunk(job):
    """One job; its counts and failures are also saved, so a run cut short keeps them."""
    reader, n_cases, seed, chunk = job
    resource.setrlimit(resource.RLIMIT_AS, (_MEMORY_CAP, _MEMORY_CAP))
    with tempfile.TemporaryDirectory() as folder:
        counts, failures = reader_fuzz.fuzz_reader(
            reader, _shared_data(), folder, n_cases=n_cases, seed=seed, chunk=chunk
        )
    saved = _JOBS.parent / "fuzz_failures"
    for k, (source, _, _, data) in enumerate(failures):
        saved.mkdir(parents=True, exist_ok=True)
        (saved / f"{reader}-{chunk}-{k}-{source}").write_bytes(data)
    failures = [f"{reader} {s}: {o}: {d}" for s, o, d, _ in failures]
    _JOBS.mkdir(parents=True, exist_ok=True)
    job_file = _JOBS / f"{seed}-{reader}-{chunk}.json"
    job_file.write_text(json.dumps({"counts": counts, "failures": failures}))
    return reader, counts, failures


def _table(results):
    """Rows per reader (all, then per file) from (reader, counts, failures) of the jobs."""
    totals = {reader: {} for reader in reader_fuzz.READERS}
    for reader, counts, _ in results:
        for name, row in counts.items():
            total = totals[reader].setdefault(name, dict.fromkeys(reader_fuzz.OUTCOMES, 0))
            for key, value in row.items():
                total[key] += value
    rows = []
    for reader in reader_fuzz.READERS:
        counts = totals[reader]
        if not counts:  # a reader this run left out
            continue
        total = {k: sum(row[k] for row in counts.values()) for k in reader_fuzz.OUTCOMES}
        rows.append({"reader": reader, "file": "all", **total})
        rows += [{"reader": reader, "file": name, **row} for name, row in counts.items()]
    return rows


def reader_counts(n_cases, seed, workers, collect=False, readers=reader_fuzz.READERS):
    """``n_cases`` (10,000) mutated real files per reader; the table per reader and source.

    With ``collect``, no new job: the table of the jobs saved by an earlier run. ``readers``
    limits the run to some readers (e.g. to run one again after a fix).
    """
    if _shared_data() is None:
        print("The real files are not found: no per-reader run.")
        return []
    jobs = [
        (reader, min(_CHUNK, n_cases - start), seed, k)
        for k, start in enumerate(range(0, n_cases, _CHUNK))
        for reader in readers
    ]
    start = time.perf_counter()
    results = []
    if collect:
        for reader, _, _, k in jobs:
            job_file = _JOBS / f"{seed}-{reader}-{k}.json"
            if job_file.exists():
                saved = json.loads(job_file.read_text())
                results.append((reader, saved["counts"], saved["failures"]))
    else:
        with multiprocessing.get_context("spawn").Pool(workers, maxtasksperchild=1) as pool:
            results = list(pool.imap_unordered(_fuzz_one_chunk, jobs))
    seconds = time.perf_counter() - start
    rows = _table(results)
    failures = [f for _, _, found in results for f in found]
    finished = f"{len(results)} of {len(jobs)} jobs finished"
    notes = (
        f"{n_cases} mutations of real files per reader (round robin over its files), seed "
        f"{seed}, in jobs of {_CHUNK} cases (each its own random stream) over {workers} worker "
        f"processes with {_MEMORY_CAP >> 30} GiB of address space each; {finished}"
        f"{'' if collect else f', {seconds:.0f} s'}. "
        "rejected: MotionFileError naming the file (and, for text, a line inside it); "
        "agrees: read, equal to an independent reference of the mutated bytes (a plain NumPy "
        "decode of the C3D data block; a plain-splitting parse of BVH, ASF, AMC and keypoint "
        "text; numpy.load of .npy/.npz bytes whose header fits the file); equal: a layout-only "
        "change read equal to the original; by the file: a C3D header or parameter edit (or "
        "a truncation) the data still backs, read as the edited file states (no independent "
        "truth). Failures: crash (any other exception, MemoryError included), hang (no answer "
        "in 5 s), allocation (tracemalloc peak past 2x (file size + the answer's arrays) + "
        "1 MB, or an answer past 4x the file size), wrong (read, and different from the "
        "reference)."
    )
    write_results("bench_fuzz_readers", rows, notes=notes)
    for failure in failures[:40]:
        print("FAILURE", failure)
    return failures


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--cases", type=int, default=1500, help="mutations per source (0: none)")
    parser.add_argument("--seed", type=int, default=2026)
    parser.add_argument("--mb", type=float, default=20.0, help="size of the large BVH file")
    parser.add_argument(
        "--binary-cases", type=int, default=2500, help="mutations per binary source (0: none)"
    )
    parser.add_argument(
        "--per-reader", type=int, default=0, help="mutated real files per reader (0: none)"
    )
    parser.add_argument("--workers", type=int, default=2, help="processes of the per-reader run")
    parser.add_argument(
        "--readers",
        nargs="+",
        choices=reader_fuzz.READERS,
        default=reader_fuzz.READERS,
        help="readers of the per-reader run (all by default)",
    )
    parser.add_argument(
        "--collect", action="store_true", help="per-reader table of the jobs an earlier run saved"
    )
    args = parser.parse_args()
    if args.per_reader > 0:
        reader_failures = reader_counts(
            args.per_reader, args.seed, args.workers, args.collect, tuple(args.readers)
        )
        if reader_failures:
            return 1
    failures = fuzz_counts(args.cases, args.seed).failures if args.cases > 0 else []
    if args.binary_cases > 0:
        failures += binary_counts(args.binary_cases, args.seed).failures
    if args.mb > 0:
        error_path(args.mb)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
