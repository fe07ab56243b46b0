"""A motion tree built out of core: the top layers from streamed statistics, each subtree on a worker.

The frames stay where they are (``.npy`` files or a ``dask.array``, see
``_frame_sources``) and are read in blocks by Dask tasks. The build is the in-memory
one (``_nodes``), cut in two:

1. *Top layers, streamed.* For the nodes that hold more than ``max_frames_per_task``
   frames, one pass over all chunks sums each node's count, mean and scatter (per
   block about the block's mean, merged with Chan, Golub and LeVeque's pairwise
   update), from which the client takes the node's Gaussian and first principal axis;
   a second pass returns the frames' projections on their node's axis (one number
   per frame), which the client sorts and cuts with the same criterion, gap rule and
   threshold (the midpoint) as the in-memory build. The first pass also gives the
   frames' range (the gap resolution) and the root's variance (the regularisation).
2. *Subtrees, in memory on a worker.* A pass writes each frame to a spill file of the
   node at which the streamed layers leave it (a node of at most
   ``max_frames_per_task`` frames); one task per such node reads its frames, in their
   order, and builds its subtree with the in-memory builder, under the whole build's
   gap resolution and regularisation.

The nodes are then numbered as the in-memory build numbers them (breadth first, left
before right). The splits are those of the in-memory build on the same frames up to
rounding: the streamed sums and the subtrees' frame order differ from the in-memory
build's, so a projection within a few units of rounding of a cut can fall on the other
side (``docs/scaling.md`` measures how many frames do).
"""

import math
import os
import resource
import shutil
import tempfile
import uuid
from pathlib import Path

import numpy as np

from skmotion.tree._build._frame_sources import BLOCK_ROWS, chunk_sources, read_blocks
from skmotion.tree._build._nodes import (
    _GAP_RESOLUTION,
    build_subtree,
    _fix_signs,
    _principal_axis,
    _top_eigenvectors,
)
from skmotion.tree._build._params import PAPER_TREE, TreeParams
from skmotion.tree._build._split import best_split
from skmotion.tree._gaussian import estimate_covariance
from skmotion.utils._progress import say

__all__ = ["build_tree_out_of_core"]


def _dask():
    try:
        import dask
    except ImportError as exc:
        raise ImportError(
            'build_tree_out_of_core needs Dask: pip install "skmotion[distributed]".'
        ) from exc
    return dask


# -- the tasks (run on the workers) ---------------------------------------------------


def _route(block, partial):
    """Each frame's node in the streamed part of the tree (``partial``: its splits)."""
    node = np.zeros(len(block), dtype=np.intp)
    for nid in partial["split_order"]:  # parents before children
        idx = np.flatnonzero(node == nid)
        if len(idx):
            proj = block[idx] @ partial["axis"][nid]  # as the build projects a node's block
            node[idx] = np.where(
                proj > partial["thr"][nid], partial["right"][nid], partial["left"][nid]
            )
    return node


def _merge(a, b):
    """Count, mean and scatter of two sets of frames from theirs (pairwise update)."""
    if a is None:
        return b
    (na, ma, sa), (nb, mb, sb) = a, b
    n = na + nb
    delta = mb - ma
    return n, ma + delta * (nb / n), sa + sb + np.outer(delta, delta) * (na * nb / n)


def _moments_task(name, source, d, partial, open_ids, rows):
    """Per open node: count, mean and scatter of the chunk's frames there; and their range."""
    stats = dict.fromkeys(open_ids)
    high, low = -np.inf, np.inf
    for _, block in read_blocks(name, source, d, rows):
        high, low = max(high, float(block.max())), min(low, float(block.min()))
        node = _route(block, partial)
        for nid in open_ids:
            part = block[node == nid]
            if len(part):
                mean = part.mean(axis=0)
                part -= mean
                stats[nid] = _merge(stats[nid], (len(part), mean, part.T @ part))
    return stats, high, low


def _projection_task(name, source, d, partial, axes, rows):
    """Per node to split: the projections of the chunk's frames there on its axis."""
    out = {nid: [] for nid in axes}
    for _, block in read_blocks(name, source, d, rows):
        node = _route(block, partial)
        for nid, axis in axes.items():
            out[nid].append(block[node == nid] @ axis)
    return {nid: np.concatenate(parts) for nid, parts in out.items()}


