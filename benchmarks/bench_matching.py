"""Search inside long takes: frame search (MotionMatcher), occurrence search, the controller.

One run, skmotion beside its peers on the same data and the same queries:

- **frame search** (``MotionMatcher``): synthetic long takes (walks in four
  directions, turning, ``make_walks``; ``--frames`` frames indexed, 10^6 by
  default) and MSRC-12's Kinect sequences (350k frames). Queries are frames of
  held-out takes (other seeds; MSRC-12: the odd persons are indexed, the even
  persons queried), one per call, after a few unmeasured calls. Peers: sklearn
  ``NearestNeighbors`` (brute, kd_tree, ball_tree) and faiss (``IndexFlatL2``:
  compiled brute force; ``IndexHNSWFlat`` as faiss makes it by default: degree
  32, construction beam 40). Both HNSW graphs are built on two threads
  (MotionMatcher builds its graph on one; the same degree and beam); every query
  runs on one. recall@1: the share of queries whose
  first answer is at the exact nearest distance. The ratios are of CPU time
  per query (the process's: on a shared machine closer to the cost of a query
  alone than the wall time, which includes waiting for a core); the summary
  printed last is the issue's test;
- **occurrence search** (``find_occurrences``): a 2 s query cut from the data
  (with noise) searched in a synthetic take (``--frames`` frames of six smooth
  channels: random sinusoids at gait-like rates and a slow drift) and in
  MSRC-12's sequences end to end (hands and feet in the body frame), against
  stumpy's ``match`` and a brute-force top-10 (every window z-normalised explicitly, in chunks;
  skmotion and stumpy each timed three times, interleaved, the fastest kept);
  subsequence DTW against tslearn's ``dtw_subsequence_path`` (MSRC-12 only:
  tslearn's cost matrix has a row per take frame);
- **controller** (``follow_path``): the 4 m zig-zag on the built-in walks and
  on CMU subject 07's walks: root error, pose jumps with and without the
  blend; ``--figure`` draws docs/images/motion_matching_paths.png.

Run: ``python benchmarks/bench_matching.py`` (minutes on an idle machine; most
of it builds the HNSW graphs of 10^6 frames); ``--quick`` uses 10^5 synthetic
frames and a fifth of MSRC-12; ``--parts frames,occurrences`` runs some parts
(``frames``: the synthetic walks; ``msrc-frames``: MSRC-12's frame search).
Needs the ``bench`` and ``ann`` extras (stumpy, tslearn, faiss-cpu).
"""

import argparse
import dataclasses
import hashlib
import os
import sys
import time
from collections import Counter
from functools import partial
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import SHARED_DATA, write_results  # noqa: E402
from _msrc12 import msrc12_takes  # noqa: E402

from skmotion.datasets import make_walks  # noqa: E402
from skmotion.io import Motion, as_motions, read_bvh  # noqa: E402
from skmotion.kinematics import get_layout  # noqa: E402
from skmotion.kinematics._layouts import layout_plan  # noqa: E402
from skmotion.neighbors import MotionMatcher, find_occurrences  # noqa: E402
from skmotion.neighbors._hnsw import hnsw_index  # noqa: E402
from skmotion.planning import follow_path  # noqa: E402
from skmotion.preprocessing._position_frame import position_frame_features  # noqa: E402

EFS = tuple(sorted({12, 16, 20, 24, 32, 64, MotionMatcher().ef}))
HNSW_DEFAULT = f"skmotion MotionMatcher hnsw ef={MotionMatcher().ef}"
#: faiss's compiled search alone on MotionMatcher's graph: what the wrapper adds is the difference.
GRAPH_ALONE = "faiss search_c alone, MotionMatcher's graph ef={}"
KD_TREE = "skmotion MotionMatcher kd_tree"
#: Threads that build the HNSW graphs (skmotion's and faiss's); queries run on one.
BUILD_THREADS = 2
BRUTE = ("sklearn NearestNeighbors brute", "faiss IndexFlatL2")
#: Unmeasured calls before each timing: the first calls fault pages in.
WARM_UP = 20
#: Queries per block when several methods are timed interleaved, block by block.
BLOCK = 50
#: Timings of the occurrence search (skmotion's and stumpy's), interleaved; the fastest kept.
REPEATS = 3
ZIGZAG = np.array([[0.0, 0.0], [1.0, 0.25], [2.0, -0.25], [3.0, 0.25], [4.0, 0.0]])


