"""An interval index split into shards on Dask workers, answering as one index.

The layout of the tree (SVD projection, entry widths, entries) depends on all
the training clips, but only through small per-clip summaries: the leading
singular vectors and values, then one feature vector per clip. So the workers
decompose their shard's clips and keep the psi signatures; the client gathers
the summaries, learns the layout exactly as one :class:`IntervalIndexNeighbors`
would, and each worker builds its shard's tree with that layout. A query's
features are computed once, broadcast to the shards, and each shard returns
its candidates and its nearest ones among them; the client merges them.
Because a clip's leaves depend only on its own feature vector and the layout,
the union of the shards' candidates is the single index's candidate set, and
the merged neighbours are the single index's neighbours.
"""

import numpy as np
from sklearn.base import clone

from skmotion.decomposition._svd_projection import N_VECTORS, fit_svd_projection, svd_project
from skmotion.neighbors._index_features import clip_level_limit, index_spectra
from skmotion.neighbors._interval_index import IntervalIndex
from skmotion.neighbors._interval_neighbors import IntervalIndexNeighbors
from skmotion.neighbors._psi import signatures_from_spectra
from skmotion.neighbors._ranking import nearest_in_leaves, psi_distance_block, smallest_k
from skmotion.utils._clips import check_clips

__all__ = ["ShardedIntervalIndex"]


def _spectra(clips, weighting, k):
    """On a worker: a shard's spectra (kept there) ..."""
    return index_spectra(check_clips(clips), weighting, k)


def _summary(spectra, n_vectors):
    """... and what the layout needs of them (sent to the client)."""
    eigenvalues, vectors = spectra
    return eigenvalues, vectors[:, :, :n_vectors]


class _Shard:
    """A worker's part: a tree over its clips (global ids from ``offset``), their signatures."""

    def __init__(self, spectra, tree_features, edges, radius, k, offset):
        self.index = IntervalIndex(edges, radius)
        self.index.insert(tree_features)
        self.weights, self.vectors = signatures_from_spectra(*spectra, k)
        self.offset = offset

    def _distances(self, query, rows, columns):
        return psi_distance_block(query, (self.weights, self.vectors), rows, columns)

    def candidates(self, tree):
        return [c + self.offset for c in self.index.candidates(tree)]

    def nearest(self, payload, n_neighbors, everything=None):
        """Candidate counts, and (distances, global ids) of each query's nearest candidates.

        ``payload`` is the queries' (tree features, signatures). Queries flagged
        in ``everything`` are ranked against all this shard's clips instead (the
        single index's rule when a leaf holds too few clips). Rows with fewer
        clips than ``n_neighbors`` are padded with infinite distances.
        """
        tree, query = payload
        n = len(self.weights)
        leaves = self.index.leaf_of(tree)
        counts = self.index.leaf_sizes(leaves)
        if everything is None:
            everything = np.zeros(len(tree), dtype=bool)

        def rank_leaf(leaf, rows):
            out_d = np.full((len(rows), n_neighbors), np.inf)
            out_i = np.full((len(rows), n_neighbors), -1, dtype=np.intp)
            for part, columns in (
                (rows[~everything[rows]], self.index.leaf_items(leaf).astype(np.intp)),
                (rows[everything[rows]], np.arange(n)),
            ):
                if not len(part) or not len(columns):
                    continue
                chosen, dist = smallest_k(
                    self._distances(query, part, columns), min(n_neighbors, len(columns))
                )
                at = np.searchsorted(rows, part)
                out_d[at, : dist.shape[1]] = dist
                out_i[at, : dist.shape[1]] = columns[chosen] + self.offset
            return out_d, out_i

        # nearest_in_leaves ranks rows grouped by leaf, rows sorted within a leaf.
        return (counts, *nearest_in_leaves(leaves, rank_leaf, n_neighbors))


def _wait(futures):
    try:
        from distributed import wait
    except ImportError as exc:  # the client came from somewhere: say what is missing
        raise ImportError(
            'ShardedIntervalIndex needs Dask: pip install "skmotion[distributed]".'
        ) from exc
    wait(futures)


def _call(shard, method, *args):
    return getattr(shard, method)(*args)


