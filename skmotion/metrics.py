"""Metrics of similarity search and scorers for ``GridSearchCV``.

"Similar" means "has the same label". For a query, the stored clips with its label
are relevant and the others irrelevant; an index returns a candidate set.
"""

from numbers import Real

import numpy as np

from skmotion.utils._sklearn_compat import Interval, StrOptions, validate_params

__all__ = [
    "SEARCH_SCORES",
    "make_pruning_scorer",
    "make_search_scorer",
    "pruning_ceiling",
    "pruning_efficiency",
    "pruning_scorer",
    "recall",
    "recall_scorer",
]


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


def _ball_options(distances, relevant, irrelevant):
    """Per query, every ball that keeps a different number of similar clips.

    Returns (recall, pruning) of the balls reaching each similar clip's distance,
    from the widest (recall 1) down to the empty ball (recall 0, pruning 1):
    a ball keeps every clip at a distance up to its radius, ties included.
    """
    near, far = np.sort(distances[relevant]), np.sort(distances[irrelevant])
    radii = np.r_[np.unique(near)[::-1], -np.inf]
    kept = np.searchsorted(near, radii, side="right")
    pruned = len(far) - np.searchsorted(far, radii, side="right")
    return kept / max(len(near), 1), pruned / max(len(far), 1)


def _upper_hull(costs, gains):
    """Slopes and widths of the upper concave hull of points starting at ``(0, gains[0])``."""
    slopes, widths = [], []
    at = 0
    while at < len(costs) - 1:
        ahead = np.arange(at + 1, len(costs))
        rise = (gains[ahead] - gains[at]) / (costs[ahead] - costs[at])
        best = ahead[np.flatnonzero(rise == rise.max())[-1]]
        slopes.append(rise.max())
        widths.append(costs[best] - costs[at])
        at = best
    return slopes, widths


@validate_params(
    {
        "distances": ["array-like"],
        "y_query": ["array-like"],
        "y_stored": ["array-like"],
        "min_recall": [Interval(Real, 0, 1, closed="both")],
    },
    prefer_skip_nested_validation=True,
)
def pruning_ceiling(distances, y_query, y_stored, *, min_recall=1.0):
    """The most pruning any candidate sets chosen by these distances can reach at a recall.

    A search that ranks by a distance and keeps, for each query, the stored
    clips within some radius of it (any radius per query, chosen knowing the
    answer) cannot prune more than this. With ``min_recall=1`` each query must
    keep its least similar stored clip of its own label, so its ball reaches
    that clip's distance, and the ceiling is exact: the mean over queries of
    the share of irrelevant stored clips strictly farther away. Below 1 the
    radii are traded across queries to keep the mean recall at
    ``min_recall``; the value returned is then an upper bound (the linear
    relaxation of that choice), at most one query's step above the best
    choice. It measures how well the distance separates each query's label
    from the others: an index meant to keep, before the ranking, the stored
    clips that this distance ranks first cannot prune more at that recall
    (a filter on other features may, by keeping clips the ranking puts last).

    Parameters
    ----------
    distances : array-like of shape (n_queries, n_stored)
        Distance of each query to each stored clip (e.g. ``1 - pairwise_psi``).
    y_query : array-like of shape (n_queries,)
        Label of each query.
    y_stored : array-like of shape (n_stored,)
        Label of each stored clip.
    min_recall : float in [0, 1], default=1.0
        The mean recall (as :func:`recall`) the candidate sets must keep.

    Returns
    -------
    ceiling : float
        The largest mean pruning efficiency (as :func:`pruning_efficiency`);
        NaN when no query has an irrelevant clip stored.

    See Also
    --------
    pruning_efficiency, recall : what an index's candidate sets reach.

    Examples
    --------
    >>> from skmotion.metrics import pruning_ceiling
    >>> y_stored = ["walk", "walk", "jump", "jump"]
    >>> # the walk query's farther walk (0.5) is beyond one jump (0.4): that jump stays
    >>> pruning_ceiling([[0.1, 0.5, 0.4, 0.9]], ["walk"], y_stored)
    0.5
    >>> pruning_ceiling([[0.1, 0.5, 0.4, 0.9]], ["walk"], y_stored, min_recall=0.5)
    1.0
    """
    distances = np.asarray(distances, dtype=float)
    y_query, y_stored = np.asarray(y_query), np.asarray(y_stored)
    if distances.ndim != 2 or distances.shape != (len(y_query), len(y_stored)):
        raise ValueError(
            f"distances has shape {distances.shape}; expected (n_queries, n_stored) = "
            f"({len(y_query)}, {len(y_stored)})."
        )
    if np.isnan(distances).any():
        row, column = np.argwhere(np.isnan(distances))[0]
        raise ValueError(f"distances[{row}, {column}] is NaN.")
    relevant = y_query[:, None] == y_stored[None, :]
    has_similar, has_other = relevant.any(axis=1), (~relevant).any(axis=1)
    if not has_other.any():
        return float("nan")
    base, steps = 0.0, []
    for q in range(len(y_query)):
        found, pruned = _ball_options(distances[q], relevant[q], ~relevant[q])
        gains = pruned / has_other.sum() if has_other[q] else np.zeros_like(pruned)
        if not has_similar[q]:  # nothing to keep: the empty ball costs no recall
            base += gains[-1]
            continue
        base += gains[0]
        costs = (1.0 - found) / has_similar.sum()
        steps.extend(zip(*_upper_hull(costs, gains)))
    budget = 1.0 - min_recall if has_similar.any() else 0.0
    for slope, width in sorted(steps, key=lambda step: -step[0]):
        if budget <= 1e-12:
            break
        base += slope * min(width, budget)
        budget -= width
    return float(min(base, 1.0))


