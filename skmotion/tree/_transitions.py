"""Node transition graphs: per-layer transition counts and smoothed probabilities.

A graph counts the transitions ``t(m, n)`` between the nodes of consecutive
frames of the same clip (paper section III-C). The probabilities are Lidstone
(additive) smoothed, so an unseen transition is never ``log(0)``: ``s``
pseudo-transitions per row (the ``smoothing``) are spread evenly over the ``K``
nodes of the layer::

    p(m -> n) = (t(m, n) + s / K) / (sum_k t(m, k) + s)

Every row sums to 1; a transition never seen has exactly the smoothing mass
``(s / K) / (T_m + s)`` of its row (``T_m`` the row's count), and a node never
left in the data (seen only at the ends of clips) has the uniform row ``1 / K``.
As ``s`` is a total per row, its weight against the data does not change with
the number of nodes of a layer. Several graphs (one per class or
per clip) are kept side by side: graph ``g`` of layer ``l`` is rows
``g K .. (g + 1) K - 1`` of one sparse count matrix.
"""

from numbers import Real

import numpy as np
import scipy.sparse as sp

from skmotion.base import VersionedStateMixin

__all__ = ["TransitionGraphs", "count_database_graphs"]

# Graphs whose dense table (n_graphs * K * K) is at most this many entries keep
# one, so lookups are one gather instead of a binary search.
_DENSE_LIMIT = 1 << 21


