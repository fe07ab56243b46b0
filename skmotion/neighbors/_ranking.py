"""The ranking of candidates for IntervalIndexNeighbors: psi distances, the k smallest, per leaf."""

import numpy as np

from skmotion.decomposition._clip_svd import small_blas
from skmotion.neighbors._leaf_kernels import smallest_columns
from skmotion.neighbors._psi import psi_from_signatures
from skmotion.neighbors._psi_rank import psi_distances
from skmotion.utils._parallel import parallel_map

__all__ = ["nearest_in_leaves", "psi_distance_block", "smallest_k"]

# From this many queries in one leaf, gathering the candidates' signatures and
# multiplying matrices beats the compiled pair-by-pair loop (measured at 300 and
# 3,000 candidates, 30 and 60 channels: the cross-over is at 8-12 queries).
_ROWS_FOR_PRODUCTS = 10


def psi_distance_block(query, stored, rows, columns):
    """``1 - psi`` between queries ``rows`` and stored clips ``columns`` (signatures).

    A few queries: the compiled loop reading each candidate's signature in
    place (no gathered copy); many: matrix products over gathered signatures.
    The two agree to rounding (tested).
    """
    if len(rows) >= _ROWS_FOR_PRODUCTS:
        (weights, vectors), (stored_weights, stored_vectors) = query, stored
        return 1.0 - psi_from_signatures(
            weights[rows], vectors[rows], stored_weights[columns], stored_vectors[columns]
        )
    rows, columns = (np.ascontiguousarray(i, dtype=np.intp) for i in (rows, columns))
    return psi_distances(*query, *stored, rows, columns)


def smallest_k(distances, n):
    """Per row, the columns of the ``n`` smallest distances, ties by column.

    Returns ``(columns, distances)``, both ``(n_rows, n)``, increasing (compiled:
    numpy's partition, sort and three gathers cost more than a small leaf's
    distances).
    """
    if n == 1:  # argmin: the first of equal minima, i.e. the lower column
        columns = distances.argmin(axis=1)
        return columns[:, None], distances[np.arange(len(distances)), columns][:, None]
    return smallest_columns(np.ascontiguousarray(distances, dtype=np.float64), n)


def nearest_in_leaves(leaves, rank_leaf, n_neighbors, *, leaves_per_task=32, n_jobs=None):
    """k nearest neighbours of queries, ranking each leaf's queries together.

    Parameters
    ----------
    leaves : ndarray of shape (n_queries,)
        The leaf each query reached.
    rank_leaf : callable
        ``rank_leaf(leaf, rows) -> (distances, ids)`` of shape
        ``(len(rows), n_neighbors)`` for the queries ``rows`` of one leaf.
    n_neighbors : int
    leaves_per_task : int, default=32
        Leaves ranked per parallel task: fixed, so results do not depend on ``n_jobs``.
    n_jobs : int, default=None
        Number of jobs over the tasks.

    Returns
    -------
    distances, indices : ndarray of shape (n_queries, n_neighbors)
    """
    if len(leaves) == 1:  # one query: no grouping, no tasks, and no BLAS (compiled loops)
        return rank_leaf(leaves[0], np.zeros(1, dtype=np.intp))
    order = np.argsort(leaves, kind="stable")
    ordered = leaves[order]
    bounds = np.flatnonzero(np.concatenate(([True], ordered[1:] != ordered[:-1], [True])))
    groups = [(leaves[order[a]], order[a:b]) for a, b in zip(bounds[:-1], bounds[1:])]
    step = leaves_per_task
    tasks = [groups[i : i + step] for i in range(0, len(groups), step)]

    def rank(task):
        return [(rows, *rank_leaf(leaf, rows)) for leaf, rows in task]

    distances = np.empty((len(leaves), n_neighbors))
    indices = np.empty((len(leaves), n_neighbors), dtype=np.intp)
    with small_blas():
        ranked = parallel_map(rank, tasks, n_jobs=n_jobs)
    for part in ranked:
        for rows, dist, ind in part:
            distances[rows], indices[rows] = dist, ind
    return distances, indices
