"""Routing frames down a motion tree: every layer's node of every frame in one compiled walk.

:class:`TreeRouter` folds a standardisation into the split axes and thresholds,
so raw frames are routed without a standardised copy, and walks all frames of
a collection down the tree in one compiled loop (``_walk.walk_frames``): each
frame compares its projection on its own node's split axis with the threshold,
layer after layer, with no Python step per clip, frame or layer.
"""

import numpy as np

from skmotion.tree._encoding._walk import walk_frames

__all__ = ["TreeRouter"]

# what routers before the compiled walk also kept (their projections of the upper layers)
_OLD_TABLES = ("split_ids", "left_or_self", "right_or_self", "in_product", "walkable", "_products")


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
        self._derive()

    def _derive(self):
        """The walk's arrays as it reads them (C-contiguous float64 and intp)."""
        self.axis = np.ascontiguousarray(self.axis, dtype=np.float64)
        self.threshold = np.ascontiguousarray(self.threshold, dtype=np.float64)
        self.left = np.ascontiguousarray(self.left, dtype=np.intp)
        self.right = np.ascontiguousarray(self.right, dtype=np.intp)
        self.layer_index = np.ascontiguousarray(self.layer_index, dtype=np.intp)

    def __setstate__(self, state):
        # a router pickled by an older version also held the tables of its product path
        for name in _OLD_TABLES:
            state.pop(name, None)
        self.__dict__.update(state)
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
        frames = np.ascontiguousarray(frames, dtype=np.float64)
        layers = (
            np.arange(self.n_layers) if layers is None else np.ascontiguousarray(layers, np.intp)
        )
        out = np.empty((len(frames), len(layers)), dtype=np.intp)
        self._walk(frames, layers, out)
        return out

    def route_clips(self, clips, layers=None):
        """:meth:`route` of the clips' frames, one clip after the other.

        Each clip is walked into its rows of the answer (a frame's nodes do not depend on
        the others routed with it), so no stacked copy of the frames is made.

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
        start = 0
        for clip in clips:
            frames = np.ascontiguousarray(clip, dtype=np.float64)
            self._walk(frames, layers, out[start : start + len(frames)])
            start += len(frames)
        return out

    def _walk(self, frames, layers, out):
        """The compiled walk of C-contiguous float64 ``frames`` into ``out``, in place."""
        walk_frames(
            frames, self.axis, self.threshold, self.left, self.right, self.layer_index, layers, out
        )
