"""Routing frames down a motion tree: every layer's node of every frame in one pass over the layers.

:class:`TreeRouter` folds a standardisation into the split axes and thresholds,
so raw frames are routed without a standardised copy, and walks all frames of
a collection down the tree together: one step per layer, none per clip or frame.
A step compares each frame's projection on its node's split axis with the
threshold. The axes of all layers with few split nodes are applied in one
product (one read of the frames); a deeper layer gathers each frame's own
axis (a product would do work for every node).
"""

import numpy as np

from skmotion.tree._encoding._walk import walk_layers

__all__ = ["TreeRouter"]

# Split nodes of a layer up to which all frames are projected on all of its axes at once:
# beyond it the per-frame gather costs less than the product's extra columns.
_DENSE_LIMIT = 24
_CHUNK = 1 << 15  # frames per block: bounds the (frames x axes) product's memory


class TreeRouter:
    """Route frames through a :class:`MotionTree`'s splits, all layers at once.

    Parameters
    ----------
    tree : MotionTree
        The tree, built on frames ``(x - center) / scale``.
    center, scale : ndarray of shape (n_channels,), default=None
        The standardisation the tree was built under (none by default).

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.tree import MotionTree
    >>> from skmotion.tree._encoding import TreeRouter
    >>> rng = np.random.default_rng(0)
    >>> frames = rng.normal(size=(500, 4))
    >>> tree = MotionTree.build(frames, max_depth=4, split="median")
    >>> nodes = TreeRouter(tree).route(frames)
    >>> nodes.shape, all((nodes[:, l] == tree.apply(frames, l)).all() for l in range(5))
    ((500, 5), True)
    """

    def __init__(self, tree, center=None, scale=None):
        n_channels = tree.n_channels
        center = np.zeros(n_channels) if center is None else np.asarray(center, float)
        scale = np.ones(n_channels) if scale is None else np.asarray(scale, float)
        # (x - c) / s @ a > t  <=>  x @ (a / s) > t + c @ (a / s)
        self.axis = np.ascontiguousarray(tree.axis / scale)
        self.threshold = np.nan_to_num(tree.threshold, nan=0.0) + self.axis @ center
        self.left, self.right = tree.left, tree.right
        self.n_layers = tree.n_layers
        self.n_nodes = tree.n_nodes
        # layer index of each tree node in each layer (-1 where it is absent)
        self.layer_index = np.full((tree.n_layers, tree.n_tree_nodes), -1, dtype=np.intp)
        for layer, ids in enumerate(tree.layers):
            self.layer_index[layer, ids] = np.arange(len(ids))
        self.split_ids = [ids[tree.left[ids] >= 0] for ids in tree.layers]
        self._derive()

    def _derive(self):
        """The lookup tables of a step, from the splits (also for a router pickled without them)."""
        # the child on each side, a leaf being its own (copied down): one step is then a
        # choice between two lookups for every frame
        own = np.arange(len(self.left))
        self.left_or_self = np.where(self.left >= 0, self.left, own)
        self.right_or_self = np.where(self.right >= 0, self.right, own)
        # layers whose split axes go into the one product (see _route_block)
        self.in_product = np.array([0 < len(ids) <= _DENSE_LIMIT for ids in self.split_ids])
        # layers walked through the product's columns: those in it, and those without splits
        self.walkable = np.array([len(ids) <= _DENSE_LIMIT for ids in self.split_ids], np.uint8)
        self.layer_index = np.ascontiguousarray(self.layer_index, dtype=np.intp)
        self.threshold = np.ascontiguousarray(self.threshold, dtype=np.float64)
        self._products = {}  # per deepest layer routed: the product's axes, each node's column

    def __setstate__(self, state):
        self.__dict__.update(state)
        if not {"walkable", "_products"} <= state.keys():  # pickled without (all) its tables
            self._derive()

    def route(self, frames, layers=None):
        """Layer index of each frame's node in each of ``layers``.

        Parameters
        ----------
        frames : ndarray of shape (n_frames, n_channels)
            Raw frames (the standardisation is folded into the splits).
        layers : array-like of int, default=None
            Non-negative layers, increasing; all by default.

        Returns
        -------
        nodes : ndarray of shape (n_frames, n_selected_layers)
            ``nodes[i, j]`` is the layer index of frame ``i``'s node in ``layers[j]``.
        """
        frames = np.asarray(frames, dtype=np.float64)
        layers = (
            np.arange(self.n_layers) if layers is None else np.ascontiguousarray(layers, np.intp)
        )
        if len(frames) <= _CHUNK:
            return self._route_block(frames, layers)
        out = np.empty((len(frames), len(layers)), dtype=np.intp)
        for start in range(0, len(frames), _CHUNK):
            block = slice(start, start + _CHUNK)
            out[block] = self._route_block(frames[block], layers)
        return out

    def route_clips(self, clips, layers=None):
        """:meth:`route` of the clips' frames, one clip after the other.

        The clips are routed in groups of about 32,768 frames (each frame's nodes do not
        depend on the others routed with it), so no stacked copy of all frames is made.

        Parameters
        ----------
        clips : list of ndarray of shape (n_frames_i, n_channels)
        layers : array-like of int, default=None
            As for :meth:`route`.

        Returns
        -------
        nodes : ndarray of shape (sum(n_frames_i), n_selected_layers)
        """
        layers = (
            np.arange(self.n_layers) if layers is None else np.ascontiguousarray(layers, np.intp)
        )
        out = np.empty((sum(len(clip) for clip in clips), len(layers)), dtype=np.intp)
        group, size, start = [], 0, 0
        for i, clip in enumerate(clips):
            group.append(clip)
            size += len(clip)
            if size >= _CHUNK or i == len(clips) - 1:
                out[start : start + size] = self.route(np.concatenate(group), layers)
                group, size, start = [], 0, start + size
        return out

    def _route_block(self, frames, layers):
        out = np.empty((len(frames), len(layers)), dtype=np.intp)
        node = np.zeros(len(frames), dtype=np.intp)  # tree node ids, from the root
        axes, column = self._product(int(layers[-1]))
        # einsum, not BLAS: a product this thin gains nothing from BLAS's threads, and on a
        # busy machine their hand-offs cost 50-100x the arithmetic (measured).
        proj = np.einsum("ij,kj->ik", frames, axes) if len(axes) else np.zeros((len(frames), 0))
        layer, k = 0, 0
        while True:
            # the layers whose axes are in the product (a leaf's column is -1: both of its
            # sides are itself), walked in one compiled loop; a deeper layer is one _step
            layer, k = walk_layers(
                proj, column, self.threshold, self.left_or_self, self.right_or_self,
                self.layer_index, self.walkable, layers, node, out, layer, k,
            )  # fmt: skip
            if layer == layers[-1]:
                return out
            node = self._step(frames, node)
            layer += 1

    def _product(self, last):
        """The split axes of the upper layers above ``last`` (few nodes each), applied to all
        frames in one product (one read of the frames), and each tree node's column there."""
        if last not in self._products:
            upper = [
                ids for layer, ids in enumerate(self.split_ids[:last]) if self.in_product[layer]
            ]
            column = np.full(len(self.left), -1, dtype=np.intp)
            ids = np.concatenate(upper) if upper else np.zeros(0, dtype=np.intp)
            column[ids] = np.arange(len(ids))
            self._products[last] = (np.ascontiguousarray(self.axis[ids]), column)
        return self._products[last]

    def _step(self, frames, node):
        """Every frame's node one layer down, each frame's own axis gathered (a leaf copied
        down stays itself)."""
        splits = self.left[node] >= 0
        if not splits.any():
            return node
        rows = np.flatnonzero(splits)
        ids = node[rows]
        values = np.einsum("ij,ij->i", frames[rows], self.axis[ids])
        right = np.zeros(len(frames), dtype=bool)
        right[rows] = values > self.threshold[ids]
        return np.where(splits, np.where(right, self.right[node], self.left[node]), node)
