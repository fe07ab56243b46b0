"""The motion tree: a binary tree of frame clusters whose every layer partitions all frames.

Yamane, Yamaguchi and Nakamura's motion database (section III-B). The tree's
construction is in :mod:`skmotion.tree._build`; this module holds the structure,
its per-layer views and the routing of frames through the splits.
"""

from numbers import Integral

import numpy as np
from joblib import effective_n_jobs

from skmotion.base import VersionedStateMixin
from skmotion.tree._build import PAPER_TREE, TreeParams, build_nodes
from skmotion.tree._gaussian import Gaussians

__all__ = ["MotionTree"]

_ROUTE_CHUNK = 1 << 16


class MotionTree(VersionedStateMixin):
    """A binary tree of frame clusters; every layer partitions all frames.

    Build one with :meth:`build`. Nodes are numbered in creation order
    (breadth first, left before right); the per-node arrays below are indexed
    by that *tree node id*. Layer ``l`` (0 is the root; the paper counts from 1)
    lists its nodes in tree order in ``layers[l]``: the children of a node sit
    next to each other, and a leaf that stopped early appears again, the same
    node, in every lower layer. The per-layer methods (``counts(layer)``,
    ``children(layer)``, ...) use *layer indices*: positions in ``layers[layer]``.

    Attributes
    ----------
    parent : ndarray of shape (n_tree_nodes,)
        Parent id, -1 for the root.
    left, right : ndarray of shape (n_tree_nodes,)
        Child ids, -1 for a leaf. The left child holds the frames whose
        projection ``frame @ axis`` is at most ``threshold``.
    depth : ndarray of shape (n_tree_nodes,)
        The layer in which the node first appears.
    count : ndarray of shape (n_tree_nodes,)
        Frames in the node.
    mean : ndarray of shape (n_tree_nodes, n_channels)
        Mean frame of the node.
    covariance : ndarray
        Shape ``(n_tree_nodes,)`` (``"spherical"``), ``(n_tree_nodes, n_channels)``
        (``"diag"``) or ``(n_tree_nodes, n_channels, n_channels)`` (``"full"``).
    axis : ndarray of shape (n_tree_nodes, n_channels)
        Unit split axis of each split node (zeros for leaves).
    threshold : ndarray of shape (n_tree_nodes,)
        Split threshold on ``frame @ axis`` (NaN for leaves).
    layers : list of ndarray
        Tree node ids of each layer, in tree order.
    low_rank : list
        For ``"full"``, each node's covariance as ``(floor, vectors, values)``,
        ``floor I + vectors.T @ diag(values) @ vectors``, when the node has no
        more frames than channels (see ``low_rank_covariance``); else None.
    covariance_type : str
        The covariance estimator.
    reg : float
        The variance added to every covariance's diagonal.
    principal_axes : ndarray of shape (n_axes, n_channels)
        The first (up to three) principal axes of all frames, to draw nodes.

    Notes
    -----
    A pickle records the skmotion version; loading it into an incompatible
    version raises :class:`~skmotion.base.IncompatibleVersionError`.

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.tree import MotionTree
    >>> rng = np.random.default_rng(0)
    >>> frames = np.r_[rng.normal(0, 1, (200, 3)), rng.normal(8, 1, (100, 3))]
    >>> tree = MotionTree.build(frames, max_depth=3, min_samples_leaf=16)
    >>> tree.n_layers, tree.counts(1).tolist()
    (4, [200, 100])
    >>> bool((tree.apply(frames, 1) == np.r_[np.zeros(200), np.ones(100)]).all())
    True
    """

    def __init__(
        self,
        *,
        parent,
        left,
        right,
        depth,
        count,
        mean,
        covariance,
        axis,
        threshold,
        layers,
        covariance_type,
        reg,
        principal_axes,
        low_rank=None,
    ):
        self.parent = parent
        self.left = left
        self.right = right
        self.depth = depth
        self.count = count
        self.mean = mean
        self.covariance = covariance
        self.axis = axis
        self.threshold = threshold
        self.layers = layers
        self.covariance_type = covariance_type
        self.reg = reg
        self.principal_axes = principal_axes
        self.low_rank = [None] * len(parent) if low_rank is None else low_rank
        self._gaussians = Gaussians(mean, covariance, covariance_type, self.low_rank)

    @classmethod
    def build(
        cls,
        frames,
        *,
        max_depth=PAPER_TREE.max_depth,
        min_samples_split=PAPER_TREE.min_samples_split,
        min_samples_leaf=PAPER_TREE.min_samples_leaf,
        split=PAPER_TREE.split,
        covariance_type=PAPER_TREE.covariance_type,
        reg_covar=PAPER_TREE.reg_covar,
        copy=True,
        n_jobs=None,
    ):
        """Build the tree over frames.

        The parameters are those of :class:`~skmotion.tree._build._params.TreeParams`,
        which checks them; the defaults are the paper's tree
        (:data:`~skmotion.tree._build._params.PAPER_TREE`), where the estimators
        declare their measured ones (the user guide's "Build parameters").

        Parameters
        ----------
        frames : array-like of shape (n_frames, n_channels)
            All frames of all clips, stacked; finite.
        max_depth : int, default=None
            The deepest layer (the root is layer 0); None for no limit.
        min_samples_split : int, default=2
            A node with fewer frames is not split.
        min_samples_leaf : int, default=16
            A split is only made when both sides keep this many frames (the
            paper's databases use 16).
        split : {"min_error", "two_means", "median"}, default="min_error"
            Where to cut a node's projections on its first principal axis:
            Kittler-Illingworth minimum-error thresholding (the paper's method,
            which tends to cut off small tails and grow deep, unbalanced trees),
            optimal 1-D 2-means, or the median (balanced trees). Only cuts
            between distinct projections are considered.
        covariance_type : {"diag", "full", "spherical"}, default="diag"
            The covariance estimator of each node (see ``estimate_covariance``):
            ``"full"`` is the Ledoit-Wolf shrunk sample covariance.
        reg_covar : float, default=1e-6
            Added to every variance, as a fraction of the mean per-channel
            variance of all frames (absolute when the frames do not vary).
        copy : bool, default=True
            False: when ``frames`` is a writable C-contiguous float64 array, the
            build works in it, reordering its rows and putting them back in their
            order at the end, so it holds no second copy of the frames (the same
            tree; about 1.1 times the frames' memory at most instead of 2.1).
            Do not read ``frames`` from another thread during the build.
        n_jobs : int, default=None
            Threads that process the nodes of a layer at once (the passes over
            the frames release the GIL). None means 1 unless in a
            :func:`joblib.parallel_backend` context; -1 means all processors.
            The tree is the same for any value.

        Returns
        -------
        tree : MotionTree
        """
        params = TreeParams(
            max_depth=max_depth,
            min_samples_split=min_samples_split,
            min_samples_leaf=min_samples_leaf,
            split=split,
            covariance_type=covariance_type,
            reg_covar=reg_covar,
        )
        return cls.from_params(frames, params, copy=copy, n_jobs=n_jobs)

    @classmethod
    def from_params(cls, frames, params, *, copy=True, n_jobs=None):
        """Build the tree over frames with the parameters of a ``TreeParams``.

        ``copy=False`` (for a caller's own C-contiguous float64 array, such as a
        fit's stacked frames): the build works in ``frames`` itself, reordering
        them and putting them back in their order at the end, so it holds no
        second copy of the frames (the same tree). ``n_jobs``: as for :meth:`build`.
        """
        X = np.asarray(frames, dtype=np.float64)
        if X.ndim != 2 or len(X) == 0 or X.shape[1] == 0:
            raise ValueError(
                f"frames must be a non-empty 2-D array (n_frames, n_channels); got shape {X.shape}."
            )
        for start in range(0, len(X), _ROUTE_CHUNK):  # in blocks: no mask the size of X
            block = X[start : start + _ROUTE_CHUNK]
            if not np.isfinite(block).all():
                frame, channel = np.argwhere(~np.isfinite(block))[0]
                raise ValueError(
                    f"frames must be finite; frame {start + frame}, channel {channel} is "
                    f"{block[frame, channel]}."
                )
        X = np.ascontiguousarray(X)
        # a conversion made a new array: the build may work in it, there is no other copy
        owned = not isinstance(frames, np.ndarray) or not np.may_share_memory(X, frames)
        in_place = (owned or not copy) and X.flags.writeable
        threads = effective_n_jobs(n_jobs)
        nodes = build_nodes(X, **params.as_dict(), copy=not in_place, n_jobs=threads)
        return cls(**nodes, covariance_type=params.covariance_type)

    # -- sizes and layer structure ------------------------------------------------

    @property
    def n_layers(self):
        """Number of layers, the root's included."""
        return len(self.layers)

    @property
    def n_tree_nodes(self):
        """Number of distinct nodes (a leaf copied down counts once)."""
        return len(self.parent)

    @property
    def n_channels(self):
        """Number of channels of the frames."""
        return self.mean.shape[1]

    @property
    def n_nodes(self):
        """Number of nodes in each layer, as an int array of length ``n_layers``."""
        return np.array([len(ids) for ids in self.layers], dtype=np.intp)

    def check_layer(self, layer):
        """The layer index as a non-negative int; negative counts from the bottom.

        Raises
        ------
        ValueError
            When the tree has no such layer.
        """
        if not isinstance(layer, Integral) or isinstance(layer, bool):
            raise ValueError(f"layer must be an int; got {layer!r}.")
        if not -self.n_layers <= layer < self.n_layers:
            raise ValueError(
                f"layer {layer} does not exist: the tree has {self.n_layers} layers "
                f"(0 to {self.n_layers - 1}, or -1 to {-self.n_layers} from the bottom)."
            )
        return int(layer) % self.n_layers

    def node_ids(self, layer):
        """Tree node ids of the nodes of a layer, in layer order."""
        return self.layers[self.check_layer(layer)]

    def _first_child(self, layer):
        """Layer index (in ``layer + 1``) of each node's first child, and whether it splits."""
        splits = self.left[self.layers[layer]] >= 0
        first = np.zeros(len(splits), dtype=np.intp)
        np.cumsum(1 + splits[:-1], out=first[1:])
        return first, splits

    def children(self, layer):
        """Layer indices (in ``layer + 1``) of each node's children.

        Returns
        -------
        children : ndarray of shape (n_nodes(layer), 2)
            ``[left, right]`` for a split node, ``[copy, -1]`` for a leaf copied
            down, ``[-1, -1]`` in the bottom layer.
        """
        layer = self.check_layer(layer)
        out = np.full((len(self.layers[layer]), 2), -1, dtype=np.intp)
        if layer + 1 < self.n_layers:
            first, splits = self._first_child(layer)
            out[:, 0] = first
            out[splits, 1] = first[splits] + 1
        return out

    def parents(self, layer):
        """Layer index (in ``layer - 1``) of each node's parent; -1 in layer 0."""
        layer = self.check_layer(layer)
        if layer == 0:
            return np.array([-1], dtype=np.intp)
        _, splits = self._first_child(layer - 1)
        return np.repeat(np.arange(len(splits)), 1 + splits)

    def counts(self, layer):
        """Frames in each node of a layer."""
        return self.count[self.node_ids(layer)]

    def means(self, layer):
        """Mean frame of each node of a layer, ``(n_nodes(layer), n_channels)``."""
        return self.mean[self.node_ids(layer)]

    def covariances(self, layer):
        """Covariance of each node of a layer, laid out as ``covariance``."""
        return self.covariance[self.node_ids(layer)]

    # -- routing frames and their likelihoods ---------------------------------------

    def iter_apply(self, frames):
        """Route frames down the tree, yielding their node in each layer in turn.

        Parameters
        ----------
        frames : array-like of shape (n_frames, n_channels)

        Yields
        ------
        labels : ndarray of shape (n_frames,)
            Layer index of each frame's node, for layers ``0, 1, ...``.
        """
        X = self._check_frames(frames)
        labels = np.zeros(len(X), dtype=np.intp)
        yield labels
        for layer in range(self.n_layers - 1):
            ids = self.layers[layer]
            first, splits = self._first_child(layer)
            rows = np.flatnonzero(splits[labels])
            right = np.zeros(len(X), dtype=np.intp)
            for start in range(0, len(rows), _ROUTE_CHUNK):
                chunk = rows[start : start + _ROUTE_CHUNK]
                node = ids[labels[chunk]]
                proj = np.einsum("ij,ij->i", X[chunk], self.axis[node])
                right[chunk] = proj > self.threshold[node]
            labels = first[labels] + right
            yield labels

    def apply(self, frames, layer=-1):
        """The node of each frame in a layer, found through the splits.

        Parameters
        ----------
        frames : array-like of shape (n_frames, n_channels)
        layer : int, default=-1
            The layer (negative counts from the bottom).

        Returns
        -------
        labels : ndarray of shape (n_frames,)
            Layer index of each frame's node.
        """
        layer = self.check_layer(layer)
        for depth, labels in enumerate(self.iter_apply(frames)):
            if depth == layer:
                return labels

    def log_likelihood(self, frames, layer, nodes=None):
        """Gaussian log density ``log Po(x | k)`` of every frame at the nodes of a layer.

        Parameters
        ----------
        frames : array-like of shape (n_frames, n_channels)
        layer : int
            The layer.
        nodes : array-like of int, default=None
            Layer indices of the nodes to evaluate; all by default.

        Returns
        -------
        log_pdf : ndarray of shape (n_frames, n_selected)
        """
        ids = self.node_ids(layer)
        if nodes is not None:
            ids = ids[np.asarray(nodes, dtype=np.intp)]
        return self._gaussians.log_pdf(self._check_frames(frames), ids)

    @property
    def gaussians(self):
        """The nodes' Gaussians (tree node id order), which give ``log_likelihood``."""
        return self._gaussians

    def _check_frames(self, frames):
        X = np.asarray(frames, dtype=np.float64)
        if X.ndim != 2 or X.shape[1] != self.n_channels:
            raise ValueError(
                f"frames must have shape (n_frames, {self.n_channels}); got {X.shape}."
            )
        return X