def _walks(n_frames, seed):
    """Long turning walks in four directions, about ``n_frames`` frames in all."""
    per_direction = max(1, int(round(n_frames / 4 / 900)))
    data = make_walks(per_direction, turn=1.0, duration=(25.0, 35.0), random_state=seed)
    return as_motions(data.clips, data.skeleton, data.frame_rate)


def _msrc(fraction):
    """MSRC-12 sequences as (positions per sequence, person per sequence)."""
    seqs, _, _, person = msrc12_takes(SHARED_DATA / "msrc12" / "msrc12_sequences.npz")
    n = int(round(len(seqs) * fraction))
    # A few sequences are empty (every frame untracked): they hold nothing to search.
    keep = [i for i in range(n) if len(seqs[i]) >= 2]
    return [seqs[i] for i in keep], person[keep]


def _time_single(funcs, queries):
    """Wall and CPU microseconds per call of each ``func(one_query)``, over all queries; answers.

    Several functions are timed interleaved, ``BLOCK`` queries of one, then of the
    next (in turn first and last), so that a change in the machine's load falls on
    all of them alike. The
    CPU time is the process's: on a loaded machine it is closer to what a query
    costs alone than the wall time, which includes waiting for a core.
    """
    for func in funcs:
        for q in queries[:WARM_UP]:
            func(q[None])
    wall, cpu = np.zeros(len(funcs)), np.zeros(len(funcs))
    out = [[] for _ in funcs]
    for start in range(0, len(queries), BLOCK):
        block = queries[start : start + BLOCK]
        # Alternate who goes first: the second finds the block's graph nodes in cache.
        order = range(len(funcs)) if start // BLOCK % 2 == 0 else reversed(range(len(funcs)))
        for i in order:
            func = funcs[i]
            w, c = time.perf_counter(), time.process_time()
            answers = [func(q[None]) for q in block]
            wall[i] += time.perf_counter() - w
            cpu[i] += time.process_time() - c
            out[i] += answers
    scale = 1e6 / len(queries)
    return [(w * scale, c * scale, np.asarray(o)) for w, c, o in zip(wall, cpu, out)]


def _graph_alone(index):
    """faiss's compiled search of one query on ``index``, buffers made once: no wrapper at all."""
    import faiss

    query = np.empty((1, index.d), dtype=np.float32)
    squared, rows = np.empty((1, 1), dtype=np.float32), np.empty((1, 1), dtype=np.int64)
    pointers = [faiss.swig_ptr(a) for a in (query, squared, rows)]
    search = index.search_c

    def func(q):
        query[:] = q
        search(1, pointers[0], 1, pointers[1], pointers[2])
        return float(np.sqrt(squared[0, 0]))

    return func


def _cached_graph(features, cache):
    """MotionMatcher's graph of ``features`` and its row order: from ``cache`` if it holds them.

    The cache is a faiss file with the row order (``.order.npy``) and the SHA-256
    of the float32 features (``.sha256``) beside it; a graph of other features is
    built again, and a new graph is written under temporary names and renamed, the
    stamp last, so the cache is never half-written.
    """
    import faiss

    data = np.ascontiguousarray(features, dtype=np.float32)
    digest = hashlib.sha256(data.tobytes()).hexdigest()
    stamp, order_file = Path(f"{cache}.sha256"), Path(f"{cache}.order.npy")
    if cache and stamp.is_file() and stamp.read_text() == digest and order_file.is_file():
        index, order = faiss.read_index(str(cache)), np.load(order_file)
        if index.ntotal == len(data) == len(order) and index.d == data.shape[1]:
            print(f"  MotionMatcher's graph read from {cache}")
            return index, order
    index, order = hnsw_index(data, BUILD_THREADS)
    if cache:
        stamp.unlink(missing_ok=True)
        faiss.write_index(index, f"{cache}.partial")
        os.replace(f"{cache}.partial", cache)
        np.save(f"{cache}.partial.npy", order)
        os.replace(f"{cache}.partial.npy", order_file)
        stamp.write_text(digest)
    return index, order


