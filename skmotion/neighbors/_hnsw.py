"""faiss's HNSW graph for MotionMatcher: building it, and searching it with little around the call.

A single approximate query on a graph of 10^6 frames costs tens of
microseconds inside faiss; what a Python wrapper does around it (input
checks, conversions, faiss's own Python checks, allocating and reshaping the
answer) can cost as much again. :meth:`HnswSearch.one` keeps that to a few
microseconds for the common case of motion matching, one query row per call:
the graph's SWIG objects, the compiled search method and the query's buffer
are looked up or made once, the query is checked for NaN and inf by its
answer (a non-finite coordinate makes every distance non-finite, and faiss
then finds no neighbour) instead of by a pass over it beforehand, and the
answer is built by three array operations.
"""

import threading

import numpy as np

#: HNSW graph degree and construction beam (docs/motion-matching.md, "Choosing the
#: graph": on 2 x 10^5 frames degree 32 reached recall@1 0.99 at beam 16, degree 16
#: not even at beam 32).
HNSW_M, HNSW_EF_CONSTRUCTION = 32, 100


def faiss_module():
    """faiss, imported lazily, with the extra to install when it is missing."""
    try:
        import faiss
    except ImportError as exc:  # pragma: no cover - depends on the environment
        raise ImportError(
            "algorithm='hnsw' needs faiss: pip install 'skmotion[ann]' (or faiss-cpu)"
        ) from exc
    return faiss


def hnsw_index(data, threads=1):
    """faiss's HNSW graph of the rows, stored in cluster order; the order.

    The graph is built on the rows as given, then its vectors and links are
    renumbered so that rows of one k-means cluster (about ``ROWS_PER_CLUSTER``
    rows each) lie together in memory: a search walks from a row to rows
    near it, which then share cache lines and pages. On 968,573 frames of
    walks (380 MB of vectors and links) this cut faiss's search from 65.5 to
    49.8 µs of CPU per query at the same answers (docs/motion-matching.md).
    Graph row ``r`` is row ``order[r]`` of ``data``.

    By default on one thread: the same graph every time. More threads build it
    faster, but the graph may then depend on their timing (the benchmark uses
    two to save time; it is not an estimator parameter, as skmotion's
    ``n_jobs`` promises results identical to one job's). faiss's thread count
    is restored afterwards.
    """
    faiss = faiss_module()
    data = np.ascontiguousarray(data, dtype=np.float32)
    index = faiss.IndexHNSWFlat(data.shape[1], HNSW_M)
    index.hnsw.efConstruction = HNSW_EF_CONSTRUCTION
    previous = faiss.omp_get_max_threads()
    faiss.omp_set_num_threads(threads)
    try:
        index.add(data)
        order = cluster_order(data)
        index.permute_entries(order)
    finally:
        faiss.omp_set_num_threads(previous)
    return index, order


#: Rows per k-means cluster of the storage order: about 1,000 rows (380 kB of
#: vectors and links at 30 dimensions) fit the processor's second-level cache.
ROWS_PER_CLUSTER = 1000


def cluster_order(data):
    """Rows grouped by k-means cluster (faiss's, seeded), in their order within each.

    Fewer than two clusters' worth of rows keep their order.
    """
    n_clusters = len(data) // ROWS_PER_CLUSTER
    if n_clusters < 2:
        return np.arange(len(data), dtype=np.int64)
    faiss = faiss_module()
    # Trained on 64 rows per centroid: the order needs neighbourhoods, not exact centres.
    kmeans = faiss.Kmeans(data.shape[1], n_clusters, niter=8, seed=0, max_points_per_centroid=64)
    kmeans.train(data)
    _, cluster = kmeans.index.search(data, 1)
    return np.argsort(cluster[:, 0], kind="stable").astype(np.int64)


def faiss_search(index, X, k):
    """faiss's search of a batch without its Python wrapper's checks (done by the caller).

    Returns the distances (float32, Euclidean) and the rows, nearest first.
    """
    faiss = faiss_module()
    X = np.ascontiguousarray(X, dtype=np.float32)
    squared = np.empty((len(X), k), dtype=np.float32)
    rows = np.empty((len(X), k), dtype=np.int64)
    index.search_c(len(X), faiss.swig_ptr(X), k, faiss.swig_ptr(squared), faiss.swig_ptr(rows))
    np.maximum(squared, 0.0, out=squared)
    return np.sqrt(squared, out=squared), rows


