"""Building the motion tree: principal axes and 1-D cuts, layer by layer.

A node's frames are centred and projected on their first principal axis, and
the sorted projections are cut in two by a 1-D criterion (minimum-error
thresholding by default); nodes split until they are too small or the tree is
deep enough. A node that stops early is copied down, so every layer holds all
frames. Building costs one sort of the projections and one ``n x d`` scatter per
split node (for the smaller of two siblings; the other's is the parent's minus it):
O(N log N) for N frames when the tree is about ``log N`` deep. There are no
pairwise distances and no Python loop over frames (only over nodes); the passes
over a node's rows are compiled (``_node_passes.pyx``).
"""

from concurrent.futures import ThreadPoolExecutor

import numpy as np
from scipy.linalg import eigh
from scipy.linalg.lapack import dsyevr

from skmotion.tree._build._node_passes import partition_rows, shifted_moments
from skmotion.tree._build._permute import permute_rows
from skmotion.tree._build._split import best_split
from skmotion.tree._gaussian import centred_moments, estimate_covariance, low_rank_covariance

__all__ = ["build_nodes", "build_subtree", "project_rows"]

# A cut must sit in a gap wider than this many units of the projections'
# rounding error, so routing a training frame again always finds the same side.
_GAP_RESOLUTION = 1e-12
# The fewest frames a thread is handed at once when the nodes of a layer are processed
# in threads.
_TASK_FRAMES = 1 << 16
# A child's scatter may be the parent's minus its sibling's (no pass over its rows) when
# the parent has at least this many rows per channel (the parent's d x d scatter is kept
# until its children are built: at most a 64th of the rows' memory). The bound on the
# rounding of a scatter summed directly, relative to its trace, and the largest relative
# error bound a derived scatter may have (else it is summed from its rows).
_KEEP_ROWS_PER_CHANNEL = 64
_SUM_ROUNDING = 1e-13
_DERIVED_ACCURACY = 1e-9
# Rows projected by one matrix-vector product: a node's projections are made block by block
# from its first row, so a build fed the same rows a block at a time (the encoder's lean fit,
# ``_clip_build``) gets the same doubles whatever the BLAS kernel's own blocking is.
PROJECT_ROWS = 1 << 15


def project_rows(block, axis, out=None):
    """``block @ axis``, in products of ``PROJECT_ROWS`` rows (into ``out`` when given)."""
    out = np.empty(len(block)) if out is None else out
    for start in range(0, len(block), PROJECT_ROWS):
        np.matmul(block[start : start + PROJECT_ROWS], axis, out=out[start : start + PROJECT_ROWS])
    return out


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
    """The unit first principal axis of a node (None when its frames do not vary).

    With fewer frames than channels, ``centred`` (the frames minus their mean)
    is given and the smaller ``n x n`` problem, which has the same axis, is solved.
    """
    if centred is None:
        values, vectors = _top_eigenvectors(scatter, 1)
        axis = vectors[:, 0]
    else:
        values, vectors = _top_eigenvectors(centred @ centred.T, 1)
        axis = centred.T @ vectors[:, 0]
    norm = float(np.sqrt(axis @ axis))
    if values[0] <= 0.0 or norm == 0.0:
        return None
    axis = axis / norm
    return -axis if axis[np.argmax(np.abs(axis))] < 0 else axis


def cut_projections(proj, split, min_samples_leaf, tol):
    """Where a node's projections are cut: the frames on the left and the threshold
    (None, nan when no cut is allowed)."""
    ordered = np.sort(proj)
    n_left = best_split(ordered, split, min_samples_leaf=min_samples_leaf, tol=tol)
    if n_left is None:
        return None, np.nan
    # the cut sits in a gap far wider than rounding, so it separates the sides exactly
    return n_left, 0.5 * (ordered[n_left - 1] + ordered[n_left])


def kept_scatter(scatter, raw, n, d, covariance_type):
    """What a split node keeps for its children's derived scatters: its scatter and an
    error bound (None with too few rows per channel, or for a full covariance)."""
    if n < _KEEP_ROWS_PER_CHANNEL * d or covariance_type == "full":
        return None
    error = 0.0 if raw is None else raw[2]
    return scatter, error + _SUM_ROUNDING * np.trace(scatter)


