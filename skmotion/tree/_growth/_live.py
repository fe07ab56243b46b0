"""A growing motion database: new clips join the tree and graphs without a rebuild.

Yamane, Yamaguchi and Nakamura build their database once, from all frames, and
list incremental learning as future work. Here new frames are routed down the
existing splits; every node they pass through merges their moments exactly
(:class:`~skmotion.tree._growth._moments.Moments`), and the transition counts of their
clips are added to the graphs. Local changes keep the tree the one the build
would make:

- a leaf is split by the build's rule (its frames' first principal axis, the
  same cut criterion and limits), recursively, as the build would, when it
  reaches ``min_samples_split`` frames (the build splits any node that large)
  or its frame count has grown ``split_growth`` times since it was last tried;
- a split node whose frame count has grown ``rebuild_growth`` times since its
  subtree was built has the subtree grown again from its frames: its axis and
  cut were chosen on a part of the frames it holds now. At the root this is
  the whole database, built again as ``fit`` builds it from all clips so far
  (standardisation included: see ``MotionTreeHMM.partial_fit``);
- a split node whose mean has moved more than ``rebuild_tol`` of its standard
  deviation (``sqrt(trace(cov) / d)`` when the split was made) is rebuilt
  locally too.

All of these need the frames, which the database keeps (the clips as given,
standardised when needed): a tree built by ``fit`` has none, so its nodes only
merge moments. Node statistics never depend on the order clips arrive in (up
to rounding); the structure does, through the moments at which nodes are
grown again.
"""

from dataclasses import replace
from numbers import Real

import numpy as np

from skmotion.tree._build import build_nodes
from skmotion.tree._growth._moments import Moments
from skmotion.tree._motion_tree import MotionTree
from skmotion.tree._transitions import TransitionGraphs

__all__ = [
    "LiveDatabase",
    "check_growth_params",
    "clip_counts",
    "node_moments",
    "regroup_graphs",
]


def check_growth_params(split_growth, rebuild_tol, rebuild_growth=None):
    """Check the growth parameters: the two growths None or > 1, ``rebuild_tol`` None or > 0.

    Returns them as the keywords of :meth:`LiveDatabase.add`.
    """
    for name, value in (("split_growth", split_growth), ("rebuild_growth", rebuild_growth)):
        if value is not None and not (
            isinstance(value, Real) and not isinstance(value, bool) and value > 1
        ):
            raise ValueError(f"{name} must be a number > 1 or None; got {value!r}.")
    if rebuild_tol is not None and not (
        isinstance(rebuild_tol, Real) and not isinstance(rebuild_tol, bool) and rebuild_tol > 0
    ):
        raise ValueError(f"rebuild_tol must be a positive number or None; got {rebuild_tol!r}.")
    return {
        "split_growth": split_growth,
        "rebuild_growth": rebuild_growth,
        "rebuild_tol": rebuild_tol,
    }


def node_moments(tree, frames, kind, n_nodes=None):
    """The moments of the frames that pass through each tree node, ``(n_tree_nodes,)`` sets.

    Nodes no frame reaches get zero counts.
    """
    n_nodes = tree.n_tree_nodes if n_nodes is None else n_nodes
    d = tree.n_channels
    shape = {"full": (n_nodes, d, d), "diag": (n_nodes, d), "spherical": (n_nodes,)}[kind]
    full = kind == "full"
    out = Moments(
        np.zeros(n_nodes, np.int64),
        np.zeros((n_nodes, d)),
        np.zeros(shape),
        kind,
        np.zeros((n_nodes, d)) if full else None,
        np.zeros(n_nodes) if full else None,
    )
    for layer, labels in enumerate(tree.iter_apply(frames)):
        ids = tree.layers[layer][labels]
        own = np.flatnonzero(tree.depth[ids] == layer)  # a copied leaf was counted above
        if not len(own):
            continue
        order = own[np.argsort(ids[own], kind="stable")]
        nodes, starts = np.unique(ids[order], return_index=True)
        out.put(nodes, out.take(nodes).merged(Moments.of(frames[order], starts, kind)))
    return out


