"""Decoding collections of clips: groups of similar lengths, decoded in parallel."""

import numpy as np

from skmotion.tree._decoder._decode import beam_decode
from skmotion.utils._parallel import parallel_map

__all__ = ["decode_clips", "length_groups"]

# Clips are decoded in groups of at most this many (step, graph) pairs, counting
# shorter clips at the length of the group's longest (the result arrays are
# padded to it). Groups depend on the data only, so results are the same for any n_jobs.
_GROUP_PAIRS = 1 << 17


def length_groups(lengths, n_graphs, budget=_GROUP_PAIRS):
    """Groups of clips of similar lengths, so the padded result arrays stay small.

    Clips are taken shortest first; a group grows while (its longest clip) x
    (its clips) x ``n_graphs`` stays within ``budget``.

    Parameters
    ----------
    lengths : ndarray of shape (n_clips,)
    n_graphs : int
    budget : int, default=131072

    Returns
    -------
    groups : list of ndarray
        Clip indices of each group; together, every clip once.

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.tree._decoder._batch import length_groups
    >>> [g.tolist() for g in length_groups(np.array([5, 50, 6, 40]), n_graphs=1, budget=80)]
    [[0, 2], [3], [1]]
    """
    order = np.argsort(lengths, kind="stable")
    groups, start = [], 0
    for end in range(1, len(order) + 1):
        if end - start > 1 and lengths[order[end - 1]] * (end - start) * n_graphs > budget:
            groups.append(order[start : end - 1])
            start = end - 1
    groups.append(order[start:])
    return groups


def decode_clips(
    tree,
    graphs,
    frames,
    offsets,
    *,
    n_graphs,
    n_jobs=None,
    **options,
):
    """Beam-decode every clip under every graph (see :func:`beam_decode`).

    Parameters
    ----------
    tree : MotionTree
    graphs : TransitionGraphs
    frames : ndarray of shape (n_frames, n_channels)
        The frames of all clips, stacked.
    offsets : ndarray of shape (n_clips + 1,)
    n_graphs : int
        Decode each clip under graphs ``0 .. n_graphs - 1``.
    n_jobs : int, default=None
        Jobs over the groups of clips (joblib's meaning); results do not depend on it.
    **options
        The keywords of :func:`beam_decode` (``layer`` is required): ``layer``,
        ``n_paths``, ``score_layers``, ``node_prior``, ``guide``,
        ``normalise``, ``prune``, ``return_paths``.

    Returns
    -------
    paths : list of ndarray of shape (n_graphs, n_paths, n_frames_i), or None
        Node sequences of each clip at ``layer``, best first (None without ``return_paths``).
    scores : ndarray of shape (n_clips, n_graphs, n_scored, n_paths)
        Their log scores at each scored layer.
    """
    lengths = np.diff(offsets)
    return_paths = options.get("return_paths", True)

    def work(group):
        clips = np.repeat(group, n_graphs)
        graph_ids = np.tile(np.arange(n_graphs), len(group))
        paths, scores = beam_decode(tree, graphs, frames, offsets, clips, graph_ids, **options)
        if paths is not None:
            paths = paths.reshape(len(group), n_graphs, *paths.shape[1:])
        return paths, scores.reshape(len(group), n_graphs, *scores.shape[1:])

    groups = length_groups(lengths, n_graphs)
    results = parallel_map(work, groups, n_jobs=n_jobs)
    scores = np.empty((len(lengths), n_graphs) + results[0][1].shape[2:])
    paths = [None] * len(lengths) if return_paths else None
    for (group_paths, group_scores), group in zip(results, groups):
        scores[group] = group_scores
        if return_paths:
            for i, clip in enumerate(group):
                paths[clip] = group_paths[i, :, :, : lengths[clip]]
    return paths, scores
