"""Query cost of the interval index against sklearn and tslearn, in the same run.

* traversal alone: microseconds per query to reach the leaf (batched, and one
  query at a time), against sklearn ``NearestNeighbors`` 1-NN (brute, kd_tree)
  on the same feature vectors;
* end to end, clips in, 1-NN out: ``IntervalIndexNeighbors.kneighbors`` (query
  SVDs + traversal + psi ranking of the candidates) against sklearn's brute
  force with the same similarity (psi against every stored clip, then
  ``NearestNeighbors(metric="precomputed")``) and against sklearn brute force on
  the SVD feature vectors (Euclidean; a different, cheaper answer);
* against tslearn's 1-NN DTW on the same clips (300 clips, 30 queries: DTW is
  slow; its linear cost is extrapolated to the largest collection).

First, the cost of one query of a 40-frame, 60-channel clip (features,
traversal, end to end; CPU time, batched, and for ``candidates`` and
``kneighbors`` also one clip per call: the difference is the per-call cost). Run:
``python benchmarks/bench_neighbors_query.py`` (``--quick``: that table only).
"""

import sys
import time
from pathlib import Path

import numpy as np
from sklearn.neighbors import NearestNeighbors

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import time_call, write_results  # noqa: E402
from _motion_data import crop_pool  # noqa: E402

from skmotion.decomposition import svd_project  # noqa: E402
from skmotion.decomposition._clip_svd import clip_spectra, small_blas  # noqa: E402
from skmotion.neighbors import IntervalIndexNeighbors  # noqa: E402
from skmotion.neighbors._psi import (  # noqa: E402
    psi_from_signatures,
    psi_signatures,
    signatures_from_spectra,
)
from skmotion.utils import check_clips  # noqa: E402

SIZES = (1_000, 3_000, 10_000)


def fast_signatures(clips, k):
    """psi signatures of validated clips by the index's own (compiled, iterative) route.

    Brute force gets the same cheap query decomposition as the index, so that
    the ratio measures the search, not two ways of decomposing the queries.
    """
    return signatures_from_spectra(*clip_spectra(clips, k, method="iterative"), k)


N_QUERIES = 500
# Queries timed one call each (the per-call cost of validation, set-up and dispatch).
N_SINGLE = 200
PARAMS = {"n_levels": 7, "target_recall": 0.99, "random_state": 0}


def traversal_rows(index, features, n):
    tree = np.ascontiguousarray(features[:, : index.n_levels])
    batched, _ = time_call(lambda: index.index_.leaf_of(tree), repeats=5)
    singles = tree[:200]
    one, _ = time_call(lambda: [index.index_.leaf_of(q[None]) for q in singles], repeats=3)
    one_numpy, _ = time_call(
        lambda: [index.index_._leaf_of_batch(q[None]) for q in singles], repeats=3
    )
    rows = [
        {
            "collection": n,
            "what": "traversal, batched",
            "method": "IntervalIndex.leaf_of",
            "us_per_query": 1e6 * batched / len(tree),
        },
        {
            "collection": n,
            "what": "traversal, one at a time",
            "method": "IntervalIndex.leaf_of (bisect path)",
            "us_per_query": 1e6 * one / len(singles),
        },
        {
            "collection": n,
            "what": "traversal, one at a time",
            "method": "vectorised path on 1 query",
            "us_per_query": 1e6 * one_numpy / len(singles),
        },
    ]
    stored = index._stored["tree"]
    for algorithm in ("brute", "kd_tree"):
        nn = NearestNeighbors(n_neighbors=1, algorithm=algorithm).fit(stored)
        seconds, _ = time_call(lambda nn=nn: nn.kneighbors(tree), repeats=3)
        one, _ = time_call(lambda nn=nn: [nn.kneighbors(q[None]) for q in singles[:50]], repeats=1)
        rows.append(
            {
                "collection": n,
                "what": "1-NN on the feature vectors, batched",
                "method": f"sklearn {algorithm}",
                "us_per_query": 1e6 * seconds / len(tree),
            }
        )
        rows.append(
            {
                "collection": n,
                "what": "1-NN on the feature vectors, one at a time",
                "method": f"sklearn {algorithm}",
                "us_per_query": 1e6 * one / 50,
            }
        )
    return rows