def regroup_graphs(graphs, source, added=None):
    """Graphs reordered and extended, plus the counts of new clips.

    Parameters
    ----------
    graphs : TransitionGraphs
    source : ndarray of int of shape (n_new_graphs,)
        The old graph each new graph continues, or -1 for a new (empty) one.
    added : tuple of lists, default=None
        Per layer the counts ``(n_new_graphs * K, K)`` and visits
        ``(n_new_graphs, K)`` to add (see :func:`clip_counts`).
    """
    import scipy.sparse as sp

    same = len(source) == graphs.n_graphs and (source == np.arange(graphs.n_graphs)).all()
    out_counts, out_visits = [], []
    for layer in range(graphs.n_layers):
        c, v = graphs.count_matrix(layer), graphs.visits(layer)
        if not same:
            k = c.shape[1]
            padded = sp.vstack([c, sp.csr_matrix((k, k), dtype=np.int64)], format="csr")
            src = np.where(source < 0, graphs.n_graphs, source)
            c = padded[(src[:, None] * k + np.arange(k)).ravel()]
            v = np.vstack([v, np.zeros((1, k), np.int64)])[src]
        if added is not None:
            c, v = c + added[0][layer], v + added[1][layer]
        out_counts.append(c)
        out_visits.append(v)
    return TransitionGraphs(out_counts, out_visits, graphs.smoothing)


def clip_counts(tree, frames, offsets, graph_of_clip, n_graphs):
    """Per layer the transition counts and visits of clips, (as in :meth:`TransitionGraphs.count`).

    Without building the graphs' tables: ``partial_fit`` only adds these counts.
    """
    import scipy.sparse as sp

    graph_of_frame = np.repeat(graph_of_clip, np.diff(offsets))
    step = np.ones(offsets[-1], dtype=bool)
    step[offsets[1:] - 1] = False  # a clip's last frame has no successor
    src = np.flatnonzero(step)
    counts, visits = [], []
    for labels, k in zip(tree.iter_apply(frames), tree.n_nodes):
        rows = graph_of_frame[src] * k + labels[src]
        data = np.ones(len(rows), dtype=np.int64)
        counts.append(sp.csr_matrix((data, (rows, labels[src + 1])), shape=(n_graphs * k, k)))
        visits.append(
            np.bincount(graph_of_frame * k + labels, minlength=n_graphs * k).reshape(n_graphs, k)
        )
    return counts, visits


def _layers_of(left, right, root=0):
    """The layers of a tree given its children: a leaf is copied down to the bottom."""
    layers = [np.array([root], dtype=np.intp)]
    while (left[layers[-1]] >= 0).any():
        prev = layers[-1]
        split = left[prev] >= 0
        nxt = np.where(split[:, None], np.c_[left[prev], right[prev]], np.c_[prev, prev])
        keep = np.c_[np.ones(len(prev), bool), split]
        layers.append(nxt[keep].astype(np.intp))
    return layers