def _contenders(matcher, matcher_kw, *, graph_cache=None, decisive=False):
    """(labels, build seconds, prepare, query functions) of skmotion and every peer.

    A contender with several functions (MotionMatcher's graph through ``kneighbors``
    and faiss's compiled search alone on the same graph) is timed interleaved.
    ``decisive``: the k-d tree (the truth) and the default beam alone.
    """
    import faiss
    from sklearn.neighbors import NearestNeighbors

    data = matcher.features_
    out = []
    for algorithm in ("kd_tree", "hnsw"):
        start = time.perf_counter()
        m = MotionMatcher(**matcher_kw, algorithm=algorithm)
        # The same features: only the search structure is built again.
        m.features_, m.take_, m.frame_ = matcher.features_, matcher.take_, matcher.frame_
        if algorithm == "hnsw":
            # MotionMatcher's graph (its degree and beam) on two threads, to save time.
            m._set_graph(*_cached_graph(m.features_, graph_cache))
        else:
            m._build()
        build = time.perf_counter() - start
        func = lambda q, m=m: m.kneighbors(q)[2][0, 0]  # noqa: E731
        if algorithm == "kd_tree":
            out.append(((KD_TREE,), build, None, (func,)))
            continue
        alone = _graph_alone(m.index_)
        for ef in (m.ef,) if decisive else EFS:
            # kneighbors writes the beam into the graph; faiss alone then searches with it.
            prepare = partial(m.set_params, ef=ef)
            labels = (f"skmotion MotionMatcher hnsw ef={ef}", GRAPH_ALONE.format(ef))
            out.append((labels, build, prepare, (func, alone)))
    if decisive:
        return out
    for algorithm in ("brute", "kd_tree", "ball_tree"):
        start = time.perf_counter()
        nn = NearestNeighbors(n_neighbors=1, algorithm=algorithm).fit(data)
        func = lambda q, nn=nn: nn.kneighbors(q)[0][0, 0]  # noqa: E731
        label = f"sklearn NearestNeighbors {algorithm}"
        out.append(((label,), time.perf_counter() - start, None, (func,)))
    data32 = np.ascontiguousarray(data, dtype=np.float32)
    faiss.omp_set_num_threads(BUILD_THREADS)
    flat = faiss.IndexFlatL2(data.shape[1])
    hnsw = faiss.IndexHNSWFlat(data.shape[1], 32)  # faiss's defaults otherwise
    for index in (flat, hnsw):
        start = time.perf_counter()
        index.add(data32)
        build = time.perf_counter() - start
        func = lambda q, index=index: float(np.sqrt(index.search(q.astype(np.float32), 1)[0][0, 0]))  # noqa: E731
        if index is flat:
            out.append((("faiss IndexFlatL2",), build, None, (func,)))
            continue
        for ef in EFS:
            prepare = partial(setattr, index.hnsw, "efSearch", ef)
            label = f"faiss IndexHNSWFlat M=32 efSearch={ef}"
            out.append(((label,), build, prepare, (func,)))
    faiss.omp_set_num_threads(1)  # single queries on one thread, as the others
    return out