def _index_and_queries(estimator, X):
    """The index at the end of ``estimator`` (maybe a Pipeline) and X as it sees it."""
    steps = getattr(estimator, "steps", None)
    if steps is None:
        return estimator, X
    for _, step in steps[:-1]:
        if step is not None and step != "passthrough":
            X = step.transform(X)
    return steps[-1][1], X


def _search_quality(estimator, X, y):
    index, X = _index_and_queries(estimator, X)
    candidates = index.candidates(X)
    return (
        pruning_efficiency(candidates, y, index.labels_),
        recall(candidates, y, index.labels_),
    )


def _bounded(pruning, found, min_recall):
    """Pruning efficiency while recall >= min_recall, else recall - 1 (negative)."""
    return pruning if found >= min_recall else found - 1.0


#: What a search scorer returns: one score, or ``"all"`` of them as a dict.
SEARCH_SCORES = ("all", "pruning", "recall", "pruning_at_recall")


class _SearchScorer:
    """Pruning, recall and bounded pruning from one query pass: one of them, or all as a dict."""

    def __init__(self, min_recall, score):
        self.min_recall = min_recall
        self.score = score

    def __call__(self, estimator, X, y):
        pruning, found = _search_quality(estimator, X, y)
        scores = {
            "pruning": pruning,
            "recall": found,
            "pruning_at_recall": _bounded(pruning, found, self.min_recall),
        }
        return scores if self.score == "all" else scores[self.score]

    def __repr__(self):
        return f"make_search_scorer(min_recall={self.min_recall!r}, score={self.score!r})"


