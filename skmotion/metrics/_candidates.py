"""Pruning efficiency and recall of candidate sets (Li & Prabhakaran).

"Similar" means "has the same label". For a query, the stored clips with its label
are relevant and the others irrelevant; an index returns a candidate set.
"""

import numpy as np

from skmotion.utils._sklearn_compat import validate_params

__all__ = ["pruning_efficiency", "recall"]


def _per_query_counts(candidates, y_query, y_stored, query_ids):
    """Per query: relevant returned, relevant stored, irrelevant returned, irrelevant stored."""
    y_query = np.asarray(y_query)
    y_stored = np.asarray(y_stored)
    if len(candidates) != len(y_query):
        raise ValueError(
            f"candidates holds {len(candidates)} sets, but y_query has {len(y_query)} labels."
        )
    if query_ids is not None and len(query_ids) != len(y_query):
        raise ValueError(
            f"query_ids has {len(query_ids)} ids, but y_query has {len(y_query)} labels."
        )
    labels, stored_codes = np.unique(y_stored, return_inverse=True)
    per_label = np.bincount(stored_codes, minlength=len(labels))
    counts = np.zeros((len(y_query), 4), dtype=np.int64)
    for q, (found, label) in enumerate(zip(candidates, y_query)):
        found = np.asarray(found, dtype=np.intp)
        if query_ids is not None:
            found = found[found != query_ids[q]]
        at = np.searchsorted(labels, label)
        stored_relevant = per_label[at] if at < len(labels) and labels[at] == label else 0
        n_stored = len(y_stored)
        if query_ids is not None:  # the query itself is neither relevant nor irrelevant
            stored_relevant -= 1
            n_stored -= 1
        returned_relevant = int(np.count_nonzero(y_stored[found] == label))
        counts[q] = (
            returned_relevant,
            stored_relevant,
            len(found) - returned_relevant,
            n_stored - stored_relevant,
        )
    return counts


def _mean_share(part, whole):
    """Mean over queries of ``part / whole``, leaving out those whose ``whole`` is 0; NaN if all."""
    defined = whole > 0
    if not defined.any():
        return float("nan")
    return float(np.mean(part[defined] / whole[defined]))


_METRIC_PARAMS = {
    "candidates": [list, tuple],
    "y_query": ["array-like"],
    "y_stored": ["array-like"],
    "query_ids": ["array-like", None],
}


@validate_params(_METRIC_PARAMS, prefer_skip_nested_validation=True)
def pruning_efficiency(candidates, y_query, y_stored, *, query_ids=None):
    """Share of the irrelevant stored clips that the index pruned, averaged over queries.

    For one query, ``P = N_pr / N_ir``: irrelevant clips (another label) left
    out of its candidates over all irrelevant stored clips (Li & Prabhakaran).
    Queries with no irrelevant clip stored are left out of the mean.

    Parameters
    ----------
    candidates : list of array-like of int
        For each query, ids (positions in ``y_stored``) of its candidates.
    y_query : array-like of shape (n_queries,)
        Label of each query.
    y_stored : array-like of shape (n_stored,)
        Label of each stored clip.
    query_ids : array-like of shape (n_queries,), default=None
        When the queries are stored clips themselves, their ids: each query is
        then left out of its own counts (as in a leave-one-out evaluation).

    Returns
    -------
    efficiency : float
        In ``[0, 1]``; NaN when no query has an irrelevant clip.

    See Also
    --------
    recall : the share of similar clips kept.

    Examples
    --------
    >>> from skmotion.metrics import pruning_efficiency
    >>> y_stored = ["walk", "walk", "jump", "jump", "kick"]
    >>> # the query is a walk; the candidates keep both walks and one jump
    >>> pruning_efficiency([[0, 1, 2]], ["walk"], y_stored)
    0.666...
    """
    counts = _per_query_counts(candidates, y_query, y_stored, query_ids)
    return _mean_share(counts[:, 3] - counts[:, 2], counts[:, 3])


@validate_params(_METRIC_PARAMS, prefer_skip_nested_validation=True)
def recall(candidates, y_query, y_stored, *, query_ids=None):
    """Share of the similar stored clips that the candidates keep, averaged over queries.

    Similar means the same label. Queries with no similar clip stored are left
    out of the mean.

    Parameters
    ----------
    candidates : list of array-like of int
        For each query, ids (positions in ``y_stored``) of its candidates.
    y_query : array-like of shape (n_queries,)
        Label of each query.
    y_stored : array-like of shape (n_stored,)
        Label of each stored clip.
    query_ids : array-like of shape (n_queries,), default=None
        When the queries are stored clips themselves, their ids (left out of
        their own counts).

    Returns
    -------
    recall : float
        In ``[0, 1]``; NaN when no query has a similar clip stored.

    See Also
    --------
    pruning_efficiency : the share of irrelevant clips pruned.

    Examples
    --------
    >>> from skmotion.metrics import recall
    >>> y_stored = ["walk", "walk", "jump", "jump", "kick"]
    >>> recall([[0, 2], [2, 3, 4]], ["walk", "jump"], y_stored)
    0.75
    >>> recall([[1], [0]], ["walk", "walk"], y_stored, query_ids=[0, 1])
    1.0
    """
    counts = _per_query_counts(candidates, y_query, y_stored, query_ids)
    return _mean_share(counts[:, 0], counts[:, 1])
