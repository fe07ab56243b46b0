"""How building, inserting into and storing the interval index grow with the collection.

Collections of 1k to 100k synthetic clips (2-4 s windows of long synthetic
performances, 75 channels). For each: the time to fit, the time to insert one
more clip (feature extraction + tree insertion, median and worst of 200 single
insertions; the paper: under 35 ms), and the memory of the tree (node tables and
leaf blocks), of the stored psi signatures and of the whole process (peak
resident set). Fit is split into its parts: the tree is rebuilt alone from the
stored feature vectors (``tree_build_s``), the rest is the per-clip SVDs and
the feature projection. A log-log fit gives the growth exponents.
Run: ``python benchmarks/bench_neighbors_scale.py`` (``--sizes 1000,3000`` for fewer).
"""

import resource
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import write_results  # noqa: E402
from _motion_data import crop_pool  # noqa: E402

from skmotion.neighbors import IntervalIndexNeighbors  # noqa: E402
from skmotion.neighbors._interval_index import IntervalIndex  # noqa: E402

SIZES = (1_000, 3_000, 10_000, 30_000, 100_000)
N_INSERTS = 200
PARAMS = {"n_levels": 7, "epsilon": 0.8}


def tree_build_seconds(index):
    """Time to build the tree alone (same entries and radii) from the stored feature vectors."""
    tree = index._tree_features
    start = time.perf_counter()
    IntervalIndex(index.index_.edges, index.index_.radius).insert(tree)
    return time.perf_counter() - start


def peak_rss_mb():
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1e3  # Linux: kilobytes


def main(sizes=SIZES):
    clips, labels = crop_pool(max(sizes) + N_INSERTS, random_state=1)
    extra, extra_labels = clips[-N_INSERTS:], labels[-N_INSERTS:]
    rows = []
    for n in sizes:
        start, cpu = time.perf_counter(), time.process_time()
        index = IntervalIndexNeighbors(**PARAMS).fit(clips[:n], labels[:n])
        fit_seconds, fit_cpu = time.perf_counter() - start, time.process_time() - cpu
        tree_seconds = tree_build_seconds(index)
        tree_bytes = index.index_.nbytes()
        stored = index.index_.n_stored()
        signature_bytes = sum(a.nbytes for a in index._ranking)
        times, cpu_times = [], []
        for i in range(N_INSERTS):
            start, cpu = time.perf_counter(), time.process_time()
            index.insert(extra[i : i + 1], extra_labels[i : i + 1])
            times.append(time.perf_counter() - start)
            cpu_times.append(time.process_time() - cpu)
        rows.append(
            {
                "clips": n,
                "fit_s": fit_seconds,
                "fit_cpu_s": fit_cpu,
                "fit_cpu_us_per_clip": 1e6 * fit_cpu / n,
                "tree_build_s": tree_seconds,
                "insert_ms_median": 1e3 * float(np.median(times)),
                "insert_cpu_ms_median": 1e3 * float(np.median(cpu_times)),
                "insert_ms_p99": 1e3 * float(np.quantile(times, 0.99)),
                "insert_ms_max": 1e3 * max(times),
                "leaf_entries_per_clip": stored / n,
                "leaves": index.index_.n_nodes[-1],
                "tree_MB": tree_bytes / 1e6,
                "tree_bytes_per_clip": tree_bytes / n,
                "signatures_MB": signature_bytes / 1e6,
                "peak_rss_MB": peak_rss_mb(),
            }
        )
        print(rows[-1], flush=True)
        del index
    sizes = np.log([r["clips"] for r in rows])
    slopes = {
        key: float(np.polyfit(sizes, np.log([r[key] for r in rows]), 1)[0])
        for key in (
            "fit_s",
            "fit_cpu_s",
            "tree_build_s",
            "tree_MB",
            "signatures_MB",
            "insert_cpu_ms_median",
        )
    }
    notes = (
        f"{PARAMS['n_levels']} levels, epsilon {PARAMS['epsilon']}. Growth exponents (log-log slope over the sizes): "
        + ", ".join(f"{k} {v:.2f}" for k, v in slopes.items())
        + ". Wall-clock times on a shared 2-core machine vary with its load; the CPU times (time.process_time) "
        "less so. The worst single insertions include merging leaf blocks (amortised)."
    )
    write_results("neighbors_scale", rows, notes=notes)


if __name__ == "__main__":
    if "--sizes" in sys.argv:
        main(tuple(int(v) for v in sys.argv[sys.argv.index("--sizes") + 1].split(",")))
    else:
        main()
