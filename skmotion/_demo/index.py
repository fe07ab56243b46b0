"""Demo section: similarity search with SVD feature vectors and the interval index."""

import time

import numpy as np

from skmotion.datasets import make_repeated_motions
from skmotion.decomposition import SVDFeatureExtractor
from skmotion.metrics import pruning_efficiency, recall
from skmotion.neighbors import IntervalIndexNeighbors

TITLE = "Similarity search: SVD features in an interval index"


def _search_report(index, labels):
    ids = np.arange(index.n_samples_fit_)
    candidates = index.candidates()
    return pruning_efficiency(candidates, labels, labels, query_ids=ids), recall(
        candidates, labels, labels, query_ids=ids
    )


def _us_per_query(func, n_queries, repeats):
    start = time.perf_counter()
    for _ in range(repeats):
        func()
    return 1e6 * (time.perf_counter() - start) / (repeats * n_queries)


def _repeated_motions(context):
    # The paper's set-up: every motion performed several times; similar = same motion.
    data = make_repeated_motions(
        n_motions_per_class=4, duration=(1.5, 2.5), random_state=context.random_state
    )
    labels = data.target
    index = IntervalIndexNeighbors(
        n_levels=7, epsilon=0.8, features=SVDFeatureExtractor(weighting="first_two")
    )
    index.fit(data.clips, labels)
    pruning, found = _search_report(index, labels)
    tree = index._stored["tree"]
    batched_us = _us_per_query(lambda: index.index_.leaf_of(tree), len(tree), 20)
    one_us = _us_per_query(lambda: [index.index_.leaf_of(row[None]) for row in tree], len(tree), 2)
    start = time.perf_counter()
    neighbours = index.kneighbors(n_neighbors=1, return_distance=False)[:, 0]
    query_us = 1e6 * (time.perf_counter() - start) / len(tree)
    n_motions = len(np.unique(labels))
    return [
        f"make_repeated_motions: {n_motions} motions x {len(labels) // n_motions} repetitions "
        f"= {len(labels)} clips "
        f"(pelvis-relative joint positions, {data.clips[0].shape[1]} channels)",
        "IntervalIndexNeighbors(n_levels=7, epsilon=0.8, weighted first two singular vectors), "
        "every clip querying the others:",
        f"  pruning efficiency {pruning:.1%} of the other motions' clips, recall {found:.1%} "
        "of its own repetitions",
        f"  tree traversal {batched_us:.2f} us per query batched, {one_us:.1f} us one at a time; "
        f"1-NN by psi over the candidates {query_us:.0f} us per query",
        "  the nearest clip is a repetition of the same motion for "
        f"{np.mean(labels[neighbours] == labels):.1%} of queries",
    ]


def _widest_label(features, labels, names):
    """The label whose clips spread furthest on some component, relative to its range."""
    span = features.max(axis=0) - features.min(axis=0)
    span[span == 0] = 1.0
    best = (0.0, None, 0)
    for g in np.unique(labels):
        rows = features[labels == g]
        if len(rows) > 1:
            relative = (rows.max(axis=0) - rows.min(axis=0)) / span
            if relative.max() > best[0]:
                best = (relative.max(), g, int(relative.argmax()))
    share, g, component = best
    name = names[g] if names is not None and g is not None else g
    return share, name, component


def _marker_clips(context):
    # The demo's data by class, as virtual markers (left by the markers section).
    base = context.data
    clips, labels = context.marker_clips, base.target
    n_levels = min(7, len(clips) - 1)
    if n_levels < 2 or len(np.unique(labels)) < 2:
        return [
            f"the data set has {len(clips)} clips in {len(np.unique(labels))} classes: "
            "too few to index"
        ]
    paper = IntervalIndexNeighbors(n_levels=n_levels, epsilon=1.0).fit(clips, labels)
    pruning, found = _search_report(paper, labels)
    share, name, component = _widest_label(paper._stored["tree"], labels, base.get("target_names"))
    tuned = IntervalIndexNeighbors(
        n_levels=n_levels, epsilon=0.8, features=SVDFeatureExtractor(weighting="first_two")
    ).fit(clips, labels)
    tuned_pruning, tuned_found = _search_report(tuned, labels)
    quantile = IntervalIndexNeighbors(n_levels=n_levels, epsilon=1.0, delta_quantile=0.5).fit(
        clips, labels
    )
    quantile_pruning, quantile_found = _search_report(quantile, labels)
    context.index_pruning = tuned_pruning
    return [
        f"the demo's data by class ({len(clips)} clips of virtual markers, {n_levels} levels), "
        "similar = same class:",
        f"  paper's rule, epsilon 1.0, first singular vector: pruning {pruning:.1%}, "
        f"recall {found:.1%}",
        "  why so little: delta_i is the widest spread of a class; "
        f"class {str(name)!r} spans {share:.0%} of "
        f"component {component}'s range, so every entry is about as wide as the whole range",
        f"  epsilon 0.8, weighted first two singular vectors: pruning {tuned_pruning:.1%}, "
        f"recall {tuned_found:.1%}",
        f"  delta_quantile=0.5 (the median class sets delta_i): pruning {quantile_pruning:.1%}, "
        f"recall {quantile_found:.1%} (the widest classes lose members)",
    ]


def run(context):
    if getattr(context, "marker_clips", False) is None:
        return ["not run: the clips have no virtual markers (the markers section says why)"]
    if getattr(context, "data_folder", None):
        skipped = [
            "repeated-motion benchmark (make_repeated_motions): skipped, it needs every motion "
            "performed several times by design; the folder's own clips are indexed below"
        ]
        return skipped + _marker_clips(context)
    return _repeated_motions(context) + _marker_clips(context)
