"""The interval index tree of Li & Prabhakaran: one level per feature component.

Level ``i`` of the tree cuts feature component ``i`` into entries (intervals).
An item (a feature vector) is inserted into *every* entry that overlaps its
covering interval ``[c_i - r_i, c_i + r_i]``, at every level, so it sits in many
leaves; a query follows the one entry that holds each of its components (one
node per level) and returns the items of the leaf it reaches. The leaf reached
by a query therefore holds exactly the items whose covering interval overlaps
the query's entry at every level.

This module knows nothing of sklearn or of motion: it stores integer ids of
vectors. Entries of one level are the same in every node of that level, so a
node is identified by the entries taken above it.

Layout: per level, a dense table ``child[node, entry] -> node of the next level``
(``int32``, grown by doubling), where node 0 is a dead end whose children are
all 0 and node 1 is the root; the last level's table points at leaves (leaf 0
is empty). Leaf contents are kept as a few sorted blocks, each a CSR layout
(leaf ids, offsets, item ids) built from one insertion; blocks of similar size
are merged, so there are O(log n) of them and every step is vectorised. Queries
are vectorised over a batch: one ``searchsorted`` and one fancy index per level.
"""

import math
from bisect import bisect_right

import numpy as np

__all__ = ["IntervalIndex", "entry_edges"]

_EMPTY = np.zeros(0, dtype=np.int32)
# Item-to-leaf pairs materialised per insertion step, to bound temporary memory.
_PAIRS_PER_STEP = 1 << 21


def entry_edges(low, high, width, max_entries):
    """Inner boundaries of the entries that cut ``[low, high]`` into width ``width``.

    There are ``ceil((high - low) / width)`` entries of width ``width``
    (the last may end past ``high``), at most ``max_entries``: when capped, the
    entries are widened to ``(high - low) / max_entries``. The first and last
    entries are open-ended, so every value falls in some entry.

    Parameters
    ----------
    low, high : float
        Range of the component over the indexed vectors.
    width : float
        Desired entry width (``epsilon * delta``); 0 asks for the finest entries.
    max_entries : int
        The most entries a node may have.

    Returns
    -------
    edges : ndarray of shape (n_entries - 1,)
        Increasing inner boundaries: entry ``j`` is ``[edges[j-1], edges[j]]``.

    Examples
    --------
    >>> from skmotion.neighbors._interval_index import entry_edges
    >>> entry_edges(0.0, 1.0, 0.3, 10).tolist()
    [0.3, 0.6, 0.9]
    >>> entry_edges(0.0, 1.0, 0.01, 4).tolist()
    [0.25, 0.5, 0.75]
    """
    span = float(high) - float(low)
    if not span > 0:
        return np.zeros(0)
    width = max(float(width), span / max_entries)
    n_entries = min(max_entries, max(1, math.ceil(span / width)))
    return low + width * np.arange(1, n_entries)


