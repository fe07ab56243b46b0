"""A motion tree built from the caller's clips, without a stacked copy of their frames.

``MotionTreeEncoder.fit`` over many frames (see ``_LEAN_FROM_FRAMES`` there) builds its
tree here; it used to stack and standardise all frames in a copy of its own, as much
memory again as the caller's clips. The in-memory build (``_nodes``) is cut in two,
as the out-of-core build (``_out_of_core``) cuts it, but without its rounding:

1. *The root, streamed.* The clips are read as the stacked array's consecutive row
   blocks, standardised in a buffer (``StackedClips``). The root's mean (NumPy's sum,
   row after row, carried from block to block), its sums and products about that mean
   (``shifted_moments`` adding each block's chunks into the running sums, as one call
   over all rows adds them), the frames' range (the gap resolution) and the projections
   on its axis (``project_rows``' blocks, from the first row) are the doubles the
   in-memory build computes over a stacked copy; its cut is the same.
2. *Each child in a copy of its own frames*, one after the other: the frames in the
   order the in-place build's partition leaves them (``partition_rows`` run on the
   projections alone gives that order), built by the in-memory builder given what the
   whole build gives the node, the root's mean and kept scatter and, for the second
   child, the first one's products (the smaller child first, as the whole build does).

The nodes are put together and numbered as the out-of-core build does (``_Nodes``).
The tree is the in-memory build's to the bit (``tests/tree/test_lean_fitting.py``);
the build holds the caller's clips, the larger child's frames (about half of them with
median cuts) and 8 bytes a frame besides (each frame's place in its child), and 24
while the root is cut.
"""

import numpy as np

from skmotion.tree._build._node_passes import moment_chunk_rows, partition_rows, shifted_moments
from skmotion.tree._build._nodes import (
    _GAP_RESOLUTION,
    PROJECT_ROWS,
    _fix_signs,
    _principal_axis,
    _top_eigenvectors,
    build_subtree,
    cut_projections,
    kept_scatter,
    project_rows,
)
from skmotion.tree._build._out_of_core import _Nodes
from skmotion.tree._build._permute import scatter_rows
from skmotion.tree._build._standardise import carried_sum, standardise_in_place
from skmotion.tree._gaussian import estimate_covariance

__all__ = ["build_from_clips"]



def build_from_clips(stacked, params):
    """The :class:`MotionTree` that ``MotionTree.from_params`` builds over the stacked
    (standardised) frames, built from the clips without stacking them.

    Parameters
    ----------
    stacked : StackedClips
        The clips, with their ``center`` and ``scale`` set; at least as many frames as
        channels.
    params : TreeParams
        A diagonal or spherical covariance (a full one needs every frame's centred norm,
        which the streamed root does not keep).

    Returns
    -------
    tree : MotionTree
    """
    from skmotion.tree._motion_tree import MotionTree

    if params.covariance_type == "full" or stacked.n_frames < stacked.n_channels:
        raise ValueError("build_from_clips builds diagonal or spherical trees of n >= d frames.")
    n, d = stacked.n_frames, stacked.n_channels
    root = _stream_root(stacked, params)
    nodes = _Nodes()
    nodes.add(-1, 0, n)
    table = nodes.table
    table["mean"][0], table["cov"][0] = root["mean"], root["cov"]
    if root["n_left"] is not None:
        table["axis"][0], table["thr"][0] = root["axis"], root["thr"]
        sizes = (root["n_left"], n - root["n_left"])
        children = [nodes.add(0, 1, size) for size in sizes]
        table["left"][0], table["right"][0] = children
        first = int(sizes[1] < sizes[0])  # the smaller first, as _Builder.process_family
        sibling = None
        for side in (first, 1 - first):
            sub, sibling = _build_child(stacked, params, root, side, sibling)
            nodes.graft(children[side], sub)
    return MotionTree(
        **nodes.arrays(d),
        covariance_type=params.covariance_type,
        reg=root["reg"],
        principal_axes=_fix_signs(_top_eigenvectors(root["scatter"], 3)[1].T),
    )


def _stream_root(stacked, params):
    """The root's Gaussian, axis and cut, as ``_Builder.process`` makes them over the
    stacked frames, from three passes over the clips; and each frame's place in its child."""
    n, d = stacked.n_frames, stacked.n_channels
    extremes = []  # each block's largest and smallest value: the gap resolution's range

    def noting_extremes(pairs):
        for pair in pairs:
            extremes.append((float(pair[1][1:].max()), float(pair[1][1:].min())))
            yield pair

    total = carried_sum(noting_extremes(stacked.blocks(PROJECT_ROWS, spare_row=True)))
    high, low = max(e[0] for e in extremes), min(e[1] for e in extremes)
    shift = total / n  # block.mean(axis=0) of the stacked frames
    out = (np.zeros(d), np.zeros((d, d)))
    chunk = moment_chunk_rows(d)  # blocks of whole chunks, about PROJECT_ROWS rows
    for _, block in stacked.blocks(chunk * max(1, PROJECT_ROWS // chunk)):
        shifted_moments(block, shift, True, out=out)
    sums, products = out
    scatter = products - np.outer(sums, sums / n)
    scale = np.trace(scatter) / (n * d)
    reg = params.reg_covar * scale if scale > 0 else float(params.reg_covar)
    root = {
        "mean": shift + sums / n,
        "cov": estimate_covariance(scatter, n, params.covariance_type, reg, None),
        "scatter": scatter,
        "reg": reg,
        "tol": _GAP_RESOLUTION * d * max(high, -low),
        "n_left": None,
    }
    min_split = max(params.min_samples_split, 2 * params.min_samples_leaf, 2)
    if (params.max_depth is not None and params.max_depth < 1) or n < min_split:
        return root
    axis = _principal_axis(None, scatter)
    if axis is None:
        return root
    proj = np.empty(n)
    for start, block in stacked.blocks(PROJECT_ROWS):
        project_rows(block, axis, out=proj[start : start + len(block)])
    n_left, thr = cut_projections(proj, params.split, params.min_samples_leaf, root["tol"])
    if n_left is None:
        return root
    # where the in-place partition puts each frame: the rows are not needed for that
    index = np.arange(n)
    if partition_rows(np.empty((n, 0)), proj, thr, index) != n_left:  # pragma: no cover
        raise RuntimeError(f"the root's cut does not separate {n_left} frames.")
    del proj
    place = np.empty(n, dtype=np.intp)
    place[index] = np.arange(n)
    root.update(
        axis=axis,
        thr=thr,
        n_left=n_left,
        place=place,
        kept=kept_scatter(scatter, None, n, d, params.covariance_type),
    )
    return root


def _build_child(stacked, params, root, side, sibling):
    """The subtree of the root's child on ``side`` (0 left, 1 right), built in a copy of
    its frames; returns its nodes (as ``_Nodes.graft`` takes them) and its top's result."""
    n_left, place = root["n_left"], root["place"]
    offset = 0 if side == 0 else n_left
    stop = n_left if side == 0 else stacked.n_frames
    frames = np.empty((stop - offset, stacked.n_channels))
    for start, block in stacked.blocks(PROJECT_ROWS, raw=True):
        scatter_rows(block, place[start : start + len(block)], offset, stop, frames)
    standardise_in_place(frames, stacked.center, stacked.scale)  # the same doubles
    top = {"shift": root["mean"], "kept": root["kept"], "sibling": sibling}
    depth = None if params.max_depth is None else params.max_depth - 1
    return build_subtree(frames, params, depth, root["tol"], root["reg"], top)
