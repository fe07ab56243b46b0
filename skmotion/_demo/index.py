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
    return pruning_efficiency(candidates, labels, labels, query_ids=ids), recall(candidates, labels, labels, query_ids=ids)


def run(context):
    lines = []
    # The paper's set-up: every motion performed several times; similar = same motion.
    data = make_repeated_motions(random_state=context.random_state)
    labels = data.target
    index = IntervalIndexNeighbors(
        n_levels=7, epsilon=0.7, features=SVDFeatureExtractor(weighting="first_two")
    ).fit(data.clips, labels)
    pruning, found = _search_report(index, labels)
    tree = index._tree_features
    start = time.perf_counter()
    for _ in range(20):
        index.index_.leaf_of(tree)
    traversal_us = 1e6 * (time.perf_counter() - start) / (20 * len(tree))
    start = time.perf_counter()
    neighbours = index.kneighbors(n_neighbors=1, return_distance=False)[:, 0]
    query_us = 1e6 * (time.perf_counter() - start) / len(tree)
    lines += [
        f"make_repeated_motions: {len(np.unique(labels))} motions x {len(labels) // len(np.unique(labels))} "
        f"repetitions = {len(labels)} clips (pelvis-relative joint positions, {data.clips[0].shape[1]} channels)",
        f"IntervalIndexNeighbors(n_levels=7, epsilon=0.7, weighted first two singular vectors), "
        f"every clip querying the others:",
        f"  pruning efficiency {pruning:.1%} of the other motions' clips, recall {found:.1%} of its own repetitions",
        f"  tree traversal {traversal_us:.2f} us per query (batched); 1-NN by psi over the candidates "
        f"{query_us:.0f} us per query",
        f"  the nearest clip is a repetition of the same motion for {np.mean(labels[neighbours] == labels):.1%} of queries",
    ]
    # The demo's data set by class (virtual markers from the markers section): broader
    # groups than repetitions of one motion, so less to prune.
    base = context.data
    clips = context.marker_clips
    n_levels = min(7, len(clips) - 1)
    if n_levels < 2 or len(np.unique(base.target)) < 2:
        lines.append(f"the data set has {len(clips)} clips in {len(np.unique(base.target))} classes: too few to index")
        return lines
    by_class = IntervalIndexNeighbors(n_levels=n_levels, epsilon=1.0).fit(clips, base.target)
    pruning, found = _search_report(by_class, base.target)
    lines.append(
        f"the demo's data by class ({len(clips)} clips of virtual markers, {n_levels} levels, epsilon 1.0): "
        f"pruning {pruning:.1%}, recall {found:.1%}"
    )
    context.index_pruning = pruning
    return lines
