"""Scorers of similarity search for ``GridSearchCV``: one pass over the queries, three scores."""

from numbers import Real

from skmotion.metrics._candidates import pruning_efficiency, recall
from skmotion.utils._sklearn_compat import Interval, StrOptions, validate_params

__all__ = [
    "SEARCH_SCORES",
    "make_pruning_scorer",
    "make_search_scorer",
    "pruning_scorer",
    "recall_scorer",
]


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