class LiveDatabase:
    """What ``partial_fit`` keeps between calls: node moments, clips and split bookkeeping.

    Parameters
    ----------
    tree : MotionTree
        The tree this state describes.
    moments : Moments
        Per tree node, the moments of its (standardised) frames.
    clips : list of ndarray or None
        The clips seen so far, as given (None: unknown, the tree came from ``fit``).
    center, scale : ndarray of shape (n_channels,)
        The standardisation of the tree's frames: ``(clip - center) / scale``.
    labels : list, default=None
        The label of each clip (kept with the clips: the graphs are counted
        again from them when the tree's layers change).
    """

    def __init__(self, tree, moments, clips, center, scale, labels=None):
        self.tree = tree
        self.moments = moments
        self.clips = clips
        self.labels = None if clips is None else list(labels)
        self.center, self.scale = center, scale
        self.checked = moments.count.copy()
        self.split_mean = moments.mean.copy()
        self.split_scale = _spread(moments)

    @classmethod
    def from_clips(cls, tree, clips, labels, center, scale):
        """For a tree built from these clips (or any tree they are routed through)."""
        # copies: the caller may change its arrays
        clips = [np.array(c, dtype=np.float64) for c in clips]
        frames = (np.concatenate(clips) - center) / scale
        moments = node_moments(tree, frames, tree.covariance_type)
        return cls(tree, moments, clips, center, scale, labels)

    @classmethod
    def from_tree(cls, tree, center, scale):
        """For a tree built by ``fit``: moments recovered from its estimates, clips unknown."""
        moments = Moments.from_estimates(
            tree.count, tree.mean, tree.covariance, tree.covariance_type, tree.reg
        )
        return cls(tree, moments, None, center, scale)

    def standardised(self, clips=None):
        """The clips (all kept ones by default) standardised, one array."""
        clips = self.clips if clips is None else clips
        return (np.concatenate(clips) - self.center) / self.scale

    def add(self, clips, labels, *, split_growth, rebuild_growth, rebuild_tol, build_params):
        # build_params: a TreeParams, the build's rule for leaves split and subtrees built again
        """Merge new clips; split and rebuild where due (the root excepted: ``root_due``).

        Returns whether the tree's structure changed.
        """
        tree = self.tree
        added = node_moments(tree, self.standardised(clips), tree.covariance_type)
        self.moments = self.moments.merged(added)
        # a node that changed loses its low-rank form: the decoder then uses the
        # triangular factor of the same covariance
        low_rank = None
        if tree.covariance_type == "full":
            low_rank = [None if c else lr for c, lr in zip(added.count, tree.low_rank)]
        if self.clips is None:
            self.tree = _with_moments(tree, self.moments, low_rank)
            return False
        self.clips.extend(np.array(c, dtype=np.float64) for c in clips)
        self.labels.extend(labels)
        regrow = self._due(split_growth, rebuild_growth, rebuild_tol, build_params)
        if not regrow:
            self.tree = _with_moments(tree, self.moments, low_rank)
            return False
        all_frames = self.standardised()
        changed = False
        while regrow:
            new_id = self._regrow(regrow.pop(0), all_frames, build_params)
            if new_id is not None:
                changed = True
                regrow = [int(new_id[v]) for v in regrow]
        self.tree = _with_moments(self.tree, self.moments)
        return changed

    def root_due(self, n_new, rebuild_growth):
        """Whether the root, with ``n_new`` more frames, has grown ``rebuild_growth`` times."""
        return (
            rebuild_growth is not None
            and self.clips is not None
            and self.moments.count[0] + n_new >= rebuild_growth * self.checked[0]
        )

    def _due(self, split_growth, rebuild_growth, rebuild_tol, params):
        """Nodes to grow again: topmost grown or drifted split nodes, then leaves outside them."""
        tree, m = self.tree, self.moments
        split = tree.left >= 0
        due = np.zeros(len(split), bool)
        if rebuild_tol is not None:
            shift = np.sqrt(((m.mean - self.split_mean) ** 2).sum(axis=1))
            due |= split & (shift > rebuild_tol * self.split_scale)
        if rebuild_growth is not None:
            due[1:] |= split[1:] & (m.count[1:] >= rebuild_growth * self.checked[1:])
        if split_growth is not None:
            max_depth = params.max_depth
            room = np.ones(len(split), bool) if max_depth is None else tree.depth < max_depth
            # the build splits every node of min_split frames (when a cut is admissible)
            min_split = max(params.min_samples_split, 2 * params.min_samples_leaf, 2)
            grown = (m.count >= split_growth * self.checked) | (
                (self.checked < min_split) & (m.count >= min_split)
            )
            due |= ~split & room & grown
        nodes = np.flatnonzero(due)
        # a node inside another's subtree is regrown with it
        covered = set()
        for node in nodes[np.argsort(tree.depth[nodes], kind="stable")]:
            up = tree.parent[node]
            while up >= 0 and up not in covered:
                up = tree.parent[up]
            if up < 0:
                covered.add(int(node))
        return sorted(covered, key=lambda v: tree.depth[v])

    def _regrow(self, node, all_frames, params):
        """Grow ``node``'s subtree again from its frames, by the build's rule.

        Returns the renumbering of the old tree node ids (-1 for removed ones),
        or None when nothing changed.
        """
        tree = self.tree
        labels = tree.apply(all_frames, int(tree.depth[node]))
        mine = all_frames[tree.layers[tree.depth[node]][labels] == node]
        self.checked[node] = len(mine)
        room = None if params.max_depth is None else params.max_depth - int(tree.depth[node])
        # the subtree's covariances are replaced by its nodes' merged moments (_graft)
        params = replace(
            params, max_depth=room, covariance_type=tree.covariance_type, reg_covar=1.0
        )
        sub = build_nodes(np.ascontiguousarray(mine), **params.as_dict())
        had_children = tree.left[node] >= 0
        if len(sub["parent"]) == 1 and not had_children:
            return None
        return self._graft(node, sub, mine)

    def _graft(self, node, sub, mine):
        """Replace ``node``'s subtree by the built one (``sub``, root = ``node``)."""
        tree = self.tree
        # drop the old descendants, renumbering the nodes that stay
        inside = np.zeros(tree.n_tree_nodes, bool)
        for layer in tree.layers[tree.depth[node] + 1 :]:
            inside[layer] |= inside[tree.parent[layer]] | (tree.parent[layer] == node)
        inside[node] = False
        keep = np.flatnonzero(~inside)
        new_id = np.full(tree.n_tree_nodes + 1, -1, np.intp)
        new_id[keep] = np.arange(len(keep))
        base = len(keep)
        ids = np.r_[new_id[node], base + np.arange(len(sub["parent"]) - 1)]  # sub node -> id

        def remap(a):
            return new_id[np.where(a < 0, -1, a)]

        parent = np.r_[remap(tree.parent[keep]), ids[sub["parent"][1:]]]
        kids = {}
        for side in ("left", "right"):
            old = remap(getattr(tree, side)[keep])
            subside = sub[side][1:]
            kids[side] = np.r_[old, np.where(subside < 0, -1, ids[np.maximum(subside, 0)])]
            kids[side][new_id[node]] = ids[sub[side][0]] if sub[side][0] >= 0 else -1
        depth = np.r_[tree.depth[keep], tree.depth[node] + sub["depth"][1:]]
        axis = np.r_[tree.axis[keep], sub["axis"][1:]]
        axis[new_id[node]] = sub["axis"][0]
        threshold = np.r_[tree.threshold[keep], sub["threshold"][1:]]
        threshold[new_id[node]] = sub["threshold"][0]
        n_sub = len(sub["parent"]) - 1
        # the new nodes' moments from their frames; the rest are kept
        arrays = dict(
            parent=parent,
            left=kids["left"],
            right=kids["right"],
            depth=depth,
            axis=axis,
            threshold=threshold,
        )
        moments = self.moments.take(keep)
        blank = node_moments(tree, mine[:0], tree.covariance_type, n_sub)
        moments = moments.append(blank)
        self.moments = moments
        self.checked = np.r_[self.checked[keep], np.zeros(n_sub, np.int64)]
        self.split_mean = np.r_[self.split_mean[keep], np.zeros((n_sub, tree.n_channels))]
        self.split_scale = np.r_[self.split_scale[keep], np.zeros(n_sub)]
        self.tree = _from_arrays(tree, arrays, moments)
        fresh = node_moments(self.tree, mine, tree.covariance_type)
        sub_ids = ids[1:]
        moments.put(sub_ids, fresh.take(sub_ids))
        self.checked[sub_ids] = moments.count[sub_ids]
        own = np.r_[new_id[node], sub_ids]
        self.split_mean[own] = moments.mean[own]
        self.split_scale[own] = _spread(moments.take(own))
        return new_id


