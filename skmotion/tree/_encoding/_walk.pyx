# cython: language_level=3, boundscheck=False, wraparound=False, initializedcheck=False
"""Frames walked down the upper layers of a motion tree from their projections on all
of those layers' split axes: the router's per-layer steps in one compiled loop.

Each step is the comparison NumPy's step makes (``projection > threshold`` of the
frame's node), on the same projections, so every frame reaches the same node; a call
on one clip costs one function call instead of about seven array operations per layer.
"""

ctypedef Py_ssize_t intp


def walk_layers(const double[:, ::1] proj, const intp[::1] column, const double[::1] threshold,
                const intp[::1] left_or_self, const intp[::1] right_or_self,
                const intp[:, ::1] layer_index, const unsigned char[::1] walkable,
                const intp[::1] layers, intp[::1] node, intp[:, ::1] out, intp layer, intp k):
    """Walk every frame from ``layer`` down while the layers are walkable; in place.

    Parameters
    ----------
    proj : ndarray of shape (n_frames, n_axes)
        Each frame's projection on the product's split axes.
    column : ndarray of shape (n_tree_nodes,)
        Each split node's column of ``proj`` (-1 for a leaf: a leaf stays itself).
    threshold : ndarray of shape (n_tree_nodes,)
    left_or_self, right_or_self : ndarray of shape (n_tree_nodes,)
        The child on each side, a leaf being its own.
    layer_index : ndarray of shape (n_layers, n_tree_nodes)
        The layer index of each tree node in each layer.
    walkable : ndarray of shape (n_layers,) of uint8
        1 for a layer whose split axes are all in ``proj`` (or that has none).
    layers : ndarray of int
        The layers whose node is written to ``out``, increasing.
    node : ndarray of shape (n_frames,)
        Each frame's tree node in ``layer``; updated.
    out : ndarray of shape (n_frames, len(layers))
        Filled for the layers passed.
    layer, k : int
        The layer to start from, and the position in ``layers`` of the next to write.

    Returns
    -------
    layer, k : int
        Where the walk stopped: ``layers[-1]`` (done), or a layer that is not
        walkable, whose ``out`` column is written but whose step is left to the caller.

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.tree._encoding._walk import walk_layers
    >>> proj = np.array([[-1.0], [2.0]])  # one split (node 0 -> 1 | 2) at threshold 0
    >>> node, out = np.zeros(2, dtype=np.intp), np.empty((2, 1), dtype=np.intp)
    >>> index = np.array([[0, -1, -1], [-1, 0, 1]])
    >>> walk_layers(proj, np.array([0, -1, -1]), np.zeros(3), np.array([1, 1, 2]),
    ...             np.array([2, 1, 2]), index, np.ones(2, np.uint8), np.array([1]), node, out, 0, 0)
    (1, 1)
    >>> out.ravel().tolist()
    [0, 1]
    """
    cdef intp n = node.shape[0], n_wanted = layers.shape[0], last = layers[n_wanted - 1]
    cdef intp i, nd, col, at, kk, stop = layer, k_stop = k
    # the layer where the walk stops: the last wanted one, or the first that is not walkable
    while stop < last and walkable[stop]:
        stop += 1
    while k_stop < n_wanted and layers[k_stop] <= stop:
        k_stop += 1
    with nogil:
        for i in range(n):
            nd = node[i]
            kk = k
            for at in range(layer, stop + 1):
                if kk < n_wanted and at == layers[kk]:
                    out[i, kk] = layer_index[at, nd]
                    kk += 1
                if at == stop:
                    break
                col = column[nd]
                if col >= 0:
                    nd = right_or_self[nd] if proj[i, col] > threshold[nd] else left_or_self[nd]
            node[i] = nd
    return stop, k_stop
