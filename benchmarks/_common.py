"""Timing and results files shared by the benchmark scripts.

Every script times skmotion and its peers in the same run, reports ratios, and
writes a CSV and a Markdown table to ``benchmarks/results/`` (git-ignored).
"""

import csv
import os
import platform
import statistics
import sys
import time
from pathlib import Path

# Run from a checkout without installing: the repository root goes on the path.
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

RESULTS = Path(__file__).resolve().parent / "results"
# As in tests/conftest.py: SKMOTION_SHARED_DATA points elsewhere (e.g. from a git worktree).
SHARED_DATA = Path(
    os.environ.get(
        "SKMOTION_SHARED_DATA", Path(__file__).resolve().parents[1].parent / "shared" / "data"
    )
)


def time_call(func, *, repeats=5, warmup=1):
    """Median and spread of wall-clock seconds of ``func()`` over ``repeats`` runs."""
    for _ in range(warmup):
        func()
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        func()
        times.append(time.perf_counter() - start)
    return statistics.median(times), (statistics.stdev(times) if repeats > 1 else 0.0)


def interleaved(funcs, rounds):
    """Median seconds of each function, timed in alternation (they share the machine's load)."""
    for func in funcs:
        func()  # warm-up
    times = [[] for _ in funcs]
    for _ in range(rounds):
        for func, bucket in zip(funcs, times):
            start = time.perf_counter()
            func()
            bucket.append(time.perf_counter() - start)
    return [statistics.median(bucket) for bucket in times]


def write_results(name, rows, *, notes=""):
    """Write ``rows`` (a list of dicts) as ``results/<name>.csv`` and ``.md``; print the table."""
    RESULTS.mkdir(exist_ok=True)
    columns = list(rows[0].keys())
    with open(RESULTS / f"{name}.csv", "w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=columns)
        writer.writeheader()
        writer.writerows(rows)
    lines = [
        f"# {name}",
        "",
        f"machine: {platform.platform()}, Python {platform.python_version()}",
        "",
    ]
    if notes:
        lines += [notes, ""]
    lines += ["| " + " | ".join(columns) + " |", "|" + "---|" * len(columns)]
    lines += ["| " + " | ".join(_fmt(r[c]) for c in columns) + " |" for r in rows]
    text = "\n".join(lines) + "\n"
    (RESULTS / f"{name}.md").write_text(text)
    print(text)
    return text


def _fmt(value):
    if isinstance(value, float):
        return f"{value:.4g}"
    return str(value)
