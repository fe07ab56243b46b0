"""How building, inserting into and storing the interval index grow with the collection.

Collections of 1k to 100k synthetic clips (2-4 s windows of long synthetic
performances, 75 channels). For each: the time to fit, the time to insert one
more clip (feature extraction + tree insertion, median and worst of 200 single
insertions; the paper: under 35 ms), and the memory of the tree (node tables and
leaf blocks) and of the stored psi signatures. A log-log fit gives the growth
exponents. Run: ``python benchmarks/bench_neighbors_scale.py``.
"""

import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import write_results  # noqa: E402
from _motion_data import crop_pool  # noqa: E402

from skmotion.neighbors import IntervalIndexNeighbors  # noqa: E402

SIZES = (1_000, 3_000, 10_000, 30_000, 100_000)
N_INSERTS = 200
PARAMS = {"n_levels": 7, "epsilon": 0.8}


def main():
    clips, labels = crop_pool(max(SIZES) + N_INSERTS, random_state=1)
    extra, extra_labels = clips[-N_INSERTS:], labels[-N_INSERTS:]
    rows = []
    for n in SIZES:
        start = time.perf_counter()
        index = IntervalIndexNeighbors(**PARAMS).fit(clips[:n], labels[:n])
        fit_seconds = time.perf_counter() - start
        tree_bytes = index.index_.nbytes()
        stored = index.index_.n_stored()
        signature_bytes = sum(a.nbytes for a in index._ranking)
        times = []
        for i in range(N_INSERTS):
            start = time.perf_counter()
            index.insert(extra[i : i + 1], extra_labels[i : i + 1])
            times.append(time.perf_counter() - start)
        rows.append(
            {
                "clips": n,
                "fit_s": fit_seconds,
                "insert_ms_median": 1e3 * float(np.median(times)),
                "insert_ms_p99": 1e3 * float(np.quantile(times, 0.99)),
                "insert_ms_max": 1e3 * max(times),
                "leaf_entries_per_clip": stored / n,
                "leaves": index.index_.n_nodes[-1],
                "tree_MB": tree_bytes / 1e6,
                "tree_bytes_per_clip": tree_bytes / n,
                "signatures_MB": signature_bytes / 1e6,
            }
        )
        print(rows[-1], flush=True)
        del index
    sizes = np.log([r["clips"] for r in rows])
    slopes = {
        key: float(np.polyfit(sizes, np.log([r[key] for r in rows]), 1)[0])
        for key in ("fit_s", "tree_MB", "leaves", "insert_ms_median")
    }
    notes = (
        f"{PARAMS['n_levels']} levels, epsilon {PARAMS['epsilon']}. Growth exponents (log-log slope over the sizes): "
        + ", ".join(f"{k} {v:.2f}" for k, v in slopes.items())
        + ". The worst single insertions include merging leaf blocks (amortised)."
    )
    write_results("neighbors_scale", rows, notes=notes)


if __name__ == "__main__":
    main()