def frame_search(name, matcher_kw, index_takes, query_takes, n_queries, **contenders_kw):
    """One table's rows: skmotion's exact and approximate search beside the peers."""
    started = time.perf_counter()
    # Brute force builds nothing: the features alone (each backend is built below).
    matcher = MotionMatcher(**matcher_kw, algorithm="brute").fit(index_takes)
    print(f"{name}: features in {time.perf_counter() - started:.1f} s")
    rng = np.random.default_rng(0)
    pool = np.concatenate(matcher.frame_features(query_takes))
    queries = pool[rng.choice(len(pool), size=min(n_queries, len(pool)), replace=False)]
    timings = {}
    for labels, build, prepare, funcs in _contenders(matcher, matcher_kw, **contenders_kw):
        if prepare is not None:
            prepare()
        # The brute-force scans are slow: a tenth of the queries is enough to time them.
        slow = "brute" in labels[0] or "Flat" in labels[0] and "HNSW" not in labels[0]
        subset = queries[: max(20, len(queries) // 10)] if slow else queries
        for label, timing in zip(labels, _time_single(funcs, subset)):
            timings[label] = (build, *timing)
            print(f"  {label}: {timing[0]:.1f} us wall, {timing[1]:.1f} us CPU per query")
    # The k-d tree is exact (the tests check it against brute force): its answers are the truth.
    exact = timings[KD_TREE][3]
    kd_cpu, hnsw_cpu = timings[KD_TREE][2], timings[HNSW_DEFAULT][2]
    rows = []
    for label, (build, wall, cpu, answers) in timings.items():
        count = len(answers)
        recall = np.mean(np.abs(answers - exact[:count]) <= 1e-4 * (1 + exact[:count]))
        rows.append(
            {
                "data": name,
                "n_frames": len(matcher.features_),
                "n_features": matcher.features_.shape[1],
                "method": label,
                "build_s": round(build, 2),
                "us_per_query": round(wall, 1),
                "cpu_us_per_query": round(cpu, 1),
                "recall@1": round(float(recall), 4),
                "queries": count,
                "cpu_ratio_to_kd_tree": round(cpu / kd_cpu, 2),
                "cpu_ratio_to_hnsw": round(cpu / hnsw_cpu, 2),
            }
        )
    _summary(rows)
    return rows, matcher


def _summary(rows):
    """The issue's test: the default HNSW beam and the exact mode against each peer."""
    by = {r["method"]: r for r in rows}
    ours, kd = by[HNSW_DEFAULT], by[KD_TREE]
    alone = by[GRAPH_ALONE.format(MotionMatcher().ef)]
    met = ours["cpu_us_per_query"] <= 50 and ours["recall@1"] >= 0.99
    print(
        f"{rows[0]['data']}, {rows[0]['n_frames']} frames: {HNSW_DEFAULT}: "
        f"{ours['cpu_us_per_query']} us CPU ({ours['us_per_query']} us wall) per query at "
        f"recall@1 {ours['recall@1']}: {'met' if met else 'NOT met'} (<= 50 us at >= 0.99); "
        f"faiss's compiled search alone on the same graph: {alone['cpu_us_per_query']} us CPU "
        f"(the wrapper: {ours['cpu_us_per_query'] - alone['cpu_us_per_query']:.1f} us)"
    )
    for label, row in by.items():
        if label != HNSW_DEFAULT:
            print(
                f"  CPU per query of {label} / ours: {row['cpu_ratio_to_hnsw']} "
                f"(exact k-d tree: {row['cpu_ratio_to_kd_tree']}; recall@1 {row['recall@1']})"
            )
    if all(m in by for m in BRUTE):
        brute = min(by[m]["cpu_ratio_to_kd_tree"] for m in BRUTE)
        print(
            f"  exact mode (k-d tree, {kd['cpu_us_per_query']} us CPU): {brute}x faster than "
            f"the faster brute force ({'met' if brute >= 10 else 'NOT met'}: >= 10x)"
        )


def _brute_top(query, take, k, exclusion):
    """Top-k z-normalised windows by explicit z-normalisation, greedy exclusion (chunks).

    A constant channel (spread 0) has no z-normalised form: as in stumpy and
    find_occurrences, it is at 0 from a constant channel and sqrt(m) from any other.
    """
    m = len(query)
    q_flat = (query == query[:1]).all(axis=0)
    q = (query - query.mean(0)) / np.where(q_flat, 1.0, query.std(0))
    profile = np.empty(len(take) - m + 1)
    for start in range(0, len(profile), 20000):
        stop = min(start + 20000, len(profile))
        w = np.lib.stride_tricks.sliding_window_view(take[start : stop + m - 1], m, axis=0)
        w = w.transpose(0, 2, 1)  # (windows, m, channels)
        # Constant exactly (a computed spread of equal values may round to 1e-17).
        flat = (w == w[:, :1, :]).all(axis=1)  # (windows, channels)
        spread = np.where(flat[:, None, :], 1.0, w.std(axis=1, keepdims=True))
        z = (w - w.mean(axis=1, keepdims=True)) / spread
        per_channel = np.sqrt(((z - q) ** 2).sum(axis=1))  # (windows, channels)
        per_channel = np.where(flat & q_flat, 0.0, per_channel)
        per_channel = np.where(flat ^ q_flat, np.sqrt(m), per_channel)
        profile[start:stop] = per_channel.mean(axis=1)
    found = []
    while len(found) < k:
        i = int(np.argmin(profile))
        found.append(i)
        profile[max(0, i - exclusion) : i + exclusion + 1] = np.inf
    return found


def occurrences(name, take, query_at, m, rows, dtw_peer):
    import stumpy

    rng = np.random.default_rng(1)
    query = take[query_at : query_at + m] + rng.normal(scale=0.01, size=(m, take.shape[1]))
    stumpy.match(query.T.copy(), take[:5000].T.copy(), max_distance=np.inf, max_matches=2)
    # Both on every core: stumpy's match runs numba's parallel loops. Each timed REPEATS
    # times, interleaved, the fastest kept: on a shared machine the others' jobs only add.
    calls = {
        "ours": partial(find_occurrences, query, [take], n_occurrences=10, n_jobs=-1),
        "ours_one": partial(find_occurrences, query, [take], n_occurrences=10),
        "peer": partial(
            stumpy.match, query.T.copy(), take.T.copy(), max_distance=np.inf, max_matches=10
        ),
    }
    best, answers = dict.fromkeys(calls, np.inf), {}
    for _ in range(REPEATS):
        for key, call in calls.items():
            start = time.perf_counter()
            answers[key] = call()
            best[key] = min(best[key], time.perf_counter() - start)
    found, peer = answers["ours"], answers["peer"]
    ours, ours_one, theirs = best["ours"], best["ours_one"], best["peer"]
    brute = _brute_top(query, take, 10, int(np.ceil(m / 4)))
    same_brute = found["start"].tolist() == brute
    same_stumpy = found["start"].tolist() == peer[:, 1].astype(int).tolist()
    rows.append(
        {
            "data": name,
            "take_frames": len(take),
            "channels": take.shape[1],
            "query_frames": m,
            "method": "znorm top-10",
            "skmotion_s": round(ours, 3),
            "skmotion_one_thread_s": round(ours_one, 3),
            "peer": "stumpy.match",
            "peer_s": round(theirs, 3),
            "speedup": round(theirs / ours, 1),
            "top10_equal_brute_force": same_brute,
            "top10_equal_peer": same_stumpy,
        }
    )
    start = time.perf_counter()
    found = find_occurrences(query, [take], metric="dtw", n_occurrences=1)
    ours = time.perf_counter() - start
    row = {
        "data": name,
        "take_frames": len(take),
        "channels": take.shape[1],
        "query_frames": m,
        "method": "subsequence DTW top-1",
        "skmotion_s": round(ours, 3),
        "skmotion_one_thread_s": "",
        "peer": "",
        "peer_s": "",
        "speedup": "",
        "top10_equal_brute_force": "",
        "top10_equal_peer": "",
    }
    if dtw_peer:
        from tslearn.metrics import dtw_subsequence_path

        dtw_subsequence_path(query[:5], take[:50])
        start = time.perf_counter()
        path, distance = dtw_subsequence_path(query, take)
        theirs = time.perf_counter() - start
        same = (found["start"][0], found["end"][0]) == (path[0][1], path[-1][1] + 1)
        row.update(
            peer="tslearn dtw_subsequence_path",
            peer_s=round(theirs, 3),
            speedup=round(theirs / ours, 1),
            top10_equal_peer=bool(same and np.isclose(found["distance"][0], distance)),
            top10_equal_brute_force="(tests)",
        )
    rows.append(row)


def _cmu_walks():
    files = sorted((SHARED_DATA / "cmu-bvh" / "07").glob("*.bvh"))
    motions = [read_bvh(f) for f in files]
    common = Counter(m.n_channels for m in motions).most_common(1)[0][0]
    motions = [m for m in motions if m.n_channels == common]
    skeleton = dataclasses.replace(motions[0].skeleton, meters_per_unit=0.01, units="cm")
    return [Motion(skeleton, m.channels, frame_rate=m.frame_rate) for m in motions]


def controller(figure):
    data = make_walks(8, turn=1.5, random_state=0)
    sets = {
        "make_walks": as_motions(data.clips, data.skeleton, data.frame_rate),
        "CMU 07 walks": _cmu_walks(),
    }
    rows, results = [], {}
    for name, takes in sets.items():
        matcher = MotionMatcher().fit(takes)
        for label, kw in (("adjusted", {}), ("no adjustment", {"adjust_halflife": None})):
            start = time.perf_counter()
            result = follow_path(matcher, takes, ZIGZAG, **kw)
            seconds = time.perf_counter() - start
            results[name, label] = result
            rows.append(
                {
                    "database": name,
                    "frames": len(matcher.features_),
                    "root": label,
                    "root_error_max_m": round(float(result.root_error.max()), 3),
                    "root_error_mean_m": round(float(result.root_error.mean()), 3),
                    "end_error_m": round(float(np.hypot(*(result.root[-1, :2] - ZIGZAG[-1]))), 3),
                    "switches": len(result.switches),
                    "jump_blended_mm": round(1000 * float(result.jump.mean()), 2),
                    "jump_no_blend_mm": round(1000 * float(result.jump_unblended.mean()), 2),
                    "median_step_mm": round(1000 * result.step, 2),
                    "adjustment_share": round(result.adjustment, 3),
                    "synthesis_s": round(seconds, 2),
                }
            )
    if figure:
        _figure(results)
    return rows


def _figure(results):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 1, figsize=(8.0, 5.0), sharex=True)
    for ax, name in zip(axes, ("make_walks", "CMU 07 walks")):
        ax.plot(*ZIGZAG.T, "k--", lw=1.5, label="desired path")
        for label, colour in (("adjusted", "C0"), ("no adjustment", "C1")):
            r = results[name, label]
            ax.plot(r.root[:, 0], r.root[:, 1], color=colour, lw=1.5, label=f"root, {label}")
            ax.plot(*r.root[r.switches, :2].T, "o", color=colour, ms=3)
        ax.set_title(f"{name}: root path (dots: database switches)")
        ax.set_ylabel("left (m)")
        ax.set_aspect("equal")
        ax.set_ylim(-0.45, 0.65)
        ax.legend(fontsize=7, loc="upper center", ncol=3, frameon=False)
    axes[-1].set_xlabel("forward (m)")
    fig.tight_layout()
    folder = Path(__file__).resolve().parents[1] / "docs" / "images"
    fig.savefig(folder / "motion_matching_paths.png", dpi=110)
    print("wrote", folder / "motion_matching_paths.png")


def _smooth_take(n_frames, n_channels, seed):
    """A long synthetic take: per channel, random sinusoids at gait-like rates plus a slow drift."""
    rng = np.random.default_rng(seed)
    t = np.arange(n_frames) / 30.0
    take = np.zeros((n_frames, n_channels))
    for c in range(n_channels):
        for _ in range(4):
            freq, phase = rng.uniform(0.2, 2.5), rng.uniform(0, 2 * np.pi)
            take[:, c] += rng.uniform(0.2, 1.0) * np.sin(2 * np.pi * freq * t + phase)
        take[:, c] += np.cumsum(rng.normal(scale=0.01, size=n_frames))
    return take


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--quick", action="store_true", help="10^5 synthetic frames, 1/5 of MSRC-12"
    )
    parser.add_argument("--frames", type=int, default=10**6, help="synthetic frames to index")
    parser.add_argument("--queries", type=int, default=1000)
    parser.add_argument("--figure", action="store_true", help="write the controller's figure")
    parser.add_argument(
        "--parts",
        default="frames,msrc-frames,occurrences,controller",
        help="comma-separated: frames, msrc-frames, occurrences, controller",
    )
    parser.add_argument(
        "--graph-cache",
        help="faiss file for MotionMatcher's graph of the synthetic walks: read when it holds "
        "the graph of these features, else built and written there",
    )
    parser.add_argument(
        "--decisive",
        action="store_true",
        help="frames: the exact k-d tree, the default beam and faiss alone on its graph only",
    )
    args = parser.parse_args()
    parts = set(args.parts.split(","))
    frames = 10**5 if args.quick else args.frames
    load = os.getloadavg()
    notes = f"load average at the start: {load[0]:.1f} / {load[1]:.1f} / {load[2]:.1f}"
    have_msrc = (SHARED_DATA / "msrc12").is_dir() and parts & {"msrc-frames", "occurrences"}
    seqs, person = _msrc(0.2 if args.quick else 1.0) if have_msrc else ([], [])
    if "frames" in parts:
        start = time.perf_counter()
        index_takes, query_takes = _walks(frames, 0), _walks(max(frames // 50, 3000), 1)
        print(f"walks generated in {time.perf_counter() - start:.1f} s")
        kw = {"graph_cache": args.graph_cache, "decisive": args.decisive}
        rows = frame_search("synthetic walks", {}, index_takes, query_takes, args.queries, **kw)
        name = "matching_frames_decisive" if args.decisive else "matching_frames"
        write_results(name, rows[0], notes=notes)
    if have_msrc and "msrc-frames" in parts:
        kw = {"layout": "kinect_v1", "frame_rate": 15.0, "points": ("left_hand", "right_hand")}
        odd = [s for s, p in zip(seqs, person) if p % 2]
        even = [s for s, p in zip(seqs, person) if not p % 2]
        rows = frame_search("MSRC-12 (odd persons indexed)", kw, odd, even, args.queries)
        write_results("matching_frames_msrc12", rows[0], notes=notes)
    if "occurrences" in parts:
        rows = []
        occurrences("synthetic take", _smooth_take(frames, 6, 0), frames // 3, 60, rows, False)
        if have_msrc:
            # Marker features: hands and feet in the body frame, every sequence end to end.
            names = ["left_hand", "right_hand", "left_toe", "right_toe"]
            plan = layout_plan(get_layout("kinect_v1"), names)
            roles = {k: plan[k] for k in ("root", "lefts", "rights", "outputs")}
            take = np.concatenate(
                [
                    position_frame_features(s.reshape(len(s), -1, 3), **roles, velocities=False)
                    for s in seqs
                ]
            )
            occurrences("MSRC-12 sequences", take, len(take) // 2, 30, rows, True)
        write_results("matching_occurrences", rows, notes=notes)
    if "controller" in parts:
        write_results("matching_controller", controller(args.figure), notes=notes)


if __name__ == "__main__":
    main()
