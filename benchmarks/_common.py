"""Timing, results files and the CMU windows shared by the benchmark scripts.

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

import numpy as np

# Run from a checkout without installing: the repository root goes on the path.
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

RESULTS = Path(__file__).resolve().parent / "results"
# SKMOTION_SHARED_DATA points elsewhere (as for the tests), e.g. from a git worktree.
_DEFAULT_DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data"
SHARED_DATA = Path(os.environ.get("SKMOTION_SHARED_DATA", _DEFAULT_DATA))

CMU_RATE = 30  # Hz, after the markers are computed at the recorded 120 Hz
CMU_WINDOW, CMU_HOP, CMU_TRAIN_SHARE = 30, 15, 0.6  # frames at 30 Hz: 1 s windows, 0.5 s hop
# Subject 02's trials by activity (cmu-index.csv descriptions, shortened)
CMU_CLASSES = {
    "walk": "walk",
    "run/jog": "run",
    "jump, balance": "jump",
    "punch/strike": "punch",
    "bend over, scoop up, rise, lift arm": "bend",
    "swordplay": "swordplay",
    "wash self": "wash",
}


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
        f"machine: {platform.platform()}, Python {platform.python_version()}, "
        f"{os.cpu_count()} cores, load average at the end (1/5/15 min): {_load()}",
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


def _load():
    """The machine's load averages, or "unknown" where the platform has none."""
    try:
        return " / ".join(f"{v:.1f}" for v in os.getloadavg())
    except (AttributeError, OSError):
        return "unknown"


def _fmt(value):
    if isinstance(value, float):
        return f"{value:.4g}"
    return str(value)


def cmu_markers(subjects):
    """Virtual-marker clips (192 channels) of CMU subjects at 30 Hz, with their Bunch (or None)."""
    from skmotion.datasets import load_cmu_asfamc
    from skmotion.preprocessing import to_markers

    folder = SHARED_DATA / "cmu-asfamc"
    if not folder.is_dir():
        return None, None
    data = load_cmu_asfamc(folder, index=SHARED_DATA / "cmu-index.csv", subjects=subjects)
    markers, _ = to_markers(data.motions)  # velocities by central differences at 120 Hz
    step = int(round(data.frame_rate / CMU_RATE))
    return [m[::step] for m in markers], data


def cmu_windows(groups=False):
    """CMU subject 02 cut into windows, split by time inside each trial: Xtr, ytr, Xte, yte.

    Each trial (30 Hz virtual markers) is cut at 60% of its frames: training
    windows lie wholly before the cut, test windows wholly after it, so no
    window overlaps across train and test (windows overlap only within one side).
    Windows: 1 s (30 frames), 0.5 s hop. The run/jog trial (02_03, 1.4 s) is
    too short for a window on both sides and is left out: 6 classes.

    With ``groups=True`` a fifth array follows: the third of its trial's training
    part that holds the centre of each training window (0, 1, 2), so that grouped CV holds
    out a stretch of every trial, as the test split does (only the windows at a
    border overlap a held-out one, by half a window), instead of folds whose
    windows overlap the held-out ones on both sides.
    """
    clips, data = cmu_markers([2])
    Xtr, ytr, Xte, yte, gtr = [], [], [], [], []
    for clip, description in zip(clips, data.description):
        label = CMU_CLASSES[description]
        cut = int(CMU_TRAIN_SHARE * len(clip))
        for part, X, y in ((clip[:cut], Xtr, ytr), (clip[cut:], Xte, yte)):
            for start in range(0, len(part) - CMU_WINDOW + 1, CMU_HOP):
                X.append(part[start : start + CMU_WINDOW])
                y.append(label)
                if X is Xtr:
                    gtr.append(min(2, 3 * (start + CMU_WINDOW // 2) // len(part)))
    ytr, yte, gtr = np.asarray(ytr), np.asarray(yte), np.asarray(gtr)
    both = np.intersect1d(ytr, yte)
    pick = lambda X, y: ([x for x, label in zip(X, y) if label in both], y[np.isin(y, both)])  # noqa: E731
    out = (*pick(Xtr, ytr), *pick(Xte, yte))
    return (*out, gtr[np.isin(ytr, both)]) if groups else out
