"""Held-out folds and per-layer class scores of a MotionTreeHMM: calibration and stacking features.

Free functions used by :class:`MotionTreeHMM`: the folds of its internal
cross-validation (contiguous, or by group), the per-layer generation scores of
clips under each class, the supervised features of ``transform`` built from
them, and their column names.
"""

import numpy as np
from sklearn.model_selection import StratifiedGroupKFold, StratifiedKFold

from skmotion.tree._calibration import log_softmax_rows, per_frame, sum_of_paths

__all__ = [
    "class_score_features",
    "class_score_names",
    "held_out_folds",
    "layer_class_scores",
]


def held_out_folds(y_index, groups, n_folds):
    """Train/held-out index pairs of the internal cross-validation, or None when it cannot run.

    Without ``groups`` the folds are stratified and *contiguous*: each class's
    clips are cut, in the order given, into ``n_folds`` blocks. Clips recorded
    together (overlapping windows of one take, the takes of one subject) are
    usually given together, so a held-out block is mostly unlike the rest, as
    new data will be; shuffled folds put a window's overlapping neighbours on
    both sides, which makes the held-out scores too sure (on CMU subject-02
    windows the fitted temperature came out 250 times too small). With
    ``groups``, no group is split across folds (``StratifiedGroupKFold``).

    Parameters
    ----------
    y_index : ndarray of int of shape (n_clips,)
    groups : array-like of shape (n_clips,) or None
    n_folds : int or None

    Returns
    -------
    folds : list of (ndarray, ndarray) or None
        None when ``n_folds`` is None, the smallest class (or the group count)
        allows fewer than two folds, or there is one class.
    """
    counts = np.bincount(y_index)
    if groups is None:
        n_folds = min(n_folds or 0, counts.min())
        if n_folds < 2 or len(counts) < 2:
            return None
        return list(StratifiedKFold(n_folds).split(y_index, y_index))
    groups = np.asarray(groups)
    if groups.shape != y_index.shape:
        raise ValueError(
            f"groups has shape {groups.shape} but X holds {len(y_index)} clips; "
            "give one group per clip."
        )
    n_folds = min(n_folds or 0, len(np.unique(groups)))
    if n_folds < 2 or len(counts) < 2:
        return None
    folds = list(StratifiedGroupKFold(n_folds).split(y_index, y_index, groups))
    return folds if all(len(train) and len(test) for train, test in folds) else None


def layer_class_scores(scores, graph_classes, n_classes, per_clip_graphs):
    """Log generation probability of each clip under each class at each scored layer.

    Parameters
    ----------
    scores : ndarray of shape (n_clips, n_graphs, n_scored, n_paths)
        The decoder's K-best log scores (best first), as ``decode_clips`` returns them.
    graph_classes : ndarray of int of shape (n_graphs,)
        Class index of each graph.
    n_classes : int
    per_clip_graphs : bool
        Graphs are training clips (``graph="clip"``): a class's score at a
        layer is that of its best graph at that layer.

    Returns
    -------
    log_prob : ndarray of shape (n_clips, n_classes, n_scored)
        ``log`` of the summed probability of the ``n_paths`` best node sequences.
    """
    per_graph = sum_of_paths(scores)
    if not per_clip_graphs:
        return per_graph
    out = np.full((len(scores), n_classes, scores.shape[2]), -np.inf)
    np.maximum.at(out.transpose(1, 0, 2), graph_classes, per_graph.transpose(1, 0, 2))
    return out


def class_score_features(log_prob, lengths):
    """The supervised features: per layer, the log-softmax over classes of per-frame scores.

    Column ``(l, c)`` is ``log softmax_c(log P_l(clip | c) / n_frames)``: the log
    posterior of class ``c`` given the clip at scored layer ``l`` under a
    uniform class prior, from the clip's generation probability per frame.
    Any constant shared by the classes of one clip at one layer (such as the
    normaliser of ``Ps`` the decoder skips) cancels; a layer at which no class
    can generate the clip gets equal values.

    Parameters
    ----------
    log_prob : ndarray of shape (n_clips, n_classes, n_scored)
    lengths : array-like of shape (n_clips,)
        Frames per clip.

    Returns
    -------
    features : ndarray of shape (n_clips, n_scored * n_classes)
        Layer-major: all classes of the first scored layer, then the next.
    """
    n_clips, n_classes, n_scored = log_prob.shape
    layer_rows = per_frame(
        log_prob.transpose(0, 2, 1).reshape(-1, n_classes), np.repeat(lengths, n_scored)
    )
    return log_softmax_rows(layer_rows).reshape(n_clips, n_scored * n_classes)


def class_score_names(score_layers, classes):
    """``layer<l>_class_<label>`` for every scored layer and class, in the features' order."""
    return np.asarray(
        [f"layer{layer}_class_{label}" for layer in score_layers for label in classes],
        dtype=object,
    )