class HnswSearch:
    """Searches of an HNSW graph, the answer labelled: a batch of queries, or one fast.

    Parameters
    ----------
    index : faiss.IndexHNSWFlat
    take, frame : ndarray of shape (n_indexed,)
        The labels of the indexed rows in the answer.

    Notes
    -----
    The search beam is written into the graph here alone, so that what is
    remembered of it is what the graph holds (it is the graph's, shared by
    every thread). :meth:`one` reuses a query buffer and answer buffers, with
    faiss's pointers to them, from call to call: fresh ones cost 3-5
    microseconds more per call (the allocations and SWIG's conversion of new
    pointers). They are kept per thread: faiss releases the GIL while it
    searches, so buffers shared between threads would let one overwrite
    another's query.
    """

    def __init__(self, index, take, frame):
        faiss = faiss_module()
        self.index = index
        self._take, self._frame = take, frame
        self._width, self._n = index.d, index.ntotal
        # Each attribute access on a SWIG proxy costs about a microsecond: once here.
        self._hnsw = index.hnsw
        self._search = index.search_c
        self._pointer = faiss.swig_ptr
        self._ef = None
        # Per thread, per k: the query and answer buffers, and faiss's pointers to them.
        self._buffers = threading.local()

    def _set_ef(self, ef):
        if ef != self._ef:
            # A SWIG attribute write costs microseconds: only when it changes.
            self._hnsw.efSearch = self._ef = ef

    def batch(self, X, k, ef):
        """Labels and distances of the ``k`` nearest rows of each query, ``(n_queries, k)``."""
        self._set_ef(max(ef, k))
        distance, rows = faiss_search(self.index, X, k)
        missing = rows[:, -1] < 0
        if missing.any():
            # faiss marks a neighbour it could not find by row -1, which would label it
            # with the last frame: a query whose every distance overflows float32 (the
            # graph searches in float32; NaN and inf are refused before) finds none.
            raise ValueError(
                f"query {int(np.flatnonzero(missing)[0])}: fewer than {k} neighbours found; "
                "its squared distances overflow float32 (values beyond about 1e19?)"
            )
        return self._take[rows], self._frame[rows], distance

    def one(self, row, n_neighbors, ef):
        """As :meth:`batch` for one query row, or None when it is not one or not found.

        The row must be a float ndarray of the index's width, of shape ``(d,)``
        or ``(1, d)``, and ``n_neighbors`` an int from 1 to the number of
        rows; anything else returns None for the caller's checked path. None
        also when faiss found fewer neighbours (a NaN or inf coordinate, or
        one too large for float32): the caller's checks and :meth:`batch`
        then name the problem.
        """
        k = n_neighbors
        if not (
            type(row) is np.ndarray
            and row.dtype.kind == "f"
            and row.size == self._width
            and (row.ndim == 1 or row.shape[0] == 1 and row.ndim == 2)
            and type(k) is int
            and 0 < k <= self._n
        ):
            return None
        self._set_ef(ef if ef >= k else k)
        buffers = self._buffers.__dict__.get(k)
        if buffers is None:
            buffers = self._buffers.__dict__[k] = self._new_buffers(k)
        query, squared, rows, pointers = buffers
        query[:] = row
        self._search(1, pointers[0], k, pointers[1], pointers[2])
        # faiss finds no neighbour (row -1) when every distance is NaN or overflows:
        # a NaN or inf coordinate, or one too large for float32. The last row, the
        # farthest, says for all; the batch's checks then name the query's problem.
        if rows[0, k - 1] < 0:
            return None
        # New arrays: the buffers are overwritten by the next call. (sqrt with out=
        # costs a microsecond more than a new array of one row.)
        return self._take[rows], self._frame[rows], np.sqrt(squared)

    def _new_buffers(self, k):
        query = np.empty((1, self.index.d), dtype=np.float32)
        squared = np.empty((1, k), dtype=np.float32)
        rows = np.empty((1, k), dtype=np.int64)
        return query, squared, rows, tuple(map(self._pointer, (query, squared, rows)))