def _spill_task(name, source, d, partial, closed_ids, folder, chunk, rows):
    """Write the chunk's frames of each closed node to a file of their own (raw float64)."""
    final = {nid: Path(folder) / f"node{nid}_chunk{chunk}.raw" for nid in closed_ids}
    partial_paths = {
        nid: path.with_suffix(f".{uuid.uuid4().hex}.tmp") for nid, path in final.items()
    }
    counts = dict.fromkeys(closed_ids, 0)
    files = {nid: open(path, "wb") for nid, path in partial_paths.items()}
    try:
        for _, block in read_blocks(name, source, d, rows):
            node = _route(block, partial)
            for nid in closed_ids:
                part = block[node == nid]
                part.tofile(files[nid])
                counts[nid] += len(part)
    finally:
        for file in files.values():
            file.close()
    for nid in closed_ids:  # whole files only: written under a temporary name, then renamed
        os.replace(partial_paths[nid], final[nid])
    return {nid: (str(final[nid]), counts[nid]) for nid in closed_ids}


def _subtree_task(pieces, d, params, max_depth, tol, reg):
    """Build the subtree of one node in memory from its spilled frames, in chunk order."""
    total = sum(count for _, count in pieces)
    X = np.empty((total, d))
    at = 0
    for path, count in pieces:
        X[at : at + count] = np.fromfile(path, dtype=np.float64, count=count * d).reshape(count, d)
        at += count
    sub, _ = build_subtree(X, params, max_depth, tol, reg)
    peak_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    return {
        **sub,
        "frames_held": total,
        "peak_rss_mb": peak_mb,
        "pid": os.getpid(),
    }


# -- the client's side ---------------------------------------------------------------


class _Nodes:
    """The tree's nodes as the client learns them (ids in order of discovery)."""

    def __init__(self):
        self.table = {
            key: []
            for key in ("parent", "depth", "count", "mean", "cov", "axis", "thr", "left", "right")
        }

    def add(self, parent, depth, count):
        values = (parent, depth, count, None, None, None, np.nan, -1, -1)
        for key, value in zip(self.table, values):
            self.table[key].append(value)
        return len(self.table["parent"]) - 1

    def partial(self):
        """The splits so far, for routing frames in the tasks."""
        t = self.table
        split_order = [i for i, left in enumerate(t["left"]) if left >= 0]
        return {
            "split_order": split_order,
            "axis": {i: t["axis"][i] for i in split_order},
            "thr": {i: t["thr"][i] for i in split_order},
            "left": {i: t["left"][i] for i in split_order},
            "right": {i: t["right"][i] for i in split_order},
        }

    def graft(self, nid, sub):
        """Put a subtree's nodes under node ``nid`` (the subtree's root is ``nid`` itself)."""
        ids = [nid] + [self.add(-1, 0, 0) for _ in range(1, len(sub["parent"]))]
        t = self.table
        for k, gid in enumerate(ids):
            if k:
                t["parent"][gid] = ids[sub["parent"][k]]
                t["depth"][gid] = t["depth"][nid] + sub["depth"][k]
                t["count"][gid] = sub["count"][k]
            t["mean"][gid], t["cov"][gid] = sub["mean"][k], sub["cov"][k]
            t["axis"][gid], t["thr"][gid] = sub["axis"][k], sub["thr"][k]
            t["left"][gid] = ids[sub["left"][k]] if sub["left"][k] >= 0 else -1
            t["right"][gid] = ids[sub["right"][k]] if sub["right"][k] >= 0 else -1

    def arrays(self, d):
        """The per-node arrays and layers of ``MotionTree``, numbered as the in-memory build."""
        t = self.table
        new = {0: 0}
        order, layers, layer, depth = [0], [np.array([0])], [0], 0
        while True:  # breadth first, left before right, a leaf copied down: _Builder.run's order
            nxt, grew = [], False
            for node in layer:
                if t["depth"][node] == depth and t["left"][node] >= 0:
                    for child in (t["left"][node], t["right"][node]):
                        new[child] = len(order)
                        order.append(child)
                        nxt.append(child)
                    grew = True
                else:
                    nxt.append(node)
            if not grew:
                break
            layer, depth = nxt, depth + 1
            layers.append(np.array([new[n] for n in nxt], dtype=np.intp))

        def remap(ids):
            return np.array([new[i] if i >= 0 else -1 for i in ids], dtype=np.intp)

        return {
            "parent": remap([t["parent"][n] for n in order]),
            "left": remap([t["left"][n] for n in order]),
            "right": remap([t["right"][n] for n in order]),
            "depth": np.array([t["depth"][n] for n in order], dtype=np.intp),
            "count": np.array([t["count"][n] for n in order], dtype=np.intp),
            "mean": np.array([t["mean"][n] for n in order]),
            "covariance": np.array([t["cov"][n] for n in order]),
            "axis": np.array(
                [np.zeros(d) if t["axis"][n] is None else t["axis"][n] for n in order]
            ),
            "threshold": np.array([t["thr"][n] for n in order], dtype=np.float64),
            "layers": layers,
        }