def _spread(moments):
    """``sqrt(trace(cov) / d)`` of each set (without regularisation); 0 for an empty set."""
    s = moments.scatter
    trace = np.trace(s, axis1=1, axis2=2) if s.ndim == 3 else s.sum(axis=1) if s.ndim == 2 else s
    n = np.maximum(moments.count, 1) * moments.mean.shape[1]
    return np.sqrt(np.maximum(trace, 0) / n)


def _from_arrays(tree, arrays, moments, low_rank=None):
    """A MotionTree of the given structure whose nodes' Gaussians come from ``moments``."""
    present = moments.count > 0
    cov = np.empty((len(moments),) + tree.covariance.shape[1:])
    if present.any():
        cov[present] = moments.take(present).covariances(tree.reg)
    # a node no frame reached yet (only while grafting) gets a unit covariance
    cov[~present] = np.eye(tree.n_channels) if tree.covariance_type == "full" else 1.0
    return MotionTree(
        **arrays,
        count=moments.count.astype(np.intp),
        mean=moments.mean.copy(),
        covariance=cov,
        layers=_layers_of(arrays["left"], arrays["right"]),
        covariance_type=tree.covariance_type,
        reg=tree.reg,
        principal_axes=tree.principal_axes,
        low_rank=low_rank,
    )


def _with_moments(tree, moments, low_rank=None):
    arrays = {
        k: getattr(tree, k) for k in ("parent", "left", "right", "depth", "axis", "threshold")
    }
    return _from_arrays(tree, arrays, moments, low_rank)
