# cython: language_level=3, boundscheck=False, wraparound=False, initializedcheck=False
"""Frames walked down a motion tree, each frame on its own path: the router's one compiled loop.

A frame at a split node goes right when its projection on the node's axis is above the
node's threshold, as :meth:`MotionTree.apply` sends it; the projection is one dot product
over the channels, computed only for the nodes on the frame's path (``depth`` products per
frame, where projecting every frame on every axis of the upper layers took several times
that and an array per layer). The dot product's sum is split over four accumulators, so
its rounding differs from NumPy's in the last bits: the thresholds sit in gaps between
training projections far wider than that (``best_split``'s gap rule), so a training frame
goes where the build put it.
"""

from skmotion.utils._dot cimport dot4

ctypedef Py_ssize_t intp


def walk_frames(const double[:, ::1] frames, const double[:, ::1] axis,
                const double[::1] threshold, const intp[::1] left, const intp[::1] right,
                const intp[:, ::1] layer_index, const intp[::1] layers, intp[:, ::1] out):
    """Each frame's node in each of ``layers``, walked from the root; ``out`` filled in place.

    Parameters
    ----------
    frames : ndarray of shape (n_frames, d), C-contiguous float64
    axis : ndarray of shape (n_tree_nodes, d)
        Each split node's axis (a leaf's row is not read).
    threshold : ndarray of shape (n_tree_nodes,)
        A frame goes right where ``frame . axis > threshold``.
    left, right : ndarray of shape (n_tree_nodes,) of intp
        The children of each node, -1 for a leaf (which stays itself one layer down).
    layer_index : ndarray of shape (n_layers, n_tree_nodes) of intp
        The layer index of each tree node in each layer.
    layers : ndarray of intp
        The layers written to ``out``, increasing, in ``0 .. n_layers - 1``.
    out : ndarray of shape (n_frames, len(layers)) of intp

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.tree._encoding._walk import walk_frames
    >>> frames = np.array([[-1.0], [2.0]])  # one split (node 0 -> 1 | 2) at threshold 0
    >>> out = np.empty((2, 2), dtype=np.intp)
    >>> index = np.array([[0, -1, -1], [-1, 0, 1]])
    >>> walk_frames(frames, np.ones((3, 1)), np.zeros(3), np.array([1, -1, -1]),
    ...             np.array([2, -1, -1]), index, np.array([0, 1]), out)
    >>> out.tolist()
    [[0, 0], [0, 1]]
    """
    cdef intp n = frames.shape[0], d = frames.shape[1], n_nodes = left.shape[0]
    cdef intp n_wanted = layers.shape[0], i, j, at, kk, nd, last
    if (axis.shape[0] != n_nodes or axis.shape[1] != d or threshold.shape[0] != n_nodes
            or right.shape[0] != n_nodes or layer_index.shape[1] != n_nodes):
        raise ValueError(
            f"shapes do not agree: frames {(n, d)}, axis {(axis.shape[0], axis.shape[1])}, "
            f"threshold {threshold.shape[0]}, left {n_nodes}, right {right.shape[0]}, "
            f"layer_index {layer_index.shape[1]} nodes."
        )
    if out.shape[0] != n or out.shape[1] != n_wanted:
        raise ValueError(f"out must have shape {(n, n_wanted)}.")
    if n_wanted == 0:
        return
    for j in range(n_wanted):
        if not 0 <= layers[j] < layer_index.shape[0] or (j and layers[j] <= layers[j - 1]):
            raise ValueError(
                f"layers must increase within 0 .. {layer_index.shape[0] - 1}; got "
                f"{list(layers)}."
            )
    for j in range(n_nodes):  # the walk reads the children unchecked
        if not (-1 <= left[j] < n_nodes and -1 <= right[j] < n_nodes
                and (left[j] < 0) == (right[j] < 0)):
            raise ValueError(f"node {j}'s children are not tree nodes (or it has one).")
    last = layers[n_wanted - 1]
    with nogil:
        for i in range(n):
            nd = 0
            kk = 0
            for at in range(last + 1):
                if at == layers[kk]:
                    out[i, kk] = layer_index[at, nd]
                    kk += 1
                    if kk == n_wanted:
                        break
                if left[nd] >= 0:
                    if dot4(&frames[i, 0], &axis[nd, 0], d) > threshold[nd]:
                        nd = right[nd]
                    else:
                        nd = left[nd]