class TransitionGraphs(VersionedStateMixin):
    """Transition counts of one or more graphs at every layer of a motion tree.

    Build with :meth:`count`. Graph ``g`` is the graph of the clips assigned to
    it (all clips for the global graph, one class's clips, or a single clip).

    Parameters
    ----------
    counts : list of scipy.sparse.csr_matrix
        Per layer, the counts of shape ``(n_graphs * K_l, K_l)``.
    visits : list of ndarray of shape (n_graphs, K_l)
        Per layer, how many frames of each graph's clips fall in each node.
    smoothing : float
        Pseudo-transitions per row, ``s`` (> 0).

    Attributes
    ----------
    n_graphs : int
    n_layers : int
    smoothing : float

    Notes
    -----
    A pickle records the skmotion version; loading it into an incompatible
    version raises :class:`~skmotion.base.IncompatibleVersionError`.

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.tree import TransitionGraphs
    >>> labels = [np.array([0, 0, 1, 1, 0])]         # one layer, one clip of 5 frames
    >>> g = TransitionGraphs.count(labels, [2], offsets=[0, 5], graph_of_clip=[0], smoothing=1.0)
    >>> g.counts(0, 0).toarray().tolist()
    [[1, 1], [1, 1]]
    >>> g.matrix(0, 0).tolist()                        # (1 + 1 / 2) / (2 + 1)
    [[0.5, 0.5], [0.5, 0.5]]
    """

    def __init__(self, counts, visits, smoothing):
        if not isinstance(smoothing, Real) or not smoothing > 0:
            raise ValueError(f"smoothing must be a positive number; got {smoothing!r}.")
        self.smoothing = float(smoothing)
        self._counts = [sp.csr_matrix(c, dtype=np.int64) for c in counts]
        for c in self._counts:
            c.sort_indices()
        self._visits = [np.asarray(v, dtype=np.int64) for v in visits]
        self.n_layers = len(self._counts)
        self.n_graphs = len(self._visits[0]) if self.n_layers else 0
        self._totals = [
            np.asarray(c.sum(axis=1)).ravel().reshape(self.n_graphs, -1) for c in self._counts
        ]
        self._dense = [self._dense_log(layer) for layer in range(self.n_layers)]
        self._keys = [
            None if d is not None else self._sorted_keys(layer)
            for layer, d in enumerate(self._dense)
        ]

    @classmethod
    def count(cls, layer_labels, n_nodes, *, offsets, graph_of_clip, n_graphs=None, smoothing=1.0):
        """Count the transitions of clips whose frames carry node labels.

        Parameters
        ----------
        layer_labels : iterable of ndarray of shape (n_frames,)
            Per layer, the node (layer index) of every frame, clip after clip.
        n_nodes : sequence of int
            Number of nodes of each layer.
        offsets : array-like of int of shape (n_clips + 1,)
            Clip ``i`` is frames ``offsets[i]:offsets[i + 1]``.
        graph_of_clip : array-like of int of shape (n_clips,)
            The graph each clip belongs to.
        n_graphs : int, default=None
            Number of graphs; ``max(graph_of_clip) + 1`` by default.
        smoothing : float, default=1.0
            Pseudo-transitions per row, spread evenly over the nodes.

        Returns
        -------
        graphs : TransitionGraphs
        """
        offsets = np.asarray(offsets, dtype=np.intp)
        graph_of_clip = np.asarray(graph_of_clip, dtype=np.intp)
        if n_graphs is None:
            n_graphs = int(graph_of_clip.max()) + 1
        lengths = np.diff(offsets)
        graph_of_frame = np.repeat(graph_of_clip, lengths)
        # A transition joins frame j to j + 1 unless j is the last frame of its clip.
        step = np.ones(offsets[-1], dtype=bool)
        step[offsets[1:] - 1] = False
        src_frames = np.flatnonzero(step)
        counts, visits = [], []
        for labels, k in zip(layer_labels, n_nodes):
            labels = np.asarray(labels, dtype=np.intp)
            rows = graph_of_frame[src_frames] * k + labels[src_frames]
            data = np.ones(len(rows), dtype=np.int64)
            counts.append(
                sp.csr_matrix((data, (rows, labels[src_frames + 1])), shape=(n_graphs * k, k))
            )
            visits.append(
                np.bincount(graph_of_frame * k + labels, minlength=n_graphs * k).reshape(
                    n_graphs, k
                )
            )
        return cls(counts, visits, smoothing)

    def _dense_log(self, layer):
        """The log table ``(K + 1, K + 1, n_graphs)``, flat; index ``K`` is "no node" (-inf).

        Graphs last, so the probabilities of one transition in every graph are
        contiguous.
        """
        k = self.n_nodes(layer)
        if self.n_graphs * (k + 1) ** 2 > _DENSE_LIMIT:
            return None
        table = np.zeros((self.n_graphs, k + 1, k + 1))
        table[:, :k, :k] = self._counts[layer].toarray().reshape(self.n_graphs, k, k)
        table += self.pseudo_count(layer)
        with np.errstate(divide="ignore"):
            table[:, :k, :k] /= (self._totals[layer] + self.smoothing)[:, :, None]
            table = np.log(table)
        table[:, k, :] = -np.inf
        table[:, :, k] = -np.inf
        return np.ascontiguousarray(table.transpose(1, 2, 0)).ravel()

    def _sorted_keys(self, layer):
        """Flat index in the ``(n_graphs, K + 1, K + 1)`` table of every stored count,
        increasing."""
        csr = self._counts[layer]
        k = csr.shape[1]
        rows = np.repeat(np.arange(csr.shape[0], dtype=np.int64), np.diff(csr.indptr))
        graph, src = np.divmod(rows, k)
        return (graph * (k + 1) + src) * (k + 1) + csr.indices

    def stacked_counts(self, layer):
        """The counts of every graph of a layer, one sparse ``(n_graphs * K, K)`` matrix.

        Graph ``g`` is rows ``g K .. (g + 1) K - 1``; indices sorted within rows.
        """
        return self._counts[layer]

    def log_table(self, layer):
        """The flat ``(K + 1, K + 1, n_graphs)`` table of ``log p(src -> dst)``, or None.

        Index ``K`` is "no node" (-inf); the graphs are last, so one transition's
        values in every graph are contiguous. None when the table would exceed
        ``2**21`` entries (``log_prob`` then looks the counts up).
        """
        return self._dense[layer]

    def n_nodes(self, layer):
        """Number of nodes of a layer."""
        return self._counts[layer].shape[1]

    def counts(self, layer, graph):
        """The transition counts of one graph, a sparse ``(K, K)`` matrix."""
        k = self.n_nodes(layer)
        return self._counts[layer][graph * k : (graph + 1) * k]

    def row_totals(self, layer):
        """Transitions leaving each node, ``(n_graphs, K)``."""
        return self._totals[layer]

    def visits(self, layer):
        """Frames of each graph's clips in each node, ``(n_graphs, K)``."""
        return self._visits[layer]

    def pseudo_count(self, layer):
        """The pseudo-count added to every transition of a layer, ``smoothing / K``."""
        return self.smoothing / self.n_nodes(layer)

    def unseen_probability(self, layer):
        """The probability of a never-seen transition in each row, ``(n_graphs, K)``."""
        return self.pseudo_count(layer) / (self._totals[layer] + self.smoothing)

    def log_prob(self, layer, graph, src, dst):
        """``log p(src -> dst)`` in a graph, for broadcastable index arrays.

        Parameters
        ----------
        layer : int
        graph, src, dst : array-like of int
            Graph and node indices (broadcast together). A node index that is
            negative or equal to the number of nodes ``K`` means "no node" and
            gives ``-inf``.

        Returns
        -------
        log_p : ndarray
        """
        k = self.n_nodes(layer)
        src, dst = (np.asarray(a, dtype=np.intp) for a in (src, dst))
        src, dst = (np.where(a < 0, k, a) if a.size and a.min() < 0 else a for a in (src, dst))
        graph = np.asarray(graph, dtype=np.intp)
        if self._dense[layer] is not None:
            return self._dense[layer].take((src * (k + 1) + dst) * self.n_graphs + graph)
        row = graph * (k + 1) + src
        flat = row * (k + 1) + dst
        keys, data = self._keys[layer], self._counts[layer].data
        t = np.zeros(flat.shape)
        if len(keys):
            pos = np.minimum(np.searchsorted(keys, flat), len(keys) - 1)
            t = np.where(keys[pos] == flat, data[pos], 0)
        totals = np.append(self._totals[layer], np.zeros((self.n_graphs, 1)), axis=1).ravel()
        with np.errstate(divide="ignore"):
            out = np.log((t + self.pseudo_count(layer)) / (totals.take(row) + self.smoothing))
        out[np.broadcast_to((src == k) | (dst == k), out.shape)] = -np.inf
        return out

    def matrix(self, layer, graph):
        """The dense ``(K, K)`` transition probabilities of one graph (small layers)."""
        table = self.counts(layer, graph).toarray().astype(np.float64) + self.pseudo_count(layer)
        return table / (self._totals[layer][graph] + self.smoothing)[:, None]

    def propagate(self, layer, graph, distribution, n_steps=1):
        """A node distribution after ``n_steps`` transitions: ``distribution @ P ** n_steps``.

        Uses the sparse counts: ``P = diag(1 / (T + s)) C + u 1^T`` with
        ``u`` the unseen probability of each row, so no dense ``K x K`` matrix is formed.

        Parameters
        ----------
        layer, graph : int
        distribution : ndarray of shape (..., K)
            Probabilities over the nodes of the layer (rows sum to 1).
        n_steps : int, default=1

        Returns
        -------
        distribution : ndarray of shape (..., K)
        """
        counts = self.counts(layer, graph)
        scale = 1.0 / (self._totals[layer][graph] + self.smoothing)
        unseen = self.pseudo_count(layer) * scale
        out = np.asarray(distribution, dtype=np.float64)
        for _ in range(n_steps):
            out = np.asarray((counts.T @ (out * scale).T).T) + (out @ unseen)[..., None]
        return out

    def count_matrix(self, layer):
        """All graphs' counts at a layer: a sparse ``(n_graphs * K, K)`` matrix, graph by graph."""
        return self._counts[layer]


