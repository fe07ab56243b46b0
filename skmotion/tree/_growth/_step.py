"""One ``MotionTreeHMM.partial_fit`` step: the database's graphs in, new ones out.

:func:`grow` merges new clips into the :class:`~skmotion.tree._growth._live.LiveDatabase`
(which regrows its tree where due) and returns the new tree and :class:`Graphs`:
the old graphs extended by the new clips' transitions (and by new classes), or
counted again from every kept clip when the tree's layers changed. The
estimator sets its own fitted attributes from them.
"""

from typing import NamedTuple

import numpy as np

from skmotion.tree._growth._live import clip_counts, regroup_graphs
from skmotion.tree._transitions import count_database_graphs
from skmotion.utils._clips import stack_clips

__all__ = ["Graphs", "grow", "regraph", "union_classes"]


class Graphs(NamedTuple):
    """A database's transition graphs and the classes they stand for (``MotionTreeHMM``'s)."""

    global_graph: object  # TransitionGraphs: one graph of all clips
    graphs: object  # TransitionGraphs: one graph per class, or per clip
    graph_classes: np.ndarray  # index in ``classes`` of each graph of ``graphs``
    classes: np.ndarray


def union_classes(classes, *more):
    """The sorted union of the model's classes and new labels (None entries skipped)."""
    parts = [np.asarray(classes)] + [np.asarray(m) for m in more if m is not None]
    kinds = {p.dtype.kind for p in parts if p.size} - {"O"}
    if len(kinds & {"U", "S"}) and len(kinds - {"U", "S"}):
        raise ValueError(
            f"new labels mix strings and numbers with the model's classes {list(classes)!r}."
        )
    return np.unique(np.concatenate(parts))


def regraph(tree, old, classes, *, per_clip, smoothing, recount=None, new_clips=(), new_y=()):
    """New :class:`Graphs` for ``classes``: ``old`` extended by new clips, or recounted.

    ``recount``: ``(clips, labels)`` of every kept clip (standardised), when the
    tree's layers changed; else the new (standardised) clips' transitions are
    added to the old counts. ``per_clip``: one graph per clip (``graph="clip"``).
    """
    old_index = np.searchsorted(classes, old.classes)
    y_index = np.searchsorted(classes, np.asarray(new_y)) if len(new_y) else np.zeros(0, np.intp)
    if not per_clip:
        source = np.full(len(classes), -1, np.intp)
        source[old_index] = np.arange(len(old.classes))
        graph_classes = np.arange(len(classes))
        new_graph = y_index
    else:
        n_old = len(old.graph_classes)
        source = np.r_[np.arange(n_old), np.full(len(new_clips), -1)].astype(np.intp)
        graph_classes = np.r_[old_index[old.graph_classes], y_index].astype(np.intp)
        new_graph = n_old + np.arange(len(new_clips))
    if recount is not None:  # the layers changed: count every kept clip again
        clips, labels = recount
        frames, offsets = stack_clips(clips)
        global_graph, graphs, _ = count_database_graphs(
            tree,
            list(tree.iter_apply(frames)),
            offsets,
            np.searchsorted(classes, np.asarray(labels)),
            n_classes=len(classes),
            per_clip=per_clip,
            smoothing=smoothing,
        )
    elif len(new_clips):
        frames, offsets = stack_clips(new_clips)
        zero = np.zeros(len(new_clips), np.intp)
        global_graph = regroup_graphs(
            old.global_graph, np.zeros(1, np.intp), clip_counts(tree, frames, offsets, zero, 1)
        )
        graphs = regroup_graphs(
            old.graphs, source, clip_counts(tree, frames, offsets, new_graph, len(source))
        )
    else:
        global_graph, graphs = old.global_graph, regroup_graphs(old.graphs, source)
    return Graphs(global_graph, graphs, graph_classes, classes)


def grow(live, old, clips, y, classes, *, per_clip, smoothing, build_params, growth):
    """Add labelled clips to a live database: its new tree and :class:`Graphs`.

    Parameters
    ----------
    live : LiveDatabase
        The database's tree, moments and kept clips; grown in place.
    old : Graphs
        The graphs so far.
    clips : list of ndarray
        The new clips, in the input's units.
    y : ndarray of shape (n_clips,)
        Their labels.
    classes : ndarray
        Every class after this step (``old.classes``, ``y`` and declared ones).
    per_clip : bool
        One graph per clip (``graph="clip"``), else one per class.
    smoothing : float
        The graphs' pseudo-transitions.
    build_params : TreeParams
        The build's rule for leaves split and subtrees built again.
    growth : dict
        ``split_growth``, ``rebuild_growth`` and ``rebuild_tol``.

    Returns
    -------
    tree : MotionTree
    graphs : Graphs
    """
    changed = live.add(clips, y, build_params=build_params, **growth)
    std = [(c - live.center) / live.scale for c in clips]
    recount = None
    if changed:
        recount = ([(c - live.center) / live.scale for c in live.clips], live.labels)
    graphs = regraph(
        live.tree,
        old,
        classes,
        per_clip=per_clip,
        smoothing=smoothing,
        recount=recount,
        new_clips=std,
        new_y=y,
    )
    return live.tree, graphs
