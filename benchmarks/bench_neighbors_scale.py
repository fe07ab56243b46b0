"""How the interval index scales: fit, query, insertion and memory at 10^4-10^6 stored clips.

At each size, against sklearn brute force in the same run: 1-NN end to end
(clips in; the query's SVD, traversal and psi ranking of its candidates)
against brute-force psi (the query's SVD, psi against every stored clip,
``NearestNeighbors(metric="precomputed")``) and against brute-force kNN on the
same feature vectors (``NearestNeighbors(algorithm="brute")``); CPU time per
query (the machine is shared: CPU time varies less than wall time), the
answers' agreement with brute-force psi, the time to insert one clip, and
memory (tree, stored psi signatures, peak resident set).

Clips: 2-4 s windows of long synthetic performances (``crop_pool``), the first 30
channels (10 joints); similar = the same performance; 7 levels, ``target_recall=0.99``
of the psi nearest neighbours (``similar="psi"``: the 1-NN is what is timed),
``width_factor=2`` (about 2^7 rather than 3^7 leaves per clip: the memory of 10^6 clips
stays in a few GB). 10^6 clips: generating and decomposing a million clips takes too
long on a shared 2-core machine, so that row indexes feature vectors directly (table
input, Euclidean ranking): the 10^5 clips' feature vectors and nine jittered copies of
each (noise 0.2 x the learned radii; label = the source clip, so similar = its copies;
agreement there is with brute-force kNN); its brute-force psi figure is the 10^5 one
times 10 (brute force is linear in the collection; marked "extrapolated").
Run: ``python benchmarks/bench_neighbors_scale.py`` (``--sizes 10000`` for a quick run;
``--sharded`` for the sharded index on two local Dask workers against one index).
"""

import resource
import sys
import time
from pathlib import Path

import numpy as np
from sklearn.neighbors import NearestNeighbors

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import interleaved, write_results  # noqa: E402
from _motion_data import crop_pool  # noqa: E402

from skmotion.decomposition._clip_svd import clip_spectra, small_blas  # noqa: E402
from skmotion.neighbors import IntervalIndexNeighbors  # noqa: E402
from skmotion.neighbors._psi import psi_from_signatures, signatures_from_spectra  # noqa: E402
from skmotion.utils import check_clips  # noqa: E402

SIZES = (10_000, 100_000, 1_000_000)
N_QUERIES = 300
N_INSERTS = 50
CHANNELS = 30
PARAMS = {
    "n_levels": 7,
    "target_recall": 0.99,
    "similar": "psi",
    "width_factor": 2.0,
    "random_state": 0,
}


def cpu_us(func, n):
    start = time.process_time()
    out = func()
    return 1e6 * (time.process_time() - start) / n, out


def peak_rss_mb():
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1e3  # Linux: kilobytes


def fast_signatures(clips, k):
    """psi signatures of validated clips by the index's own (compiled, iterative) route.

    Brute force gets the same cheap query decomposition as the index, so that
    the ratio measures the search, not two ways of decomposing the queries.
    """
    return signatures_from_spectra(*clip_spectra(clips, k, method="iterative"), k)


def brute_psi_1nn(stored_signatures, queries, k):
    def run():
        signatures = fast_signatures(check_clips(queries), k)
        best = np.empty(len(queries), dtype=np.intp)
        with small_blas():
            for start in range(0, len(stored_signatures[0]), 50_000):
                part = [s[start : start + 50_000] for s in stored_signatures]
                similarity = psi_from_signatures(*signatures, *part)
                if start == 0:
                    score = similarity.max(axis=1)
                    best[:] = similarity.argmax(axis=1)
                else:
                    better = similarity.max(axis=1) > score
                    best[better] = similarity.argmax(axis=1)[better] + start
                    score = np.maximum(score, similarity.max(axis=1))
        return best

    return run


def timed_fit(params, X, y):
    """The index fitted on ``X, y``, with the fit's wall-clock and CPU seconds."""
    start, cpu = time.perf_counter(), time.process_time()
    index = IntervalIndexNeighbors(**params).fit(X, y)
    return index, time.perf_counter() - start, time.process_time() - cpu