def end_to_end_rows(index, db_clips, db_labels, queries, query_labels, n):
    stored_signatures = psi_signatures(db_clips, index.k)

    def ours():
        return index.kneighbors(queries, n_neighbors=1, return_distance=False)[:, 0]

    # sklearn's precomputed search wants the square training matrix at fit; its
    # values play no part in kneighbors, so zeros do (setup, not timed).
    precomputed = NearestNeighbors(n_neighbors=1, metric="precomputed").fit(
        np.zeros((n, n), dtype=np.float32)
    )

    def brute_psi():
        signatures = fast_signatures(check_clips(queries), index.k)
        with small_blas():  # the same BLAS set-up as ours
            distance = 1.0 - psi_from_signatures(*signatures, *stored_signatures)
        return precomputed.kneighbors(distance, return_distance=False)[:, 0]

    def brute_psi_threaded():
        signatures = fast_signatures(check_clips(queries), index.k)
        distance = 1.0 - psi_from_signatures(*signatures, *stored_signatures)
        return precomputed.kneighbors(distance, return_distance=False)[:, 0]

    extractor = index.feature_extractor_
    features_nn = NearestNeighbors(n_neighbors=1, algorithm="brute").fit(
        extractor.transform(db_clips)
    )

    def brute_features():
        return features_nn.kneighbors(extractor.transform(queries), return_distance=False)[:, 0]

    rows = []
    reference = brute_psi()
    methods = (
        ("IntervalIndexNeighbors", ours),
        ("sklearn brute force, psi", brute_psi),
        ("sklearn brute force, psi, multithreaded BLAS", brute_psi_threaded),
        ("sklearn brute force, SVD features", brute_features),
    )
    for method, func in methods:
        seconds, _ = time_call(func, repeats=3)
        found = func()
        rows.append(
            {
                "collection": n,
                "what": "end to end 1-NN, clips in",
                "method": method,
                "us_per_query": 1e6 * seconds / len(queries),
                "same_motion": float(np.mean(db_labels[found] == query_labels)),
                "agrees_with_psi_brute_force": float(np.mean(found == reference)),
            }
        )
    return rows


def dtw_rows(clips, labels, queries, query_labels, n=300, n_queries=30, extrapolate_to=None):
    """tslearn 1-NN DTW against the index on the same clips (a subset: DTW is slow).

    tslearn's ``KNeighborsTimeSeries(metric="dtw")`` computes the DTW distance
    from each query to every stored clip, so its cost per query grows linearly
    with the collection: the figure at ``extrapolate_to`` clips is the measured
    one times ``extrapolate_to / n``.
    """
    try:
        from tslearn.neighbors import KNeighborsTimeSeries
        from tslearn.utils import to_time_series_dataset
    except ImportError:
        print('tslearn is not installed (pip install "skmotion[bench]"): no DTW comparison')
        return []
    extrapolate_to = max(SIZES) if extrapolate_to is None else extrapolate_to
    db, db_labels, q, q_labels = (
        clips[:n],
        labels[:n],
        queries[:n_queries],
        query_labels[:n_queries],
    )
    index = IntervalIndexNeighbors(**PARAMS).fit(db, db_labels)
    dtw = KNeighborsTimeSeries(n_neighbors=1, metric="dtw").fit(to_time_series_dataset(db))
    dtw.kneighbors(to_time_series_dataset(q[:1]))  # compiles tslearn's numba code (not timed)
    methods = (
        (
            "IntervalIndexNeighbors",
            lambda: index.kneighbors(q, n_neighbors=1, return_distance=False)[:, 0],
        ),
        (
            "tslearn 1-NN DTW",
            lambda: dtw.kneighbors(to_time_series_dataset(q), return_distance=False)[:, 0],
        ),
    )
    rows = []
    for method, func in methods:
        start = time.perf_counter()
        found = func()
        seconds = time.perf_counter() - start
        per_query = 1e6 * seconds / len(q)
        rows.append(
            {
                "collection": n,
                "what": "end to end 1-NN vs DTW",
                "method": method,
                "us_per_query": per_query,
                "same_motion": float(np.mean(db_labels[found] == q_labels)),
                "agrees_with_psi_brute_force": float("nan"),
            }
        )
        print(rows[-1], flush=True)
    dtw_us = rows[-1]["us_per_query"]
    rows.append(
        {
            **rows[-1],
            "collection": extrapolate_to,
            "what": f"extrapolated from {n} clips (linear)",
            "us_per_query": dtw_us * extrapolate_to / n,
            "same_motion": float("nan"),
        }
    )
    return rows


def _cpu_us(func, n, repeats=3):
    """Median CPU microseconds per item of ``func()`` (the machine is shared: CPU time)."""
    times = []
    for _ in range(repeats):
        start = time.process_time()
        func()
        times.append(time.process_time() - start)
    return 1e6 * float(np.median(times)) / n


