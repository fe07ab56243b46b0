"""Building the motion tree: principal axes and 1-D cuts, layer by layer.

A node's frames are centred and projected on their first principal axis, and
the sorted projections are cut in two by a 1-D criterion (minimum-error
thresholding by default); nodes split until they are too small or the tree is
deep enough. A node that stops early is copied down, so every layer holds all
frames. Building costs one sort and one ``n x d`` scatter per split node:
O(N log N) for N frames when the tree is about ``log N`` deep. There are no
pairwise distances and no Python loop over frames (only over nodes).
"""

import numpy as np
from scipy.linalg import eigh
from scipy.linalg.lapack import dsyevr

from skmotion.tree._gaussian import estimate_covariance
from skmotion.tree._split import best_split

__all__ = ["build_nodes"]

# A cut must sit in a gap wider than this many units of the projections'
# rounding error, so routing a training frame again always finds the same side.
_GAP_RESOLUTION = 1e-12


def _top_eigenvectors(symmetric, k):
    """The ``k`` leading eigenpairs of a symmetric matrix, largest first.

    LAPACK's subset driver computes only the wanted pairs; it is called
    directly because the wrapper's checks cost as much as the work on the small
    matrices of tree nodes.
    """
    m = len(symmetric)
    k = min(k, m)
    values, vectors, _, _, info = dsyevr(symmetric, compute_v=1, range="I", il=m - k + 1, iu=m)
    if info != 0:  # pragma: no cover - LAPACK failure on a finite symmetric matrix
        values, vectors = eigh(symmetric, subset_by_index=[m - k, m - 1])
    return values[:k][::-1], vectors[:, :k][:, ::-1]


def _fix_signs(axes):
    """Flip each row so its largest component is positive (reproducible axes)."""
    signs = np.sign(axes[np.arange(len(axes)), np.argmax(np.abs(axes), axis=1)])
    return axes * np.where(signs == 0, 1.0, signs)[:, None]


def _principal_axis(centred, scatter):
    """The unit first principal axis of centred frames (None when they do not vary)."""
    if scatter is not None:
        values, vectors = _top_eigenvectors(scatter, 1)
        axis = vectors[:, 0]
    else:  # fewer frames than channels: the small n x n problem has the same axis
        values, vectors = _top_eigenvectors(centred @ centred.T, 1)
        axis = centred.T @ vectors[:, 0]
    norm = float(np.sqrt(axis @ axis))
    if values[0] <= 0.0 or norm == 0.0:
        return None
    axis = axis / norm
    return -axis if axis[np.argmax(np.abs(axis))] < 0 else axis


