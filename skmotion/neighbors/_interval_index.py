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
is empty). Only the first levels are materialised that way (as many as keep an
item in at most about 100 leaves: ``3 ** n_levels`` leaves per item at 7 levels
would be 2 x 10^9 stored pairs at 10^6 items): an item's entries at the deeper
levels are kept as its first and last entry per level, and a query's leaf of the
paper's tree is the materialised leaf's items filtered by them, so the candidate
sets are exactly the paper's. A leaf is named by one integer, the materialised
leaf times the number of entry combinations of the deeper levels plus the
query's combination. Leaf contents are kept as a few sorted blocks, each a CSR layout
(leaf ids, offsets, item ids) built from one insertion; blocks of similar size
are merged, so there are O(log n) of them and every step is vectorised. Queries
are vectorised over a batch: one ``searchsorted`` and one fancy index per level.
"""

import math
from bisect import bisect_right

import numpy as np

from skmotion.neighbors._leaf_kernels import filter_items

__all__ = ["IntervalIndex", "entry_edges", "tree_levels"]

_EMPTY = np.zeros(0, dtype=np.int32)
# Item-to-leaf pairs materialised per insertion step, to bound temporary memory.
_PAIRS_PER_STEP = 1 << 21
# Levels are materialised while an item's typical number of leaves stays within
# this (the rest are filtered at query time): 81 at 4 levels of 3 entries each.
_LEAVES_PER_ITEM = 100
# Entry combinations of the filtered levels, at most: leaf names must fit int64.
_MAX_DEEP_COMBINATIONS = 1 << 31


def tree_levels(edges, radius):
    """How many levels to materialise (see the module's docstring).

    An item's covering interval ``[c - r, c + r]`` meets about ``1 + 2 r / w``
    entries of width ``w``; levels are materialised while the product stays
    within ``_LEAVES_PER_ITEM`` (at least one), and more when the remaining
    levels have too many entry combinations to name a leaf by an int64.

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.neighbors._interval_index import tree_levels
    >>> tree_levels([np.arange(1.0, 10.0)] * 7, [1.0] * 7)  # 3 entries per item and level
    4
    """
    spans = []
    for e, r in zip(edges, radius):
        e = np.asarray(e, dtype=np.float64)
        if len(e) < 2:  # one or two entries: an item meets at most all of them
            spans.append(len(e) + 1)
        else:
            spans.append(min(len(e) + 1, 1 + 2 * float(r) / float(np.diff(e).min())))
    levels = max(1, int(np.searchsorted(np.cumprod(spans), _LEAVES_PER_ITEM, side="right")))
    n_entries = [len(e) + 1 for e in edges]
    while math.prod(n_entries[levels:]) >= _MAX_DEEP_COMBINATIONS:
        levels += 1
    return min(levels, len(edges))


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


def _entry_type(n_entries):
    """The smallest signed integer type holding entry numbers below each of ``n_entries``."""
    largest = max(n_entries, default=1) - 1
    return next(t for t in (np.int8, np.int16, np.int32) if largest <= np.iinfo(t).max)


def _expanded(span):
    """Row ``i`` repeated ``span[i]`` times, and the offsets ``0 .. span[i] - 1`` of the copies."""
    repeat = np.repeat(np.arange(len(span)), span)
    return repeat, np.arange(len(repeat)) - np.repeat(np.cumsum(span) - span, span)


def _appended(buffer, n_filled, rows):
    """``buffer`` with ``rows`` written after its first ``n_filled`` rows, grown by doubling."""
    need = n_filled + len(rows)
    if need > len(buffer):
        grown = np.empty((max(need, 2 * len(buffer)),) + buffer.shape[1:], dtype=buffer.dtype)
        grown[:n_filled] = buffer[:n_filled]
        buffer = grown
    buffer[n_filled:need] = rows
    return buffer


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
        self._n_tree = tree_levels(self.edges, self.radius)
        # Level 0 holds the dead node 0 and the root 1.
        self._tables = [
            np.zeros((2 if level == 0 else 1, n), dtype=np.int32)
            for level, n in enumerate(self.n_entries[: self._n_tree])
        ]
        self._n_nodes = [2] + [1] * (self._n_tree - 1)
        self._n_leaves = 1
        self._blocks = []  # (leaf ids, offsets, items), oldest (lowest item ids) first
        # The filtered levels: each item's first and last entry, and the radix of a leaf's name.
        deep_entries = self.n_entries[self._n_tree :]
        self._deep = np.zeros((0, 2, len(deep_entries)), dtype=_entry_type(deep_entries))
        self._stride = math.prod(self.n_entries[self._n_tree :])
        self._paper_pairs = 0
        self.n_items = 0

    def __setstate__(self, state):
        self.__dict__.update(state)
        if "_n_tree" not in state:  # pickled before the deeper levels were filtered
            self._n_tree, self._stride = self.n_levels, 1
            self._deep = np.zeros((self.n_items, 2, 0), dtype=np.int32)
            self._paper_pairs = int(sum(len(block[2]) for block in self._blocks))

    @property
    def n_levels(self):
        return len(self.edges)

    @property
    def n_nodes(self):
        """Number of nodes per level of the paper's tree (without the dead node), then of leaves.

        The levels that are filtered rather than materialised are counted by
        enumerating every item's leaves: as costly as building the paper's tree.
        """
        counts = [n - 1 for n in self._n_nodes] + [self._n_leaves - 1]
        if self._n_tree == self.n_levels or not self.n_items:
            return counts + [0] * (self.n_levels - self._n_tree)
        node = np.concatenate([np.repeat(b[0], np.diff(b[1])) for b in self._blocks])
        item = np.concatenate([b[2] for b in self._blocks]).astype(np.intp)
        node = node.astype(np.int64)
        for level in range(self.n_levels - self._n_tree):
            lo, hi = (self._deep[item, side, level].astype(np.intp) for side in (0, 1))
            span = hi - lo + 1
            repeat, offset = _expanded(span)
            item = item[repeat]
            entries = self.n_entries[self._n_tree + level]
            node = np.unique(node[repeat] * entries + lo[repeat] + offset, return_inverse=True)[1]
            counts.append(int(node.max()) + 1)
        return counts

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
            last_level = level == self._n_tree - 1
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
        """The (materialised leaf, item id) pairs of some items, creating missing nodes."""
        item = np.arange(len(ids))
        node = np.ones(len(ids), dtype=np.intp)
        for level in range(self._n_tree):
            lo, span = first[item, level], last[item, level] - first[item, level] + 1
            repeat, offset = _expanded(span)
            item, node = item[repeat], node[repeat]
            node = self._children(level, node, lo[repeat] + offset)
        return node.astype(np.int32), ids[item]

    @staticmethod
    def _block(leaf, items):
        """CSR block from (leaf, item) pairs, items increasing within a leaf.

        One in-place sort of ``leaf * base + item`` (int64): cheaper than a
        stable argsort and two gathers, and the same order.
        """
        base = int(items.max()) + 1 if len(items) else 1
        key = leaf.astype(np.int64) * base
        key += items
        key.sort()
        items = (key % base).astype(np.int32)
        key //= base  # now the leaves, in place
        starts = np.flatnonzero(np.r_[True, key[1:] != key[:-1]])
        return key[starts].astype(np.int32), np.r_[starts, len(key)].astype(np.int64), items

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
        spans = (last - first + 1).astype(np.float64)
        self._paper_pairs += int(np.prod(spans, axis=1).sum())
        # Each item lands in prod(span) materialised leaves: batch items to bound the pairs.
        n_leaves = np.prod(spans[:, : self._n_tree], axis=1)
        step = np.cumsum(n_leaves) // _PAIRS_PER_STEP
        pairs = [
            self._insert_batch(first[rows], last[rows], ids[rows])
            for rows in np.split(np.arange(len(ids)), np.flatnonzero(np.diff(step)) + 1)
        ]
        leaves, items = (np.concatenate(p) for p in zip(*pairs))
        del pairs  # the pieces: the sort's memory is the peak of a large insertion
        self._add_block(leaves, items)
        deep = np.stack([first[:, self._n_tree :], last[:, self._n_tree :]], axis=1)
        self._deep = _appended(self._deep, self.n_items, deep.astype(self._deep.dtype))
        self.n_items += len(ids)
        return ids.astype(np.intp)

    # -- queries -------------------------------------------------------------------

    def leaf_of(self, vectors):
        """The leaf each query reaches, one node per level (0: an empty leaf).

        Leaves are named by int64s: the materialised leaf times the number of
        entry combinations of the filtered levels, plus the query's combination
        (the materialised leaf itself when every level is materialised).
        """
        vectors = self._check(vectors)
        if len(vectors) == 1:
            return np.array([self._leaf_of_one(vectors[0].tolist())], dtype=np.int64)
        return self._leaf_of_batch(vectors)

    def _leaf_of_batch(self, vectors):
        entries = self.query_entries(vectors)
        node = np.ones(len(entries), dtype=np.int64)
        for level, table in enumerate(self._tables):
            node = table[node, entries[:, level]].astype(np.int64)
        for level in range(self._n_tree, self.n_levels):
            node = node * self.n_entries[level] + entries[:, level]
        return node

    def _leaf_of_one(self, vector):
        """The leaf of one query given as a list (``bisect_right`` = ``searchsorted`` right)."""
        node = 1
        for edges, table, value in zip(self._edge_lists, self._tables, vector):
            node = table.item(node, bisect_right(edges, value))
        for level in range(self._n_tree, self.n_levels):
            node = node * self.n_entries[level] + bisect_right(
                self._edge_lists[level], vector[level]
            )
        return node

    def _split_leaf(self, leaf):
        """(materialised leaf, entries of the filtered levels) of a leaf's name."""
        leaf, code = divmod(int(leaf), self._stride)
        entries = []
        for n in reversed(self.n_entries[self._n_tree :]):
            code, entry = divmod(code, n)
            entries.append(entry)
        return leaf, np.array(entries[::-1], dtype=self._deep.dtype)

    def _filtered(self, items, entries):
        """The items whose first and last entries hold ``entries`` at every filtered level."""
        if not len(entries) or not len(items):
            return items
        return filter_items(np.ascontiguousarray(items, dtype=np.int32), self._deep, entries)

    def leaf_items(self, leaf):
        """Sorted ids of the items in a leaf, as an ``int32`` array."""
        leaf, entries = self._split_leaf(leaf)
        return self._filtered(self._tree_leaf_items(leaf), entries)

    def _tree_leaf_items(self, leaf):
        """Sorted ids of the items in a materialised leaf."""
        parts = []
        # The leaf as the blocks' own int32: searchsorted with an int64 key would
        # first convert the whole block, work that grows with the collection.
        leaf = np.int32(leaf) if leaf < 2**31 else np.int32(-1)
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
        if self._stride > 1:
            return np.array([len(items) for items in self.items_of_leaves(leaves)], dtype=np.intp)
        sizes = np.zeros(len(leaves), dtype=np.intp)
        for start, end in self._leaf_bounds(leaves)[1]:
            sizes += end - start
        return sizes

    def items_of_leaves(self, leaves):
        """:meth:`leaf_items` of many leaves (as ``intp`` arrays), one look-up per block.

        Each block is searched once for all the leaves (one ``searchsorted``);
        what is left per leaf is a slice (or, after insertions, a concatenation
        of one slice per block, oldest block first: ids increase), filtered by
        the deeper levels when not every level is materialised.
        """
        if len(leaves) == 1:  # one query: a search per block costs less than the bounds
            return [self.leaf_items(leaves[0]).astype(np.intp)]
        if self._stride == 1:
            return self._tree_items_of_leaves(leaves)
        tree_leaves, codes = np.divmod(np.asarray(leaves, dtype=np.int64), self._stride)
        return [
            self._filtered(items, self._split_leaf(code)[1])
            for items, code in zip(self._tree_items_of_leaves(tree_leaves), codes.tolist())
        ]

    def _tree_items_of_leaves(self, leaves):
        """Sorted ids (``intp``) of the items of many materialised leaves."""
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
        """Memory held by the tree: node tables, leaf blocks and the filtered levels' entries."""
        tables = sum(t.nbytes for t in self._tables) + self._deep[: self.n_items].nbytes
        return tables + sum(a.nbytes for block in self._blocks for a in block)

    def n_stored(self):
        """Number of (leaf, item) pairs of the paper's tree, i.e. the total size of its leaves.

        The pairs held are fewer when not every level is materialised
        (:meth:`nbytes` is the memory).
        """
        return self._paper_pairs