class _Builder:
    """Breadth-first construction on the frames reordered so that every node's frames
    are one contiguous block (splitting a node partitions its block in place).

    The frames are a copy, or with ``copy=False`` the caller's own array, whose
    order is put back after the build (``index`` follows every row). With
    ``n_jobs`` above 1 the nodes of a layer are processed in that many threads (the
    passes over the frames release the GIL); every node is computed as it would be
    alone, so the tree does not depend on ``n_jobs``.

    ``top`` builds the subtree of a node of a larger tree alone (the encoder's lean fit,
    ``_clip_build``): the node's parent's mean ``"shift"``, the parent's kept scatter
    ``"kept"`` and its sibling's products ``"sibling"`` (or None), with which the node's
    moments are the doubles the whole build gives it; ``tol`` and ``reg`` are then set by
    the caller (the whole build's). The top node's result is kept in ``top_result``."""

    def __init__(
        self,
        X,
        max_depth,
        min_samples_split,
        min_samples_leaf,
        split,
        covariance_type,
        reg_covar,
        copy=True,
        n_jobs=1,
        top=None,
    ):
        self.top = top
        self.top_result = None
        # Rounding of a projection x @ axis is below d * eps * max|x|; cuts must
        # sit in gaps far wider, so a training frame always routes back to its side.
        self.tol = _GAP_RESOLUTION * X.shape[1] * max(float(X.max()), -float(X.min()))
        self.blocks = X.copy() if copy else X
        self.index = None if copy else np.arange(len(X))
        self.reg_covar = reg_covar
        self.reg = None  # set from the root's variance
        self.root_scatter = None
        self.max_depth = max_depth
        self.min_split = max(min_samples_split, 2 * min_samples_leaf, 2)
        self.min_leaf = min_samples_leaf
        self.split = split
        self.kind = covariance_type
        self.n_jobs = n_jobs
        self.kept = {}  # per split node of the last layer: its scatter and an error bound
        self.nodes = {
            k: []
            for k in (
                "parent",
                "depth",
                "start",
                "stop",
                "mean",
                "cov",
                "low_rank",
                "axis",
                "thr",
                "left",
                "right",
            )
        }

    def add(self, parent, depth, start, stop):
        for key, value in zip(("parent", "depth", "start", "stop"), (parent, depth, start, stop)):
            self.nodes[key].append(value)
        for key, value in (
            ("left", -1),
            ("right", -1),
            ("axis", None),
            ("thr", np.nan),
            ("mean", None),
            ("cov", None),
            ("low_rank", None),
        ):
            self.nodes[key].append(value)
        return len(self.nodes["parent"]) - 1

    def moments(self, node, block, scatter, sibling=None):
        """The node's mean, scatter and squared centred norms (None unless ``"full"``),
        and the products about the parent's mean it was computed from (or None).

        Without ``scatter`` (a node that will not be split, under a diagonal or
        spherical covariance, which need only the scatter's diagonal) the scatter
        is diagonal: the off-diagonal products are not computed. The sums are taken
        about the parent's mean (the root's own, computed first), close to the node's.
        With the ``sibling``'s products, the scatter is the parent's minus the
        sibling's (no pass over the rows), unless too much would be lost to
        cancellation (see :meth:`derived`).
        """
        if self.kind == "full":  # Ledoit-Wolf needs every frame's centred norm
            return (*centred_moments(block), None)
        n = len(block)
        parent = self.nodes["parent"][node]
        top = self.top if parent < 0 else None  # a subtree's top: its parent is elsewhere
        if top is not None:
            shift, kept, sibling = top["shift"], top["kept"], top["sibling"]
        else:
            shift = block.mean(axis=0) if parent < 0 else self.nodes["mean"][parent]
            kept = self.kept.get(parent)
        raw = self.derived(kept, sibling) if scatter else None
        if raw is None:
            raw = (*shifted_moments(block, shift, scatter), 0.0)
        sums, products, error = raw
        mean = shift + sums / n
        if not scatter:  # a constant channel may round a hair below zero
            return mean, np.diag(np.maximum(products - sums * (sums / n), 0.0)), None, None
        scatter = products - np.outer(sums, sums / n)
        # the error bound of the products: a direct sum's rounding, or what the derivation's was
        raw = (sums, products, error or _SUM_ROUNDING * np.trace(products))
        return mean, scatter, None, raw if parent >= 0 or top is not None else None

    @staticmethod
    def derived(kept, sibling):
        """The products about the parent's mean, ``(sums, products, error)``, as the
        parent's kept scatter minus the sibling's products; None when the parent's scatter
        was not kept, or when its error bound exceeds ``_DERIVED_ACCURACY`` of the result
        (a node with far less spread than its parent: the difference would cancel)."""
        if kept is None or sibling is None or sibling.get("raw") is None:
            return None
        parent_scatter, parent_error = kept
        sums, products, error = sibling["raw"]
        mine = parent_scatter - products
        error = (
            parent_error + error + _SUM_ROUNDING * (np.trace(parent_scatter) + np.trace(products))
        )
        if not error <= _DERIVED_ACCURACY * np.trace(mine):
            return None
        return -sums, mine, error

    def process(self, node, may_split, sibling=None):
        """The node's Gaussian and, when allowed and possible, its split (the block
        partitioned in place); returns what :meth:`record` enters in the tree."""
        nodes = self.nodes
        start, stop = nodes["start"][node], nodes["stop"][node]
        block = self.blocks[start:stop]
        n, d = block.shape
        may_split = may_split and n >= self.min_split
        root = nodes["parent"][node] < 0 and self.top is None
        mean, scatter, sq_norms, raw = self.moments(node, block, may_split or root, sibling)
        if self.reg is None:  # the root: reg_covar is relative to its mean per-channel variance
            scale = np.trace(scatter) / (n * d)
            self.reg = self.reg_covar * scale if scale > 0 else float(self.reg_covar)
        if root:
            self.root_scatter = scatter
        result = {"mean": mean, "cov": estimate_covariance(scatter, n, self.kind, self.reg, sq_norms)}
        result["raw"] = raw
        if self.kind == "full" and n <= d:  # the covariance is low rank plus a floor
            result["low_rank"] = low_rank_covariance(block - mean, scatter, sq_norms, self.reg)
        if nodes["parent"][node] < 0:
            self.top_result = result
        if not may_split:
            return result
        axis = _principal_axis(block - mean if n < d else None, scatter)
        if axis is None:
            return result
        proj = project_rows(block, axis)  # as routing computes it
        n_left, thr = cut_projections(proj, self.split, self.min_leaf, self.tol)
        if n_left is None:
            return result
        index = None if self.index is None else self.index[start:stop]
        if partition_rows(block, proj, thr, index) != n_left:  # pragma: no cover - a bug
            raise RuntimeError(f"node {node}: the cut does not separate {n_left} frames.")
        result.update(axis=axis, thr=thr, n_left=n_left)
        kept = kept_scatter(scatter, raw, n, d, self.kind)
        if kept is not None:
            result["keep"] = kept
        return result

    def process_family(self, family, may_split):
        """``process`` of a node or of two siblings: the one with fewer rows first, whose
        products give the other's scatter."""
        if len(family) == 1:
            return [self.process(family[0], may_split)]
        sizes = [self.nodes["stop"][k] - self.nodes["start"][k] for k in family]
        first = int(sizes[1] < sizes[0])
        results = [None, None]
        results[first] = self.process(family[first], may_split)
        results[1 - first] = self.process(family[1 - first], may_split, results[first])
        return results

    def record(self, node, result):
        """Enter a node's Gaussian and split; add its children (None for a leaf)."""
        nodes = self.nodes
        for key in ("mean", "cov", "low_rank", "axis", "thr"):
            if key in result:
                nodes[key][node] = result[key]
        if "keep" in result:
            self.next_kept[node] = result["keep"]
        if "n_left" not in result:
            return ()
        start, stop, cut = nodes["start"][node], nodes["stop"][node], result["n_left"]
        depth = nodes["depth"][node] + 1
        left = self.add(node, depth, start, start + cut)
        right = self.add(node, depth, start + cut, stop)
        nodes["left"][node], nodes["right"][node] = left, right
        return (left, right)

    def process_layer(self, nodes, may_split, pool):
        """``process_family`` of each node or pair of siblings, in threads when there is
        a pool: consecutive families are grouped into tasks of at least ``_TASK_FRAMES``
        frames (a thread hand-off costs more than a small node's work)."""
        parents = self.nodes["parent"]
        families = []
        for node in nodes:  # siblings are consecutive: both children of a split are in the layer
            if families and parents[node] >= 0 and parents[families[-1][0]] == parents[node]:
                families[-1].append(node)
            else:
                families.append([node])
        tasks, task, frames = [], [], 0
        for family in families:
            task.append(family)
            frames += sum(self.nodes["stop"][k] - self.nodes["start"][k] for k in family)
            if frames >= _TASK_FRAMES or pool is None:
                tasks.append(task)
                task, frames = [], 0
        if task:
            tasks.append(task)

        def work(task):
            return [result for family in task for result in self.process_family(family, may_split)]

        done = map(work, tasks) if pool is None or len(tasks) < 2 else pool.map(work, tasks)
        return [result for group in done for result in group]

    def run(self):
        root = self.add(-1, 0, 0, len(self.blocks))
        layers = [np.array([root])]
        depth = 0
        pool = ThreadPoolExecutor(self.n_jobs) if self.n_jobs > 1 else None
        try:
            while True:
                may_split = self.max_depth is None or depth < self.max_depth
                current = [node for node in layers[-1] if self.nodes["depth"][node] == depth]
                results = dict(zip(current, self.process_layer(current, may_split, pool)))
                self.next_kept = {}  # the scatters this layer's splits keep for their children
                next_layer, grew = [], False
                for node in layers[-1]:  # a leaf of an upper layer is copied down
                    children = self.record(node, results[node]) if node in results else ()
                    grew |= bool(children)
                    next_layer.extend(children or (node,))
                self.kept = self.next_kept
                if not grew:
                    break
                layers.append(np.array(next_layer))
                depth += 1
        finally:
            if pool is not None:
                pool.shutdown()
        if self.index is not None:  # the caller's frames back in their order
            inverse = np.empty_like(self.index)
            inverse[self.index] = np.arange(len(self.index))
            self.index = None
            permute_rows(self.blocks, inverse)
        return layers