def build_tree_out_of_core(
    frames,
    *,
    max_depth=PAPER_TREE.max_depth,
    min_samples_split=PAPER_TREE.min_samples_split,
    min_samples_leaf=PAPER_TREE.min_samples_leaf,
    split=PAPER_TREE.split,
    covariance_type=PAPER_TREE.covariance_type,
    reg_covar=PAPER_TREE.reg_covar,
    max_frames_per_task=None,
    spill_dir=None,
    block_rows=BLOCK_ROWS,
    verbose=0,
):
    """Build a :class:`MotionTree` over frames that need not fit in memory, with Dask.

    The tasks run on Dask's active scheduler: a ``distributed.Client`` when one is
    active (each subtree on its own worker), else Dask's default local one. The top
    layers are found from streamed statistics and each node of at most
    ``max_frames_per_task`` frames is built in memory by one task (see the module's
    description); the result equals :meth:`MotionTree.build` on the same frames up to
    rounding (a frame within rounding of a cut may fall on the other side; measured in
    the user guide, ``docs/scaling.md``).

    Parameters
    ----------
    frames : list of path-like, or dask.array.Array of shape (n_frames, n_channels)
        ``.npy`` files of float frames, one after the other, or a 2-D ``dask.array``.
        Every worker must be able to read the files.
    max_depth, min_samples_split, min_samples_leaf, split, covariance_type, reg_covar
        As for :meth:`MotionTree.build` (and its defaults); ``covariance_type="full"``
        is refused (its Ledoit-Wolf shrinkage needs every frame's centred norm, which
        the streamed layers do not keep).
    max_frames_per_task : int, default=None
        The most frames one task holds in memory (besides a block); None: a quarter of
        all frames.
    spill_dir : path-like, default=None
        Where the subtrees' frames are written between the passes (about the frames'
        size on disk; shared by all workers); None: a new temporary directory. The
        files are removed at the end.
    block_rows : int, default=65536
        Frames read at once by a task.
    verbose : int, default=0
        1 or more reports the passes on standard error.

    Returns
    -------
    tree : MotionTree
        With ``tree.build_report_`` (a dict): the frames, the streamed layers'
        nodes, and for each subtree task its frames and the worker's peak memory.

    Examples
    --------
    >>> import numpy as np, pytest, tempfile, os
    >>> _ = pytest.importorskip("dask")  # pip install "skmotion[distributed]"
    >>> from skmotion.tree import MotionTree, build_tree_out_of_core
    >>> rng = np.random.default_rng(0)
    >>> frames = np.r_[rng.normal(0, 1, (3000, 3)), rng.normal(8, 1, (1000, 3))]
    >>> folder = tempfile.mkdtemp()
    >>> paths = [os.path.join(folder, f"part{i}.npy") for i in range(2)]
    >>> for path, part in zip(paths, np.array_split(frames, 2)):
    ...     np.save(path, part)
    >>> tree = build_tree_out_of_core(paths, max_depth=4, split="median", min_samples_leaf=16)
    >>> memory = MotionTree.build(frames, max_depth=4, split="median", min_samples_leaf=16)
    >>> tree.n_nodes.tolist() == memory.n_nodes.tolist()
    True
    >>> float(np.mean(tree.apply(frames) == memory.apply(frames)))
    1.0
    """
    dask = _dask()
    params = TreeParams(
        max_depth=max_depth,
        min_samples_split=min_samples_split,
        min_samples_leaf=min_samples_leaf,
        split=split,
        covariance_type=covariance_type,
        reg_covar=reg_covar,
    )
    if covariance_type == "full":
        raise ValueError(
            "build_tree_out_of_core does not build covariance_type='full' (its shrinkage "
            "needs every frame's centred norm); use 'diag' or 'spherical', or MotionTree.build."
        )
    chunks, d = chunk_sources(frames)
    nodes, report = _Nodes(), {"streamed_nodes": 0, "subtrees": []}
    nodes.add(-1, 0, 0)
    open_ids, closed, state = [0], [], {}
    while open_ids:
        say(verbose, f"build_tree_out_of_core: streaming {len(open_ids)} node(s)")
        open_ids = _stream_layer(
            dask, chunks, d, nodes, open_ids, closed, params, state, max_frames_per_task, block_rows
        )
    report.update(n_frames=state["n"], streamed_nodes=len(nodes.table["parent"]) - len(closed))
    folder = Path(tempfile.mkdtemp(dir=spill_dir, prefix="skmotion-spill-"))
    try:
        if closed:
            _build_subtrees(
                dask, chunks, d, nodes, closed, params, state, folder, block_rows, report, verbose
            )
    finally:
        shutil.rmtree(folder, ignore_errors=True)
    from skmotion.tree._motion_tree import MotionTree

    tree = MotionTree(
        **nodes.arrays(d),
        covariance_type=covariance_type,
        reg=state["reg"],
        principal_axes=_fix_signs(_top_eigenvectors(state["root_scatter"], 3)[1].T),
    )
    tree.build_report_ = report
    return tree


