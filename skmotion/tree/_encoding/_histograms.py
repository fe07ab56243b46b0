"""Clip histograms over a motion tree's nodes: occupancy per temporal-pyramid cell and transitions.

Free functions on routed node labels (see :class:`TreeRouter`), used by
:class:`MotionTreeEncoder`. All clips are handled together: each frame adds one
entry per (layer, pyramid level) to a sparse matrix whose duplicates sum into
the histograms.
"""

import numpy as np
import scipy.sparse as sp

from skmotion.tree._encoding._readout_passes import histogram_rows, moment_rows, residual_rows
from skmotion.utils._group_sums import group_sums

# rows per block of node_variances' squared deviations (bounds its temporaries)
_ROWS_PER_BLOCK = 1 << 15

__all__ = [
    "feature_blocks",
    "histogram_features",
    "moment_features",
    "node_variances",
    "residual_features",
    "second_order_features",
]


def feature_blocks(layers, n_nodes, pyramid, transition_layers):
    """The sparse blocks of the feature vector, in order: ``(kind, layer, parts, width)``.

    ``kind`` is ``"occupancy"`` (one block per layer and pyramid level, ``parts``
    cells of ``n_nodes[layer]`` columns) or ``"transitions"`` (``parts`` is 1,
    ``n_nodes[layer] ** 2`` columns).
    """
    blocks = [
        ("occupancy", int(layer), int(parts), int(n_nodes[layer]) * int(parts))
        for layer in layers
        for parts in pyramid
    ]
    blocks += [
        ("transitions", int(layer), 1, int(n_nodes[layer]) ** 2) for layer in transition_layers
    ]
    return blocks