@validate_params(
    {
        "min_recall": [Interval(Real, 0, 1, closed="both")],
        "score": [StrOptions(set(SEARCH_SCORES))],
    },
    prefer_skip_nested_validation=True,
)
def make_search_scorer(min_recall=0.99, *, score="all"):
    """A scorer of similarity search on held-out queries, for ``GridSearchCV(scoring=...)``.

    The validation clips query the index built on the training clips
    (``estimator`` is an :class:`~skmotion.neighbors.IntervalIndexNeighbors`
    or a Pipeline ending in one). The scores are the pruning efficiency, the
    recall, and the *bounded* pruning: the pruning efficiency while recall
    ``>= min_recall``, else ``recall - 1`` (negative), so that any setting
    that keeps the recall beats every setting that does not, and among those
    that do not, the higher recall wins.

    ``GridSearchCV`` calls each scorer of a ``scoring`` dict on its own, so
    three scorers side by side query the index (and run any transformer
    before it) three times. With ``score="all"`` the scorer queries once and
    returns the three scores as a dict, which ``GridSearchCV(scoring=...)``
    accepts: ``refit="pruning_at_recall"`` refits the best bounded setting.

    Parameters
    ----------
    min_recall : float, default=0.99
        The recall bound of ``"pruning_at_recall"``.
    score : {"all", "pruning", "recall", "pruning_at_recall"}, default="all"
        The score the scorer returns, or ``"all"`` for the dict of them.

    Returns
    -------
    scorer : callable
        ``scorer(estimator, X, y)``: a float, or with ``score="all"``
        ``{"pruning": ..., "recall": ..., "pruning_at_recall": ...}``.

    See Also
    --------
    pruning_scorer, recall_scorer : ``make_search_scorer(score="pruning")``
        and ``make_search_scorer(score="recall")``.
    make_pruning_scorer : ``make_search_scorer(min_recall, score="pruning_at_recall")``.

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.datasets import make_repeated_motions
    >>> from skmotion.metrics import make_search_scorer, pruning_scorer
    >>> from skmotion.neighbors import IntervalIndexNeighbors
    >>> data = make_repeated_motions(n_motions_per_class=2, n_repeats=4, random_state=0)
    >>> query = [k % 4 == 0 for k in range(len(data.clips))]  # one repetition of each motion
    >>> stored = [c for c, q in zip(data.clips, query) if not q]
    >>> queries = [c for c, q in zip(data.clips, query) if q]
    >>> index = IntervalIndexNeighbors(n_levels=5).fit(stored, data.target[~np.array(query)])
    >>> scores = make_search_scorer(0.9)(index, queries, data.target[query])
    >>> sorted(scores), scores["recall"] >= 0.9
    (['pruning', 'pruning_at_recall', 'recall'], True)
    >>> pruning_scorer(index, queries, data.target[query]) == scores["pruning"]
    True

    In a grid search: ``GridSearchCV(index, grid, scoring=make_search_scorer(0.9),
    refit="pruning_at_recall")``.
    """
    return _SearchScorer(min_recall, score)


#: Scorer: the pruning efficiency of the fitted index on held-out queries.
pruning_scorer = _SearchScorer(0.99, "pruning")

#: Scorer: the recall of the fitted index on held-out queries.
recall_scorer = _SearchScorer(0.99, "recall")


@validate_params(
    {"min_recall": [Interval(Real, 0, 1, closed="both")]}, prefer_skip_nested_validation=True
)
def make_pruning_scorer(min_recall=0.99):
    """A scorer that rewards pruning only while recall stays at or above a bound.

    ``make_search_scorer(min_recall, score="pruning_at_recall")``: the pruning
    efficiency when recall ``>= min_recall``, else ``recall - 1`` (negative).

    Parameters
    ----------
    min_recall : float, default=0.99
        The recall a setting must keep.

    Returns
    -------
    scorer : callable
        ``scorer(estimator, X, y) -> float``, for ``GridSearchCV(scoring=...)``.

    Examples
    --------
    >>> from sklearn.model_selection import GridSearchCV
    >>> from skmotion.datasets import make_motions
    >>> from skmotion.metrics import make_pruning_scorer
    >>> from skmotion.neighbors import IntervalIndexNeighbors
    >>> data = make_motions(n_clips_per_class=6, random_state=0)
    >>> clips = [c[:, 6:] for c in data.clips]
    >>> search = GridSearchCV(
    ...     IntervalIndexNeighbors(n_levels=4), {"epsilon": [0.6, 1.2]},
    ...     scoring=make_pruning_scorer(0.9), cv=3,
    ... ).fit(clips, data.target)
    >>> sorted(search.best_params_)
    ['epsilon']
    """
    return _SearchScorer(min_recall, "pruning_at_recall")
