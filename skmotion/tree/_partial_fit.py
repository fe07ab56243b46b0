"""``MotionTreeHMM.partial_fit``: clips (and classes) join a fitted database without a rebuild."""

import numpy as np
from sklearn.utils.multiclass import check_classification_targets
from sklearn.utils.validation import column_or_1d

from skmotion.tree._incremental import (
    LiveDatabase,
    check_growth_params,
    clip_counts,
    regroup_graphs,
)
from skmotion.tree._transitions import TransitionGraphs
from skmotion.utils._clips import check_clips, stack_clips

__all__ = ["partial_fit"]


def _labels(y, n_clips):
    y = column_or_1d(np.asarray(y), warn=True)
    if len(y) != n_clips:
        raise ValueError(
            f"y has {len(y)} labels but X holds {n_clips} clips; give one label per clip."
        )
    check_classification_targets(y)
    return y


def _union(classes, *more):
    parts = [np.asarray(classes)] + [np.asarray(m) for m in more if m is not None]
    kinds = {p.dtype.kind for p in parts if p.size} - {"O"}
    if len(kinds & {"U", "S"}) and len(kinds - {"U", "S"}):
        raise ValueError(
            f"new labels mix strings and numbers with the model's classes {list(classes)!r}."
        )
    return np.unique(np.concatenate(parts))


def _set_layers(est, tree):
    """``layer_``, ``score_layers_``, ``n_layers_``, ``n_nodes_`` as ``fit`` sets them."""
    est.layer_ = tree.check_layer(-1 if est.layer is None else est.layer)
    n_scored = est.layer_ if est.score_layers == "all" else min(est.score_layers, est.layer_)
    est.score_layers_ = (
        np.arange(est.layer_ - n_scored + 1, est.layer_ + 1) if est.layer_ else np.zeros(1, int)
    )
    est.tree_ = tree
    est.n_layers_ = tree.n_layers
    est.n_nodes_ = tree.n_nodes


def _count(tree, clips, graph_of_clip, n_graphs, smoothing):
    frames, offsets = stack_clips(clips)
    return TransitionGraphs.count(
        list(tree.iter_apply(frames)),
        tree.n_nodes,
        offsets=offsets,
        graph_of_clip=graph_of_clip,
        n_graphs=n_graphs,
        smoothing=smoothing,
    )


def _first_call(est, X, y, classes):
    """Build the database from the first batch, as ``fit`` does, keeping its clips and moments."""
    clips = check_clips(X, estimator=est, reset=True)
    return _build(est, clips, list(_labels(y, len(clips))), classes)


def _build(est, clips, labels, classes):
    """The database ``fit`` builds from ``clips``; then the declared classes without clips."""
    names = getattr(est, "feature_names_in_", None)  # the clips kept are arrays: keep the names
    est.fit(clips, labels)
    if names is not None:
        est.feature_names_in_ = names
    est._live = LiveDatabase.from_clips(est.tree_, clips, est.center_, est.scale_)
    est._live.labels = labels
    if classes is not None and len(np.setdiff1d(classes, est.classes_)):
        _regraph(est, _union(est.classes_, classes), None, [], [])
    return est


def _regraph(est, classes, tree_changed_clips, new_clips, new_y):
    """New classes; graphs extended by new clips' counts, or recounted when the layers changed."""
    old_index = np.searchsorted(classes, est.classes_)
    y_index = np.searchsorted(classes, np.asarray(new_y)) if len(new_y) else np.zeros(0, np.intp)
    tree, smoothing = est.tree_, est.smoothing
    if est.graph == "class":
        source = np.full(len(classes), -1, np.intp)
        source[old_index] = np.arange(len(est.classes_))
        graph_classes = np.arange(len(classes))
        new_graph = y_index
    else:
        n_old = len(est.graph_classes_)
        source = np.r_[np.arange(n_old), np.full(len(new_clips), -1)].astype(np.intp)
        graph_classes = np.r_[old_index[est.graph_classes_], y_index].astype(np.intp)
        new_graph = n_old + np.arange(len(new_clips))
    if tree_changed_clips is not None:  # the layers changed: count every stored clip again
        clips, labels = tree_changed_clips
        label_index = np.searchsorted(classes, np.asarray(labels))
        of_clip = label_index if est.graph == "class" else np.arange(len(clips))
        est.global_graph_ = _count(tree, clips, np.zeros(len(clips), np.intp), 1, smoothing)
        est.graphs_ = _count(tree, clips, of_clip, len(graph_classes), smoothing)
    elif len(new_clips):
        frames, offsets = stack_clips(new_clips)
        zero = np.zeros(len(new_clips), np.intp)
        est.global_graph_ = regroup_graphs(
            est.global_graph_, np.zeros(1, np.intp), clip_counts(tree, frames, offsets, zero, 1)
        )
        est.graphs_ = regroup_graphs(
            est.graphs_, source, clip_counts(tree, frames, offsets, new_graph, len(source))
        )
    else:
        est.graphs_ = regroup_graphs(est.graphs_, source)
    est.classes_ = classes
    est.graph_classes_ = graph_classes


def partial_fit(est, X, y, classes, split_growth, rebuild_growth, rebuild_tol):
    """See :meth:`MotionTreeHMM.partial_fit`."""
    check_growth_params(split_growth, rebuild_tol, rebuild_growth)
    if classes is not None and np.ndim(classes) != 1:
        raise ValueError(f"classes must be a 1-D array-like of labels; got {classes!r}.")
    if not hasattr(est, "tree_"):
        return _first_call(est, X, y, classes)
    clips = check_clips(X, estimator=est)
    y = _labels(y, len(clips))
    new_classes = _union(est.classes_, y, classes)
    live = getattr(est, "_live", None)
    if live is None or live.tree is not est.tree_:  # fit since: start from its tree
        live = est._live = LiveDatabase.from_tree(est.tree_, est.center_, est.scale_)
    if live.root_due(sum(len(c) for c in clips), rebuild_growth):
        # the whole database has grown rebuild_growth times: built again, as fit
        # builds it from all clips so far (standardisation and temperature included)
        return _build(est, live.clips + clips, live.labels + list(y), new_classes)
    changed = live.add(
        clips,
        split_growth=split_growth,
        rebuild_growth=rebuild_growth,
        rebuild_tol=rebuild_tol,
        build_params={
            "max_depth": est.max_depth,
            "min_samples_split": est.min_samples_split,
            "min_samples_leaf": est.min_samples_leaf,
            "split": est.split,
        },
    )
    if live.clips is not None:
        live.labels.extend(y)
    _set_layers(est, live.tree)
    std = [(c - est.center_) / est.scale_ for c in clips]
    recount = None
    if changed:
        recount = ([(c - est.center_) / est.scale_ for c in live.clips], live.labels)
    _regraph(est, new_classes, recount, std, y)
    return est