def query_cost_rows(n_stored=10_000, n_queries=1_000):
    """Per-query cost for 40-frame, 60-channel clips: features, traversal, end to end.

    The query's features are its leading eigenpairs (the smaller Gram matrix,
    one batched call per clip length) and the projection; "exact" is a full
    batched eigh of every Gram matrix, "iterative" the subspace iteration the
    index uses (weighting "first"). CPU time per query, batched.
    """
    clips, labels = crop_pool(n_stored + n_queries, random_state=2)
    clips = [c[:40, :60] for c in clips]
    db, db_labels, queries = clips[:n_stored], labels[:n_stored], clips[n_stored:]
    index = IntervalIndexNeighbors(random_state=0).fit(db, db_labels)
    projection = index.projection_
    checked = check_clips(queries)
    tree = index.feature_extractor_.transform(queries)

    def features(method):
        spectra = clip_spectra(checked, index.k, method=method)
        return svd_project(projection, *spectra), signatures_from_spectra(*spectra, index.k)

    stored_signatures = index._stored.ranking
    precomputed = NearestNeighbors(n_neighbors=1, metric="precomputed").fit(
        np.zeros((n_stored, n_stored), dtype=np.float32)
    )

    def brute_psi():
        signatures = fast_signatures(checked, index.k)
        with small_blas():
            distance = 1.0 - psi_from_signatures(*signatures, *stored_signatures)
        return precomputed.kneighbors(distance, return_distance=False)[:, 0]

    features_nn = NearestNeighbors(n_neighbors=1, algorithm="brute").fit(index._stored["tree"])
    found = index.kneighbors(queries, return_distance=False)[:, 0]
    reference = brute_psi()
    cases = (
        ("query features, exact eigh", lambda: features("exact")),
        ("query features, iterative (the index's)", lambda: features("iterative")),
        (
            "query tree features only (first vector: what candidates needs)",
            lambda: svd_project(projection, *clip_spectra(checked, 1, method="iterative")),
        ),
        ("traversal, batched", lambda: index.index_.leaf_of(tree)),
        ("candidates: validation + features + traversal", lambda: index.candidates(queries)),
        (
            "candidates, one clip per call (index.candidates([clip]))",
            lambda: [index.candidates([clip]) for clip in queries[:N_SINGLE]],
        ),
        ("end to end 1-NN: IntervalIndexNeighbors.kneighbors", lambda: index.kneighbors(queries)),
        (
            "end to end 1-NN, one clip per call (index.kneighbors([clip]))",
            lambda: [index.kneighbors([clip]) for clip in queries[:N_SINGLE]],
        ),
        ("end to end 1-NN: brute-force psi", brute_psi),
        (
            "end to end 1-NN: brute force on the index's features",
            lambda: features_nn.kneighbors(index.feature_extractor_.transform(queries)),
        ),
    )
    rows = []
    for what, func in cases:
        rows.append(
            {
                "stored": n_stored,
                "clip": "40 x 60",
                "what": what,
                "cpu_us_per_query": _cpu_us(
                    func, N_SINGLE if "one clip per call" in what else n_queries
                ),
                "agrees_with_psi_brute_force": float(np.mean(found == reference))
                if "IntervalIndex" in what
                else float("nan"),
            }
        )
        print(rows[-1], flush=True)
    return rows


def main():
    write_results(
        "neighbors_query_cost",
        query_cost_rows(),
        notes="CPU microseconds per query (batches of 1,000 queries of 40 frames x 60 channels; "
        "10,000 stored clips; target_recall 0.99, 7 levels); the machine's load is in the header: "
        "ratios within the run count.",
    )
    if "--quick" in sys.argv:
        return
    rows, end_rows = [], []
    clips, labels = crop_pool(max(SIZES) + N_QUERIES, random_state=0)
    queries, query_labels = clips[-N_QUERIES:], labels[-N_QUERIES:]
    for n in SIZES:
        db, db_labels = clips[:n], labels[:n]
        start = time.perf_counter()
        index = IntervalIndexNeighbors(**PARAMS).fit(db, db_labels)
        print(f"{n} clips: fit {time.perf_counter() - start:.1f} s", flush=True)
        features = index.feature_extractor_.transform(queries)
        rows += traversal_rows(
            index, np.vstack([index._stored["tree"], features[:, : index.n_levels]]), n
        )
        part = end_to_end_rows(index, db, db_labels, queries, query_labels, n)
        end_rows += part
        for r in rows[-7:] + part:
            print(r, flush=True)
    end_rows += dtw_rows(clips, labels, queries, query_labels)
    write_results(
        "neighbors_traversal",
        rows,
        notes="Microseconds per query to reach the leaf (7 levels, target_recall 0.99) vs "
        "sklearn 1-NN on the same 7-D feature vectors.",
    )
    write_results(
        "neighbors_end_to_end",
        end_rows,
        notes=f"{N_QUERIES} held-out clips query collections of 2-4 s synthetic clips (75 "
        "channels); same_motion = the 1-NN is a clip of the query's motion.",
    )


if __name__ == "__main__":
    main()