def first_neighbor_us(index, queries):
    """CPU microseconds per query of the index's nearest neighbour, and the neighbours."""
    return cpu_us(lambda: index.kneighbors(queries, return_distance=False)[:, 0], N_QUERIES)


def insert_cpu_ms(index, X, y):
    """CPU milliseconds of each of ``N_INSERTS`` single insertions of ``X, y`` into the index."""
    insert_ms = []
    for i in range(N_INSERTS):
        t = time.process_time()
        index.insert(X[i : i + 1], y[i : i + 1])
        insert_ms.append(1e3 * (time.process_time() - t))
    return insert_ms


def scale_row(index, n, source, times, agrees, candidates, insert_ms, signatures_bytes):
    """One results row; ``times`` is (fit_s, fit_cpu, ours_us, psi_us, knn_us)."""
    fit_s, fit_cpu, ours_us, psi_us, knn_us = times
    return {
        "stored": n,
        "input": source,
        "fit_s": fit_s,
        "fit_cpu_us_per_clip": 1e6 * fit_cpu / n,
        "index_1nn_cpu_us": ours_us,
        "brute_psi_cpu_us": psi_us,
        "brute_knn_features_cpu_us": knn_us,
        "speedup_vs_brute_psi": psi_us / ours_us,
        "speedup_vs_brute_knn": knn_us / ours_us,
        "agrees_with_brute_psi": agrees,
        "candidates_share": float(np.mean([len(c) for c in candidates])) / n,
        "insert_cpu_ms_median": float(np.median(insert_ms)),
        "leaf_entries_per_clip": index.index_.n_stored() / n,
        "tree_MB": index.index_.nbytes() / 1e6,
        "stored_signatures_MB": signatures_bytes / 1e6,
        "peak_rss_MB": peak_rss_mb(),
    }


def clip_row(n, clips, labels, queries, extra, extra_labels):
    index, fit_s, fit_cpu = timed_fit(PARAMS, clips[:n], labels[:n])
    ours_us, ours = first_neighbor_us(index, queries)
    psi_us, reference = cpu_us(brute_psi_1nn(index._stored.ranking, queries, index.k), N_QUERIES)
    nn = NearestNeighbors(n_neighbors=1, algorithm="brute").fit(index._stored["tree"])
    extractor = index.feature_extractor_
    knn_us, _ = cpu_us(lambda: nn.kneighbors(extractor.transform(queries)), N_QUERIES)
    candidates = index.candidates(queries)
    insert_ms = insert_cpu_ms(index, extra, extra_labels)
    times = (fit_s, fit_cpu, ours_us, psi_us, knn_us)
    agrees = float(np.mean(ours == reference))
    signatures_bytes = sum(a.nbytes for a in index._stored.ranking)
    return index, scale_row(
        index, n, "clips", times, agrees, candidates, insert_ms, signatures_bytes
    )