def count_database_graphs(tree, labels, offsets, y_index, *, n_classes, per_clip, smoothing):
    """A motion database's graphs from its routed frames: the global graph and the classifying ones.

    Parameters
    ----------
    tree : MotionTree
    labels : list of ndarray
        Per layer, the node of every frame (``tree.iter_apply`` of the stacked clips).
    offsets : ndarray of shape (n_clips + 1,)
    y_index : ndarray of shape (n_clips,)
        Each clip's class, an index below ``n_classes``.
    n_classes : int
    per_clip : bool
        One classifying graph per clip; else one per class.
    smoothing : float

    Returns
    -------
    global_graph : TransitionGraphs
        One graph of all clips.
    graphs : TransitionGraphs
        One graph per class, or per clip.
    graph_classes : ndarray of shape (n_graphs,)
        The class of each graph of ``graphs``.
    """
    n_clips = len(offsets) - 1
    global_graph = TransitionGraphs.count(
        labels,
        tree.n_nodes,
        offsets=offsets,
        graph_of_clip=np.zeros(n_clips, dtype=np.intp),
        n_graphs=1,
        smoothing=smoothing,
    )
    if per_clip:
        graph_of_clip, graph_classes = np.arange(n_clips), y_index
    else:
        graph_of_clip, graph_classes = y_index, np.arange(n_classes)
    graphs = TransitionGraphs.count(
        labels,
        tree.n_nodes,
        offsets=offsets,
        graph_of_clip=graph_of_clip,
        n_graphs=len(graph_classes),
        smoothing=smoothing,
    )
    return global_graph, graphs, graph_classes