class _Builder:
    """Breadth-first construction on a copy of the frames in which every node's
    frames are one contiguous block (splitting a node reorders its block)."""

    def __init__(self, X, max_depth, min_samples_split, min_samples_leaf, split, covariance_type, reg):
        # Rounding of a projection x @ axis is below d * eps * max|x|; cuts must
        # sit in gaps far wider, so a training frame always routes back to its side.
        self.tol = _GAP_RESOLUTION * X.shape[1] * float(np.abs(X).max())
        self.blocks = X.copy()
        self.max_depth = max_depth
        self.min_split = max(min_samples_split, 2 * min_samples_leaf, 2)
        self.min_leaf = min_samples_leaf
        self.split = split
        self.kind = covariance_type
        self.reg = reg
        self.nodes = {k: [] for k in ("parent", "depth", "start", "stop", "mean", "cov", "axis", "thr", "left", "right")}

    def add(self, parent, depth, start, stop):
        for key, value in zip(("parent", "depth", "start", "stop"), (parent, depth, start, stop)):
            self.nodes[key].append(value)
        for key, value in (("left", -1), ("right", -1), ("axis", None), ("thr", np.nan), ("mean", None), ("cov", None)):
            self.nodes[key].append(value)
        return len(self.nodes["parent"]) - 1

    def process(self, node, may_split):
        """Compute the node's Gaussian; split it when allowed and possible."""
        nodes = self.nodes
        start, stop = nodes["start"][node], nodes["stop"][node]
        block = self.blocks[start:stop]
        n, d = block.shape
        mean = block.mean(axis=0)
        centred = block - mean
        eligible = may_split and n >= self.min_split
        scatter = centred.T @ centred if (self.kind == "full" or (eligible and n >= d)) else None
        nodes["mean"][node] = mean
        nodes["cov"][node] = estimate_covariance(centred, self.kind, self.reg, scatter)
        if not eligible:
            return ()
        axis = _principal_axis(centred, scatter if n >= d else None)
        if axis is None:
            return ()
        proj = centred @ axis
        proj += mean @ axis  # the projection of the frames themselves, as routing computes it
        order = np.argsort(proj, kind="stable")
        ordered = proj[order]
        n_left = best_split(ordered, self.split, min_samples_leaf=self.min_leaf, tol=self.tol)
        if n_left is None:
            return ()
        self.blocks[start:stop] = block[order]
        depth = nodes["depth"][node] + 1
        left = self.add(node, depth, start, start + n_left)
        right = self.add(node, depth, start + n_left, stop)
        nodes["left"][node], nodes["right"][node] = left, right
        nodes["axis"][node] = axis
        nodes["thr"][node] = 0.5 * (ordered[n_left - 1] + ordered[n_left])
        return (left, right)

    def run(self):
        root = self.add(-1, 0, 0, len(self.blocks))
        layers = [np.array([root])]
        depth = 0
        while True:
            may_split = self.max_depth is None or depth < self.max_depth
            next_layer, grew = [], False
            for node in layers[-1]:
                if self.nodes["depth"][node] == depth:
                    children = self.process(node, may_split)
                else:  # a leaf of an upper layer, copied down
                    children = ()
                grew |= bool(children)
                next_layer.extend(children or (node,))
            if not grew:
                break
            layers.append(np.array(next_layer))
            depth += 1
        return layers


def _root_axes(X, n_axes=3):
    """The first principal axes of all frames (for plotting node positions)."""
    centred = X - X.mean(axis=0)
    _, vectors = _top_eigenvectors(centred.T @ centred, n_axes)
    return _fix_signs(vectors.T)


def build_nodes(X, *, max_depth, min_samples_split, min_samples_leaf, split, covariance_type, reg):
    """Grow the tree over validated frames; the per-node arrays and the layers.

    Parameters
    ----------
    X : ndarray of shape (n_frames, n_channels)
        C-contiguous, finite frames.
    max_depth, min_samples_split, min_samples_leaf, split, covariance_type
        As for :meth:`MotionTree.build`.
    reg : float
        The absolute variance added to every covariance's diagonal.

    Returns
    -------
    nodes : dict
        ``parent``, ``left``, ``right``, ``depth``, ``count``, ``mean``,
        ``covariance``, ``axis``, ``threshold`` (per tree node id), ``layers``
        and ``principal_axes``: the arguments of ``MotionTree``.
    """
    builder = _Builder(X, max_depth, min_samples_split, min_samples_leaf, split, covariance_type, reg)
    layers = builder.run()
    nodes = builder.nodes
    d = X.shape[1]
    return {
        "parent": np.array(nodes["parent"], dtype=np.intp),
        "left": np.array(nodes["left"], dtype=np.intp),
        "right": np.array(nodes["right"], dtype=np.intp),
        "depth": np.array(nodes["depth"], dtype=np.intp),
        "count": np.array(nodes["stop"], dtype=np.intp) - np.array(nodes["start"], dtype=np.intp),
        "mean": np.array(nodes["mean"]),
        "covariance": np.array(nodes["cov"]),
        "axis": np.array([np.zeros(d) if a is None else a for a in nodes["axis"]]),
        "threshold": np.array(nodes["thr"], dtype=np.float64),
        "layers": layers,
        "principal_axes": _root_axes(X),
    }