def feature_row(n, base, psi_us_base, n_base):
    """The index on feature vectors: ``base`` (a fitted clip index) copied with jitter."""
    rng = np.random.default_rng(0)
    copies = -(-n // len(base._stored["tree"]))
    noise = 0.2 * base.radius_
    features = np.concatenate(
        [
            base._stored["tree"] + (c > 0) * rng.normal(size=base._stored["tree"].shape) * noise
            for c in range(copies)
        ]
    )[:n]
    labels = np.tile(np.arange(len(base._stored["tree"])), copies)[:n]  # the source clip
    queries = (
        features[rng.choice(n, N_QUERIES, replace=False)]
        + rng.normal(size=(N_QUERIES, features.shape[1])) * noise
    )
    index, fit_s, fit_cpu = timed_fit({**PARAMS, "similar": "labels"}, features, labels)
    ours_us, ours = first_neighbor_us(index, queries)
    nn = NearestNeighbors(n_neighbors=1, algorithm="brute").fit(features)
    knn_us, knn = cpu_us(lambda: nn.kneighbors(queries, return_distance=False)[:, 0], N_QUERIES)
    insert_ms = insert_cpu_ms(index, queries, labels)
    psi_us = psi_us_base * n / n_base
    times = (fit_s, fit_cpu, ours_us, psi_us, knn_us)
    agrees = float(np.mean(ours == knn))  # here: with brute kNN
    source = "feature vectors (brute psi extrapolated)"
    candidates = index.candidates(queries)  # after the insertions, as the row reports them
    return scale_row(
        index, n, source, times, agrees, candidates, insert_ms, index._stored.ranking.nbytes
    )


def sharded_rows(n=10_000, n_queries=N_QUERIES):
    """The sharded index on two local Dask workers (processes, loopback) against one index.

    Wall-clock seconds per query batch, timed in alternation (the two share the
    machine's load); the answers compared id by id.
    """
    try:
        import dask
        import distributed
    except ImportError:
        print('dask is not installed (pip install "skmotion[distributed]"): no sharded row')
        return []
    from skmotion.neighbors import ShardedIntervalIndex

    pool, labels = crop_pool(n + n_queries, random_state=3)
    pool = [c[:, :CHANNELS] for c in pool]
    stored, queries = pool[:n], pool[n:]
    params = {**PARAMS, "similar": "labels"}  # the sharded index learns from labels
    single = IntervalIndexNeighbors(**params).fit(stored, labels[:n])
    rows = []
    with dask.config.set({"distributed.comm.timeouts.connect": "60s"}):
        cluster = distributed.LocalCluster(
            n_workers=2,
            threads_per_worker=1,
            processes=True,
            host="127.0.0.1",
            dashboard_address=None,
        )
        try:
            with distributed.Client(cluster) as client:
                client.wait_for_workers(2, timeout=120)
                start = time.perf_counter()
                sharded = ShardedIntervalIndex(
                    IntervalIndexNeighbors(**params), client=client, n_shards=2
                ).fit(stored, labels[:n])
                sharded_fit = time.perf_counter() - start
                one, two = interleaved(
                    [lambda: single.kneighbors(queries), lambda: sharded.kneighbors(queries)], 5
                )
                same_ids = np.array_equal(
                    single.kneighbors(queries, 5)[1], sharded.kneighbors(queries, 5)[1]
                )
                rows.append(
                    {
                        "stored": n,
                        "queries": n_queries,
                        "single_index_ms_per_batch": 1e3 * one,
                        "sharded_2_workers_ms_per_batch": 1e3 * two,
                        "sharded_over_single": two / one,
                        "sharded_fit_s": sharded_fit,
                        "identical_5nn_ids": bool(same_ids),
                    }
                )
                print(rows[-1], flush=True)
        finally:
            cluster.close(timeout=60)
    return rows


def main(sizes=SIZES):
    clip_sizes = [n for n in sizes if n <= 100_000]
    total = max(clip_sizes) + N_QUERIES + N_INSERTS
    pool, labels = crop_pool(total, random_state=1)
    pool = [c[:, :CHANNELS] for c in pool]
    queries, extra = pool[-N_QUERIES - N_INSERTS : -N_INSERTS], pool[-N_INSERTS:]
    extra_labels = labels[-N_INSERTS:]
    rows, index = [], None
    for n in clip_sizes:
        index, row = clip_row(n, pool, labels, queries, extra, extra_labels)
        rows.append(row)
        print(row, flush=True)
    for n in (n for n in sizes if n > 100_000):
        row = feature_row(n, index, rows[-1]["brute_psi_cpu_us"], rows[-1]["stored"])
        rows.append(row)
        print(row, flush=True)
    write_results(
        "neighbors_scale",
        rows,
        notes="CPU microseconds per query (batches of "
        f"{N_QUERIES} held-out queries), 1-NN. {PARAMS}. speedup = brute force / index. "
        "CPU times (the machine's load is in the header); ratios within one run.",
    )


if __name__ == "__main__":
    if "--sharded" in sys.argv:
        write_results(
            "neighbors_sharded",
            sharded_rows(),
            notes="ShardedIntervalIndex on a LocalCluster (2 worker processes, 1 thread each, "
            f"loopback TCP) against IntervalIndexNeighbors in this process; {PARAMS}; wall-clock "
            "medians of 5 alternated rounds, on a shared 2-core machine.",
        )
    elif "--sizes" in sys.argv:
        main(tuple(int(v) for v in sys.argv[sys.argv.index("--sizes") + 1].split(",")))
    else:
        main()