def histogram_features(nodes, offsets, layers, blocks, power, dense=False):
    """Per-clip normalised histograms of routed frames, as a CSR matrix (or dense).

    Parameters
    ----------
    nodes : ndarray of shape (n_frames, n_layers_routed)
        Layer index of every frame's node, for the layers ``layers``.
    offsets : ndarray of shape (n_clips + 1,)
        Clip ``i`` is frames ``offsets[i]:offsets[i + 1]``.
    layers : sequence of int
        The layer of each column of ``nodes``.
    blocks : list of tuple
        From :func:`feature_blocks`.
    power : float
        Every entry is raised to this power (0.5: Hellinger's square root).
    dense : bool, default=False
        Return the same entries as a dense array, summed by one compiled pass over
        the frames (``_readout_passes.histogram_rows``) with no sparse matrix made.

    Returns
    -------
    features : scipy.sparse.csr_matrix or ndarray of shape (n_clips, n_features)
        Occupancy cell ``c`` of ``parts`` holds the share of the clip's frames
        ``[c n / parts, (c + 1) n / parts)`` in each node (each cell sums to 1
        before ``power``); a transition entry is the share of the clip's
        ``n - 1`` steps that go from one node to another (staying is not
        counted: occupancy says it).
    """
    if dense:
        return _dense_histograms(nodes, offsets, layers, blocks, power)
    n_clips = len(offsets) - 1
    lengths = np.diff(offsets)
    clip = np.repeat(np.arange(n_clips), lengths)
    position = np.arange(offsets[-1]) - offsets[clip]
    column_of = {layer: j for j, layer in enumerate(layers)}
    rows, cols, vals = [], [], []
    start = 0
    for kind, layer, parts, width in blocks:
        node = nodes[:, column_of[layer]]
        k = width // parts if kind == "occupancy" else int(np.sqrt(width))
        if kind == "occupancy":
            cell = position * parts // lengths[clip]
            key = clip * parts + cell
            size = np.bincount(key, minlength=n_clips * parts)
            rows.append(clip)
            cols.append(start + cell * k + node)
            vals.append(1.0 / size[key])
        else:
            same_clip = position[:-1] + 1 < lengths[clip[:-1]]
            step = np.flatnonzero(same_clip & (node[:-1] != node[1:]))
            src_clip = clip[step]
            rows.append(src_clip)
            cols.append(start + node[step] * k + node[step + 1])
            vals.append(1.0 / (lengths[src_clip] - 1))
        start += width
    if not blocks:
        return sp.csr_matrix((n_clips, 0))
    matrix = sp.csr_matrix(
        (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
        shape=(n_clips, start),
    )
    matrix.sum_duplicates()
    if power != 1:
        np.power(matrix.data, power, out=matrix.data)
    return matrix


def _dense_histograms(nodes, offsets, layers, blocks, power):
    """:func:`histogram_features`' entries as a dense array, in one compiled pass."""
    column_of = {layer: j for j, layer in enumerate(layers)}
    spec, start = [], 0
    for kind, layer, parts, width in blocks:
        k = width // parts if kind == "occupancy" else int(np.sqrt(width))
        spec.append((0 if kind == "occupancy" else 1, column_of[layer], parts, k, start))
        start += width
    rows = histogram_rows(
        np.ascontiguousarray(nodes, dtype=np.intp),
        np.ascontiguousarray(offsets, dtype=np.intp),
        np.array(spec, dtype=np.intp).reshape(-1, 5),
        start,
        power == 0.5,  # the square root, NumPy's power(x, 0.5) to the bit
    )
    if power not in (0.5, 1):  # NumPy's pow on the entries, as the sparse matrix's
        filled = rows != 0
        rows[filled] = np.power(rows[filled], power)
    return rows


def residual_features(frames, nodes, offsets, means, center, scale, power):
    """Per clip and node, the mean offset of the clip's frames from the node's mean (VLAD).

    For each layer, ``sum_{t in node k} (z_t - mean_k) / n_frames`` for every
    node ``k`` (zeros where the clip has no frame), with ``z = (x - center) /
    scale``, raised to ``power`` with its sign, and the layer's block scaled to
    unit Euclidean norm (so every layer weighs alike, whatever its node count).
    Where occupancy says which poses a clip visits, this says how its frames
    sit within them: the continuous detail a partition loses.

    Parameters
    ----------
    frames : ndarray of shape (n_frames, n_channels)
        Raw frames (the standardisation is applied to the sums).
    nodes : ndarray of shape (n_frames, n_layers)
        Layer index of every frame's node in each encoded layer.
    offsets : ndarray of shape (n_clips + 1,)
    means : list of ndarray of shape (n_nodes(layer), n_channels)
        The nodes' mean frames (standardised), per layer.
    center, scale : ndarray of shape (n_channels,)
    power : float

    Returns
    -------
    features : ndarray of shape (n_clips, sum(n_nodes(layer) * n_channels))
    """
    # one compiled pass per layer (_readout_passes: the doubles of the NumPy expressions
    # sum (x - c) / s - mean = (sum x - share c) / s - share mean, share = sum 1 / n, then the
    # signed square root and the unit norm); on a clip of a few dozen frames their forty
    # array operations' fixed costs were most of the encoder's call
    frames = np.ascontiguousarray(frames, dtype=np.float64)
    offsets = np.ascontiguousarray(offsets, dtype=np.intp)
    nodes = np.asarray(nodes, dtype=np.intp)
    compiled = power in (0.5, 1.0)  # other powers: NumPy's pow, whose rounding may differ
    blocks = []
    for j, mean in enumerate(means):
        block = residual_rows(
            frames, nodes[:, j], offsets, mean, center, scale, compiled, power == 0.5
        )
        blocks.append(block if compiled else _signed_power_unit_norm(block, power))
    if len(blocks) == 1:
        return blocks[0]
    return np.concatenate(blocks, axis=1) if blocks else np.zeros((len(offsets) - 1, 0))


def _signed_power_unit_norm(block, power):
    """``sign(b) |b| ** power`` per entry, then each row scaled to unit Euclidean norm."""
    if power != 1:
        block = np.sign(block) * np.abs(block) ** power
    # np.linalg.norm's own arithmetic (sqrt of the row sums of squares), without its checks
    norm = np.sqrt(np.add.reduce(block * block, axis=1, keepdims=True))
    return block / np.where(norm > 0, norm, 1.0)


def moment_features(frames, offsets, center, scale, order, pyramid=(1,)):
    """Per clip, the mean and root mean square of every channel in units of the training frames.

    With ``z = (x - center) / scale`` (``center``, ``scale``: the training
    frames' mean and standard deviation, the tree's root node), moment 1 is
    ``mean_t z_t`` and moment 2 is ``sqrt(mean_t z_t ** 2) - 1``, per channel:
    the root's first-order Fisher-vector term and the square root of its
    second-order one (0 for a clip that spreads like the training frames; the
    square root, like ``power`` elsewhere, tempers large values), not scaled
    to unit norm, so a clip far from the training mean keeps its distance.
    They say where a clip sits and how much it moves, the coarse description
    the residuals of the nodes leave out (each of their blocks is scaled to
    unit norm).

    Parameters
    ----------
    frames : ndarray of shape (n_frames, n_channels)
        Raw frames.
    offsets : ndarray of shape (n_clips + 1,)
        Clip ``i`` is frames ``offsets[i]:offsets[i + 1]`` (none empty).
    center, scale : ndarray of shape (n_channels,)
    order : int
        1 (means) or 2 (means, then root mean squares).
    pyramid : sequence of int, default=(1,)
        The means also over each ``1/p`` of the clip, for each ``p`` (1: the
        whole clip): a coarse trajectory of every channel, *when* the clip is
        where. The root mean square is over the whole clip only.

    Returns
    -------
    features : ndarray of shape (n_clips, (sum(pyramid) + order - 1) * n_channels)
        The means cell by cell (level by level, cells in time order, each cell
        every channel), then the root mean squares.
    """
    # one compiled pass over each clip's frames (_readout_passes), the doubles of
    # (sum over a cell of (x - center) / its frames) / scale and sqrt(mean (x - center)^2) / scale
    return moment_rows(
        np.ascontiguousarray(frames, dtype=np.float64),
        np.ascontiguousarray(offsets, dtype=np.intp),
        center,
        scale,
        order,
        np.asarray(pyramid, dtype=np.intp),
    )


def _clip_weights(offsets):
    """Each frame's clip, ``1 / length`` of its clip, and the clips, for :func:`_node_averages`."""
    lengths = offsets[1:] - offsets[:-1]  # np.diff, without its checks
    clip = np.repeat(np.arange(len(lengths)), lengths)
    return clip, 1.0 / lengths[clip], len(lengths)


def _node_averages(values, nodes, clip_weights, k):
    """Per clip and node: the sums of ``values`` over the clip's frames in the node / its frames.

    ``values`` is a list of arrays of shape (n_frames, n_channels), each summed per
    (clip, node) group in frame order (the compiled ``group_sums``: the doubles of the
    sparse (clip, node) x frame product, without building the matrix, whose making
    dominated a call on one clip); ``clip_weights`` is :func:`_clip_weights`. Also
    returns each group's share of its clip's frames.
    """
    clip, weight, n_clips = clip_weights
    n_groups = n_clips * k
    group = clip * k + nodes
    share = np.bincount(group, weights=weight, minlength=n_groups)[:, None]
    return [group_sums(v, group, weight, n_groups) for v in values], share


def node_variances(z_blocks, nodes, means):
    """Each node's per-channel variance of the standardised frames routed to it.

    1 where a node holds fewer than two frames; at least 1e-3 (a floor against
    division by a node whose frames agree in a channel). ``z_blocks(rows)`` yields
    ``(start, block)``, the standardised frames' consecutive blocks of ``rows`` rows
    (``StackedClips.blocks``: no stacked copy needed).
    """
    variances = []
    for j, mean in enumerate(means):
        node = nodes[:, j]
        count = np.bincount(node, minlength=len(mean))[:, None]
        squares = np.zeros_like(mean)
        # in blocks of rows (the same sums in the same order): the temporaries are a block's
        for start, block in z_blocks(_ROWS_PER_BLOCK):
            rows = slice(start, start + len(block))
            np.add.at(squares, node[rows], (block - mean[node[rows]]) ** 2)
        spread = np.maximum(squares / np.maximum(count, 1), 1e-3)
        variances.append(np.where(count > 1, spread, 1.0))
    return variances


def second_order_features(frames, nodes, offsets, means, variances, center, scale, power):
    """Per clip and node, the mean of ``(z - mean) ** 2 / variance - 1`` over its frames there.

    A Fisher vector's variance terms over a layer's nodes (without their
    constant factors), with ``z = (x - center) / scale``: how much more or less
    the clip's frames spread within each node than the training frames did.
    Each layer's block is raised to ``power`` with its sign and scaled to unit
    norm, like the residuals.

    Parameters
    ----------
    frames : ndarray of shape (n_frames, n_channels)
        Raw frames.
    nodes, offsets, means, center, scale, power : as for :func:`residual_features`
    variances : list of ndarray of shape (n_nodes(layer), n_channels)
        From :func:`node_variances` on the training frames.

    Returns
    -------
    features : ndarray of shape (n_clips, sum(n_nodes(layer) * n_channels))
    """
    n_clips = len(offsets) - 1
    # sum (z - m)^2 = sum z^2 - 2 m sum z + share m^2 per group: two sparse sums of one centred
    # copy per layer, no per-frame gather of the node's mean (z and m are in standardised units,
    # a few at most, so the expansion loses nothing that matters)
    centred = np.subtract(frames, center)
    squares = centred * centred
    clip_weights = _clip_weights(offsets)
    blocks = []
    for j, (mean, variance) in enumerate(zip(means, variances)):
        k = len(mean)
        (first, second), share = _node_averages([centred, squares], nodes[:, j], clip_weights, k)
        mean_rows, variance_rows = np.tile(mean, (n_clips, 1)), np.tile(variance, (n_clips, 1))
        spread = second / scale**2 - 2 * mean_rows * first / scale + share * mean_rows**2
        block = (spread / variance_rows - share).reshape(n_clips, -1)
        blocks.append(_signed_power_unit_norm(block, power))
    return np.concatenate(blocks, axis=1) if blocks else np.zeros((n_clips, 0))
