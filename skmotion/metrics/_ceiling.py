"""The most pruning any ranking by a distance could reach at a recall (``pruning_ceiling``)."""

from numbers import Real

import numpy as np

from skmotion.utils._sklearn_compat import Interval, validate_params

__all__ = ["pruning_ceiling"]


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
    # the means of recall and pruning run over the queries where each is defined
    n_similar, n_other = np.count_nonzero(has_similar), np.count_nonzero(has_other)
    if not n_other:
        return float("nan")
    base, steps = 0.0, []
    for q in range(len(y_query)):
        found, pruned = _ball_options(distances[q], relevant[q], ~relevant[q])
        gains = pruned / n_other if has_other[q] else np.zeros_like(pruned)
        if not has_similar[q]:  # nothing to keep: the empty ball costs no recall
            base += gains[-1]
            continue
        base += gains[0]
        steps.extend(zip(*_upper_hull((1.0 - found) / n_similar, gains)))
    budget = 1.0 - min_recall if n_similar else 0.0
    for slope, width in sorted(steps, key=lambda step: -step[0]):
        if budget <= 1e-12:
            break
        base += slope * min(width, budget)
        budget -= width
    return float(min(base, 1.0))