class ShardedIntervalIndex:
    """An :class:`IntervalIndexNeighbors` whose clips are split over Dask workers.

    Fitting decomposes each shard's clips on a worker, learns the tree's layout
    on the client from the clips' small summaries (exactly as the single index
    would), and builds one tree per shard on its worker; the psi signatures
    stay there. Queries are decomposed once on the client, broadcast, and the
    shards' candidates and neighbours merged: the answers equal those of
    ``IntervalIndexNeighbors`` with the same parameters fitted on all clips.

    Needs the ``distributed`` extra (``pip install "skmotion[distributed]"``).

    Parameters
    ----------
    estimator : IntervalIndexNeighbors, default=None
        The parameters (cloned); ``similar="psi"`` is not supported (it would
        compare every pair of clips across shards), nor ``axes="discriminant"``.
        None means the defaults.
    client : distributed.Client
        The Dask client whose workers hold the shards.
    n_shards : int, default=None
        Number of shards; None means one per worker.

    Attributes
    ----------
    layout_ : IntervalIndexNeighbors
        Holds the learned layout: ``n_levels_``, ``projection_``, ``radius_``,
        ``delta_``, ``classes_`` (but no stored clips).
    shards_ : list of distributed.Future
        The shards, on the workers.
    labels_ : ndarray of shape (n_samples_fit_,)
    n_samples_fit_ : int

    Examples
    --------
    See ``docs/similarity-search.md`` (a ``LocalCluster`` on loopback).
    """

    def __init__(self, estimator=None, *, client, n_shards=None):
        self.estimator = estimator
        self.client = client
        self.n_shards = n_shards

    def fit(self, X, y):
        """Decompose the shards on the workers, learn the layout, build the shards' trees."""
        layout = clone(IntervalIndexNeighbors() if self.estimator is None else self.estimator)
        if layout.similar == "psi":
            raise ValueError('ShardedIntervalIndex supports similar="labels" only.')
        if layout.axes != "svd":
            raise ValueError('ShardedIntervalIndex supports axes="svd" only.')
        clips = check_clips(X, estimator=layout, reset=True)
        y = layout._check_labels(y, len(clips))
        weighting = layout._weighting()
        workers = sorted(self.client.scheduler_info()["workers"])
        n_shards = self.n_shards or len(workers)
        bounds = np.linspace(0, len(clips), n_shards + 1).astype(int)
        parts = [list(clips[a:b]) for a, b in zip(bounds[:-1], bounds[1:])]
        # Shard i lives on worker i (modulo their number), and is built where its
        # spectra are: the shards of one query batch then rank in parallel.
        where = [{"workers": [workers[i % len(workers)]]} for i in range(n_shards)]
        spectra = [
            self.client.submit(_spectra, p, weighting, layout.k, **w) for p, w in zip(parts, where)
        ]
        summaries = self.client.gather(
            [self.client.submit(_summary, s, N_VECTORS[weighting]) for s in spectra]
        )
        eigenvalues = np.concatenate([s[0] for s in summaries])
        vectors = np.concatenate([s[1] for s in summaries])
        layout.n_levels_ = layout._resolve_levels(*clip_level_limit(clips, weighting))
        layout.projection_ = fit_svd_projection(eigenvalues, vectors, layout.n_levels_, weighting)
        tree = svd_project(layout.projection_, eigenvalues, vectors)
        layout.input_kind_, layout.effective_metric_ = "clips", "psi"
        layout.classes_ = np.unique(y)
        edges, radius = layout._layout(tree, np.searchsorted(layout.classes_, y), None)
        self.shards_ = [
            self.client.submit(_Shard, s, tree[a:b], edges, radius, layout.k, a, **w)
            for s, a, b, w in zip(spectra, bounds[:-1], bounds[1:], where)
        ]
        _wait(self.shards_)  # until built (the shards stay on the workers)
        self.layout_, self.labels_, self.n_samples_fit_ = layout, np.asarray(y), len(clips)
        return self

    def _query(self, X):
        layout = self.layout_
        clips = check_clips(X, estimator=layout)
        spectra = index_spectra(clips, layout._weighting(), layout.k)
        return svd_project(layout.projection_, *spectra), signatures_from_spectra(
            *spectra, layout.k
        )

    def _each(self, method, *args):
        futures = [self.client.submit(_call, s, method, *args, pure=False) for s in self.shards_]
        return self.client.gather(futures)

    def candidates(self, X):
        """Each query's candidate ids (sorted), as :meth:`IntervalIndexNeighbors.candidates`."""
        tree = self._query(X)[0]
        parts = self._each("candidates", tree)
        return [np.sort(np.concatenate(c)) for c in zip(*parts)]

    def kneighbors(self, X, n_neighbors=None, return_distance=True):
        """The nearest stored clips, as :meth:`IntervalIndexNeighbors.kneighbors` gives them."""
        n_neighbors = self.layout_.n_neighbors if n_neighbors is None else n_neighbors
        if not 1 <= n_neighbors <= self.n_samples_fit_:
            raise ValueError(
                f"n_neighbors must be an integer from 1 to {self.n_samples_fit_}; "
                f"got {n_neighbors!r}."
            )
        # The queries' features go with the tasks (a few hundred kB for hundreds
        # of queries): a scatter first would cost the scheduler another round trip.
        payload = self._query(X)
        parts = self._each("nearest", payload, n_neighbors)
        everything = sum(p[0] for p in parts) < n_neighbors
        if everything.any():  # a second round only for queries whose leaves hold too few
            again = self._each("nearest", payload, n_neighbors, everything)
            parts = [
                (
                    c,
                    np.where(everything[:, None], a[1], p[1]),
                    np.where(everything[:, None], a[2], p[2]),
                )
                for c, p, a in zip((p[0] for p in parts), parts, again)
            ]
        distances = np.concatenate([p[1] for p in parts], axis=1)
        ids = np.concatenate([p[2] for p in parts], axis=1)
        # By distance, then by id: the single index's order.
        order = np.lexsort((ids, distances), axis=1)[:, :n_neighbors]
        ids = np.take_along_axis(ids, order, axis=1)
        distances = np.take_along_axis(distances, order, axis=1)
        return (distances, ids) if return_distance else ids