def build_subtree(frames, params, max_depth, tol, reg, top=None):
    """The subtree of one node of a larger build, built in ``frames`` (its own copy of the
    node's frames, reordered and not put back), under the whole build's gap resolution
    ``tol`` and regularisation ``reg`` (the out-of-core build's tasks, the lean fit's
    children; ``top``: as for ``_Builder``).

    Returns
    -------
    nodes : dict
        Per subtree node (the node itself first): ``parent``, ``depth``, ``count``,
        ``mean``, ``cov``, ``axis``, ``thr``, ``left``, ``right`` (lists).
    top_result : dict
        The node's own result (its products: a sibling built after it derives from them).
    """
    builder = _Builder(
        frames,
        max_depth,
        params.min_samples_split,
        params.min_samples_leaf,
        params.split,
        params.covariance_type,
        params.reg_covar,
        copy=False,
        top=top,
    )
    builder.index = None  # the frames are the caller's copy: their order is not put back
    builder.tol, builder.reg = tol, reg  # the whole build's, not this node's
    builder.run()
    t = builder.nodes
    sub = {key: t[key] for key in ("parent", "depth", "mean", "cov", "axis", "thr", "left", "right")}
    sub["count"] = [b - a for a, b in zip(t["start"], t["stop"])]
    return sub, builder.top_result