class IntervalIndex:
    """A tree of feature intervals; items may sit in many leaves.

    Parameters
    ----------
    edges : sequence of ndarray
        For each level, the increasing inner boundaries of its entries
        (see :func:`entry_edges`); level ``i`` indexes component ``i``.
    radius : array-like of shape (n_levels,)
        Half-width of an item's covering interval at each level
        (``epsilon * delta_i`` in the paper).

    Attributes
    ----------
    n_levels : int
    n_items : int
        Items inserted so far; their ids are ``0 .. n_items - 1``.

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.neighbors._interval_index import IntervalIndex
    >>> index = IntervalIndex([np.array([0.25, 0.5, 0.75])], radius=[0.1])
    >>> index.insert(np.array([[0.3], [0.45], [0.9]])).tolist()
    [0, 1, 2]
    >>> [c.tolist() for c in index.candidates(np.array([[0.2], [0.55], [0.8]]))]
    [[0], [1], [2]]
    >>> [c.tolist() for c in index.candidates(np.array([[0.4]]))]
    [[0, 1]]
    """

    def __init__(self, edges, radius):
        self.edges = [np.asarray(e, dtype=np.float64) for e in edges]
        self.radius = np.asarray(radius, dtype=np.float64)
        if self.radius.shape != (len(self.edges),) or (self.radius < 0).any():
            raise ValueError(
                f"radius must hold one non-negative value per level ({len(self.edges)})."
            )
        for level, e in enumerate(self.edges):
            if e.ndim != 1 or (np.diff(e) <= 0).any():
                raise ValueError(f"edges of level {level} must be a strictly increasing 1-D array.")
        self.n_entries = [len(e) + 1 for e in self.edges]
        self._edge_lists = [e.tolist() for e in self.edges]  # for bisect (one query)
        # Level 0 holds the dead node 0 and the root 1.
        self._tables = [
            np.zeros((2 if level == 0 else 1, n), dtype=np.int32)
            for level, n in enumerate(self.n_entries)
        ]
        self._n_nodes = [2] + [1] * (self.n_levels - 1)
        self._n_leaves = 1
        self._blocks = []  # (leaf ids, offsets, items), oldest (lowest item ids) first
        self.n_items = 0

    @property
    def n_levels(self):
        return len(self.edges)

    @property
    def n_nodes(self):
        """Number of nodes per level (without the dead node), then of leaves."""
        return [n - 1 for n in self._n_nodes] + [self._n_leaves - 1]

    # -- entries ---------------------------------------------------------------

    def _check(self, vectors):
        vectors = np.asarray(vectors, dtype=np.float64)
        if vectors.ndim != 2 or vectors.shape[1] < self.n_levels:
            raise ValueError(
                f"vectors must be 2-D with at least {self.n_levels} components (one per level); "
                f"got shape {vectors.shape}."
            )
        return vectors

    def query_entries(self, vectors):
        """The entry holding each component: ``(n_vectors, n_levels)`` ints.

        A value on a boundary belongs to the entry above it.
        """
        vectors = self._check(vectors)
        out = np.empty((len(vectors), self.n_levels), dtype=np.intp)
        for level, e in enumerate(self.edges):
            out[:, level] = np.searchsorted(e, vectors[:, level], side="right")
        return out

    def covering_entries(self, vectors):
        """First and last entries overlapping each covering interval.

        Returns two ``(n_vectors, n_levels)`` int arrays; entry ``j`` overlaps
        ``[c - r, c + r]`` when its closed interval meets it.
        """
        vectors = self._check(vectors)
        first = np.empty((len(vectors), self.n_levels), dtype=np.intp)
        last = np.empty_like(first)
        for level, (e, r) in enumerate(zip(self.edges, self.radius)):
            first[:, level] = np.searchsorted(e, vectors[:, level] - r, side="left")
            last[:, level] = np.searchsorted(e, vectors[:, level] + r, side="right")
        return first, last

    # -- insertion ---------------------------------------------------------------

    def _grow(self, level, n_rows):
        table = self._tables[level]
        if len(table) < n_rows:
            bigger = np.zeros((max(n_rows, 2 * len(table)), table.shape[1]), dtype=np.int32)
            bigger[: len(table)] = table
            self._tables[level] = bigger

    def _children(self, level, node, entry):
        """Children of (node, entry) pairs at ``level``, creating missing ones."""
        table = self._tables[level]
        child = table[node, entry]
        missing = child == 0
        if missing.any():
            n = table.shape[1]
            keys, inverse = np.unique(node[missing] * n + entry[missing], return_inverse=True)
            last_level = level == self.n_levels - 1
            start = self._n_leaves if last_level else self._n_nodes[level + 1]
            new = np.arange(start, start + len(keys), dtype=np.int32)
            table[keys // n, keys % n] = new
            if last_level:
                self._n_leaves += len(keys)
            else:
                self._n_nodes[level + 1] += len(keys)
                self._grow(level + 1, self._n_nodes[level + 1])
            child[missing] = new[inverse.ravel()]
        return child

    def _insert_batch(self, first, last, ids):
        item = np.arange(len(ids))
        node = np.ones(len(ids), dtype=np.intp)
        for level in range(self.n_levels):
            lo, span = first[item, level], last[item, level] - first[item, level] + 1
            repeat = np.repeat(np.arange(len(item)), span)
            offset = np.arange(len(repeat)) - np.repeat(np.cumsum(span) - span, span)
            item, node = item[repeat], node[repeat]
            node = self._children(level, node, lo[repeat] + offset)
        self._add_block(node, ids[item])

    @staticmethod
    def _block(leaf, items):
        """CSR block from (leaf, item) pairs; a stable sort keeps items increasing per leaf."""
        order = np.argsort(leaf, kind="stable")
        leaf, items = leaf[order], items[order]
        starts = np.flatnonzero(np.r_[True, leaf[1:] != leaf[:-1]])
        return (
            leaf[starts].astype(np.int32),
            np.r_[starts, len(leaf)].astype(np.int64),
            items.astype(np.int32),
        )

    def _add_block(self, leaf, items):
        self._blocks.append(self._block(leaf, items))
        # Merge while the newer block is at least half the older one: sizes then
        # halve along the list, so there are O(log n) blocks and each pair is
        # copied O(log n) times.
        while len(self._blocks) > 1 and 2 * len(self._blocks[-1][2]) >= len(self._blocks[-2][2]):
            newer, older = self._blocks.pop(), self._blocks.pop()
            leaves = np.concatenate([np.repeat(b[0], np.diff(b[1])) for b in (older, newer)])
            self._blocks.append(self._block(leaves, np.concatenate([older[2], newer[2]])))

    def insert(self, vectors):
        """Insert vectors; each goes into every leaf its covering intervals reach.

        Parameters
        ----------
        vectors : array-like of shape (n_vectors, >= n_levels)
            Component ``i`` is indexed at level ``i``; further columns are ignored.

        Returns
        -------
        ids : ndarray of shape (n_vectors,)
            The ids given to the vectors, continuing from earlier insertions.
        """
        first, last = self.covering_entries(vectors)
        ids = np.arange(self.n_items, self.n_items + len(first), dtype=np.int32)
        if not len(ids):
            return ids.astype(np.intp)
        # Each item lands in prod(span) leaves: batch items so that the pairs stay bounded.
        n_leaves = np.prod((last - first + 1).astype(np.float64), axis=1)
        step = np.cumsum(n_leaves) // _PAIRS_PER_STEP
        for rows in np.split(np.arange(len(ids)), np.flatnonzero(np.diff(step)) + 1):
            self._insert_batch(first[rows], last[rows], ids[rows])
        self.n_items += len(ids)
        return ids.astype(np.intp)

    # -- queries -------------------------------------------------------------------

    def leaf_of(self, vectors):
        """The leaf each query reaches, one node per level (0: an empty leaf)."""
        vectors = self._check(vectors)
        if len(vectors) == 1:
            return np.array([self._leaf_of_one(vectors[0].tolist())], dtype=np.intp)
        return self._leaf_of_batch(vectors)

    def _leaf_of_batch(self, vectors):
        entries = self.query_entries(vectors)
        node = np.ones(len(entries), dtype=np.intp)
        for level, table in enumerate(self._tables):
            node = table[node, entries[:, level]]
        return node

    def _leaf_of_one(self, vector):
        """The leaf of one query given as a list (``bisect_right`` = ``searchsorted`` right)."""
        node = 1
        for edges, table, value in zip(self._edge_lists, self._tables, vector):
            node = table.item(node, bisect_right(edges, value))
        return node

    def leaf_items(self, leaf):
        """Sorted ids of the items in a leaf, as an ``int32`` array."""
        parts = []
        # The leaf as the blocks' own int32: searchsorted with an int64 key would
        # first convert the whole block, work that grows with the collection.
        leaf = np.int32(leaf)
        for leaves, offsets, items in self._blocks:
            at = np.searchsorted(leaves, leaf)
            if at < len(leaves) and leaves[at] == leaf:
                parts.append(items[offsets[at] : offsets[at + 1]])
        if len(parts) == 1:
            return parts[0]
        return np.concatenate(parts) if parts else _EMPTY

    def candidates(self, vectors):
        """For each query, the sorted ids of the items in the leaf it reaches."""
        return self.items_of_leaves(self.leaf_of(vectors))

    def _leaf_bounds(self, leaves):
        """The non-empty blocks, and per block where each leaf's items start and end."""
        # The blocks' own int32 (see leaf_items): no conversion of the blocks.
        leaves = np.asarray(leaves).astype(np.int32)
        blocks = [block for block in self._blocks if len(block[0])]
        bounds = []
        for block_leaves, offsets, _ in blocks:
            at = np.searchsorted(block_leaves, leaves)
            inside = np.minimum(at, len(block_leaves) - 1)
            hit = (at < len(block_leaves)) & (block_leaves[inside] == leaves)
            start = np.where(hit, offsets[inside], 0)
            bounds.append((start, np.where(hit, offsets[inside + hit], 0)))
        return blocks, bounds

    def leaf_sizes(self, leaves):
        """How many items each leaf holds (``len(leaf_items(leaf))``, for many leaves at once)."""
        sizes = np.zeros(len(leaves), dtype=np.intp)
        for start, end in self._leaf_bounds(leaves)[1]:
            sizes += end - start
        return sizes

    def items_of_leaves(self, leaves):
        """:meth:`leaf_items` of many leaves (as ``intp`` arrays), one look-up per block.

        Each block is searched once for all the leaves (one ``searchsorted``);
        what is left per leaf is a slice (or, after insertions, a concatenation
        of one slice per block, oldest block first: ids increase).
        """
        if len(leaves) == 1:  # one query: a search per block costs less than the bounds
            return [self.leaf_items(leaves[0]).astype(np.intp)]
        blocks, bounds = self._leaf_bounds(leaves)
        bounds = [(start.tolist(), end.tolist()) for start, end in bounds]
        if len(blocks) == 1:
            items = blocks[0][2]
            return [items[a:b].astype(np.intp) for a, b in zip(*bounds[0])]
        return [
            np.concatenate(
                [_EMPTY] + [block[2][b[0][q] : b[1][q]] for block, b in zip(blocks, bounds)]
            ).astype(np.intp)
            for q in range(len(leaves))
        ]

    def nbytes(self):
        """Memory held by the tree: node tables and leaf blocks."""
        tables = sum(t.nbytes for t in self._tables)
        return tables + sum(a.nbytes for block in self._blocks for a in block)

    def n_stored(self):
        """Number of (leaf, item) pairs, i.e. the total size of the leaves."""
        return int(sum(len(block[2]) for block in self._blocks))