def _stream_layer(dask, chunks, d, nodes, open_ids, closed, params, state, budget, rows):
    """Two passes for the open nodes: their Gaussians and axes, then their cuts. Returns
    the children still too large for one task; the others join ``closed``."""
    partial = nodes.partial()
    tasks = [
        dask.delayed(_moments_task)(name, src, d, partial, open_ids, rows) for name, src in chunks
    ]
    results = dask.compute(*tasks)
    t = nodes.table
    merged = dict.fromkeys(open_ids)
    for stats, _, _ in results:
        for nid in open_ids:
            if stats[nid] is not None:
                merged[nid] = _merge(merged[nid], stats[nid])
    if "n" not in state:  # the root: the whole build's gap resolution and regularisation
        high = max(r[1] for r in results)
        low = min(r[2] for r in results)
        n, _, scatter = merged[0]
        state["n"], state["root_scatter"] = n, scatter
        state["tol"] = _GAP_RESOLUTION * d * max(high, -low)
        scale = np.trace(scatter) / (n * d)
        state["reg"] = params.reg_covar * scale if scale > 0 else float(params.reg_covar)
        state["budget"] = budget or max(1, math.ceil(n / 4))
        t["count"][0] = n
    axes = {}
    min_split = max(params.min_samples_split, 2 * params.min_samples_leaf, 2)
    for nid in open_ids:
        n, mean, scatter = merged[nid]
        t["mean"][nid] = mean
        t["cov"][nid] = estimate_covariance(scatter, n, params.covariance_type, state["reg"])
        may_split = params.max_depth is None or t["depth"][nid] < params.max_depth
        axis = _principal_axis(None, scatter) if may_split and n >= min_split else None
        if axis is not None:
            axes[nid] = axis
    if not axes:
        return []
    tasks = [
        dask.delayed(_projection_task)(name, src, d, partial, axes, rows) for name, src in chunks
    ]
    projections = dask.compute(*tasks)
    next_open = []
    for nid, axis in axes.items():
        ordered = np.sort(np.concatenate([p[nid] for p in projections]))
        n_left = best_split(
            ordered, params.split, min_samples_leaf=params.min_samples_leaf, tol=state["tol"]
        )
        if n_left is None:
            continue
        t["axis"][nid], t["thr"][nid] = axis, 0.5 * (ordered[n_left - 1] + ordered[n_left])
        for side, count in (("left", n_left), ("right", len(ordered) - n_left)):
            child = nodes.add(nid, t["depth"][nid] + 1, count)
            t[side][nid] = child
            (next_open if count > state["budget"] else closed).append(child)
    return next_open


def _build_subtrees(dask, chunks, d, nodes, closed, params, state, folder, rows, report, verbose):
    """Spill each closed node's frames, then build its subtree in one task, and graft it."""
    partial = nodes.partial()
    say(verbose, f"build_tree_out_of_core: spilling the frames of {len(closed)} subtree(s)")
    tasks = [
        dask.delayed(_spill_task)(name, src, d, partial, closed, str(folder), i, rows)
        for i, (name, src) in enumerate(chunks)
    ]
    spilled = dask.compute(*tasks)
    t = nodes.table
    jobs = []
    for nid in closed:
        pieces = [s[nid] for s in spilled if s[nid][1]]
        depth_left = None if params.max_depth is None else params.max_depth - t["depth"][nid]
        jobs.append(
            dask.delayed(_subtree_task)(pieces, d, params, depth_left, state["tol"], state["reg"])
        )
    say(verbose, f"build_tree_out_of_core: building {len(closed)} subtree(s)")
    for nid, sub in zip(closed, dask.compute(*jobs)):
        nodes.graft(nid, sub)
        report["subtrees"].append(
            {k: sub[k] for k in ("frames_held", "peak_rss_mb", "pid")} | {"node": nid}
        )