def build_nodes(
    X,
    *,
    max_depth,
    min_samples_split,
    min_samples_leaf,
    split,
    covariance_type,
    reg_covar,
    copy=True,
    n_jobs=1,
):
    """Grow the tree over validated frames; the per-node arrays and the layers.

    Parameters
    ----------
    X : ndarray of shape (n_frames, n_channels)
        C-contiguous, finite float64 frames.
    copy : bool, default=True
        False: work in ``X`` itself (no copy of the frames), which is reordered
        during the build and put back in its order at the end (the same values).
    n_jobs : int, default=1
        Threads processing the nodes of a layer (the same tree for any number).
    max_depth, min_samples_split, min_samples_leaf, split, covariance_type
        As for :meth:`MotionTree.build`.
    reg_covar : float
        Added to every variance, as a fraction of the mean per-channel variance
        of all frames (absolute when the frames do not vary).

    Returns
    -------
    nodes : dict
        ``parent``, ``left``, ``right``, ``depth``, ``count``, ``mean``,
        ``covariance``, ``low_rank`` (a list; see ``low_rank_covariance``, None for
        a node with more frames than channels or another covariance type),
        ``axis``, ``threshold`` (per tree node id), ``layers``,
        ``principal_axes`` (the first three axes of all frames) and ``reg`` (the
        absolute regularisation): the arguments of ``MotionTree``.
    """
    builder = _Builder(
        X,
        max_depth,
        min_samples_split,
        min_samples_leaf,
        split,
        covariance_type,
        reg_covar,
        copy,
        n_jobs,
    )
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
        "low_rank": nodes["low_rank"],
        "axis": np.array([np.zeros(d) if a is None else a for a in nodes["axis"]]),
        "threshold": np.array(nodes["thr"], dtype=np.float64),
        "layers": layers,
        "principal_axes": _fix_signs(_top_eigenvectors(builder.root_scatter, 3)[1].T),
        "reg": builder.reg,
    }
