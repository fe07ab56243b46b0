"""How wide the interval index's entries are: the paper's delta rule, or learned for a recall.

The paper's rule (``epsilon * delta_i``) takes the largest within-label range of
each component, so one spread-out label widens every entry. The learned rule
(``target_recall``) looks at the similar pairs themselves and sets the radii so
that the share of them asked for survives, and no wider.
"""

import numpy as np

from skmotion.neighbors._interval_index import entry_edges
from skmotion.neighbors._psi import psi_from_signatures
from skmotion.utils._parallel import parallel_map

__all__ = [
    "label_pairs",
    "learn_delta",
    "learn_radius",
    "psi_pairs",
    "radius_for_recall",
    "surviving",
    "weighted_quantile",
]


def learn_delta(features, labels, quantile):
    """Per component, how far apart clips with the same label can be.

    For each label with two or more clips, the range (max - min) of each
    component over its clips; then the ``quantile`` of these ranges over the
    labels. ``quantile=1`` is the maximum, the paper's ``delta_i``.

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.neighbors._widths import learn_delta
    >>> features = np.array([[0.0, 0.0], [0.3, 0.1], [1.0, 1.0], [1.1, 1.5]])
    >>> learn_delta(features, np.array([0, 0, 1, 1]), 1.0).round(6).tolist()
    [0.3, 0.5]
    """
    # One pass over the clips sorted by label (not one per label: a collection
    # of repeated motions has about as many labels as clips).
    _, codes, counts = np.unique(labels, return_inverse=True, return_counts=True)
    order = np.argsort(codes.ravel(), kind="stable")
    starts = np.r_[0, np.cumsum(counts)[:-1]]
    ordered = features[order]
    spreads = (
        np.maximum.reduceat(ordered, starts, axis=0) - np.minimum.reduceat(ordered, starts, axis=0)
    )[counts > 1]
    if not len(spreads):
        return np.zeros(features.shape[1])
    return np.quantile(spreads, quantile, axis=0)


# Similar pairs target_recall learns from (drawn beyond this), and psi anchors.
_MAX_PAIRS = 50_000
_PSI_ANCHORS = 2_000
# Per-level quantiles of the similar pairs' distances tried as the shape of the radii.
_PROFILE_QUANTILES = (0.5, 0.75, 0.9, 0.97, 0.995)
# Bisection steps on the radii's common scale.
_STEPS = 16
# Random pairs of training clips on which the pruning of each choice is estimated.
_RANDOM_PAIRS = 10_000


def weighted_quantile(values, weights, q):
    """The smallest value whose cumulated weight reaches the share ``q`` of the total.

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.neighbors._widths import weighted_quantile
    >>> float(weighted_quantile(np.array([3.0, 1.0, 2.0]), np.array([1.0, 1.0, 2.0]), 0.5))
    2.0
    """
    order = np.argsort(values, kind="stable")
    cumulated = np.cumsum(weights[order])
    at = np.searchsorted(cumulated, q * cumulated[-1] * (1 - 1e-12), side="left")
    return values[order][min(at, len(values) - 1)]


def label_pairs(labels, max_pairs, rng):
    """Ordered pairs of distinct clips with the same label, and their weights.

    Each clip with a similar clip weighs 1, spread evenly over its similar clips,
    so that a weighted share of surviving pairs is the mean per-query recall
    (the measure of :func:`skmotion.metrics.recall`). Beyond ``max_pairs``, pairs
    are drawn: a clip at random, then one of its similar clips (weights 1).
    """
    _, codes, counts = np.unique(labels, return_inverse=True, return_counts=True)
    codes = codes.ravel()
    size = counts[codes]
    anchors = np.flatnonzero(size > 1)
    if not len(anchors):
        return np.zeros(0, np.intp), np.zeros(0, np.intp), np.zeros(0)
    order = np.argsort(codes, kind="stable")
    starts = np.r_[0, np.cumsum(counts)[:-1]]
    total = int((size[anchors] - 1).sum())
    if total <= max_pairs:
        first = np.repeat(anchors, size[anchors] - 1)
        offset = np.arange(total) - np.repeat(
            np.cumsum(size[anchors] - 1) - (size[anchors] - 1), size[anchors] - 1
        )
        weight = 1.0 / (size[first] - 1)
    else:
        first = rng.choice(anchors, size=max_pairs)
        offset = rng.randint(0, size[first] - 1)
        weight = np.ones(max_pairs)
    # The offset-th clip of the anchor's label other than the anchor itself.
    members = order[starts[codes[first]] + offset]
    second = np.where(members == first, order[starts[codes[first]] + size[first] - 1], members)
    return first, second, weight


def surviving(query, stored, radius, low, high, max_entries, width_factor=1.0):
    """Whether each (query, stored) pair of vectors survives the tree, exactly.

    The stored vector sits in every entry its covering interval overlaps; the
    pair survives when, at every level, that includes the query's entry (the
    entries of :func:`~skmotion.neighbors._interval_index.entry_edges`).
    """
    keep = np.ones(len(query), dtype=bool)
    for i in range(query.shape[1]):
        edges = entry_edges(low[i], high[i], width_factor * radius[i], max_entries)
        entry = np.searchsorted(edges, query[:, i], side="right")
        first = np.searchsorted(edges, stored[:, i] - radius[i], side="left")
        last = np.searchsorted(edges, stored[:, i] + radius[i], side="right")
        keep &= (first <= entry) & (entry <= last)
    return keep


def learn_radius(
    features, first, second, weight, target_recall, rng, *, max_entries=64, width_factor=1.0
):
    """Per-level radii keeping ``target_recall`` of the similar pairs, pruning the most.

    For each candidate shape of the radii (a per-level quantile of the similar
    pairs' distances), the common scale is the smallest (by bisection) at which
    the weighted share of similar pairs that survive the tree exactly (entries
    and covering intervals as the tree will have them) reaches
    ``target_recall``; of these, the radii that let the fewest random pairs of
    training clips survive are kept.

    Returns
    -------
    radius : ndarray of shape (n_levels,)
    survival : float
        The share of random pairs of training clips that survive.
    """
    low, high = features.min(axis=0), features.max(axis=0)
    span = high - low
    floor = np.maximum(span, np.finfo(float).tiny) * 1e-9  # a constant component
    if not len(first):
        return span.copy(), 1.0
    distance = np.abs(features[first] - features[second])
    a, b = rng.randint(0, len(features), size=(2, _RANDOM_PAIRS))
    # Gathered once, column by column contiguous (searchsorted reads one column
    # at a time): the bisection asks for the recall 80 times.
    query, stored = np.asfortranarray(features[first]), np.asfortranarray(features[second])

    def recall_at(radius):
        keep = surviving(query, stored, radius, low, high, max_entries, width_factor)
        return float(weight[keep].sum() / weight.sum())

    best = None
    for q in _PROFILE_QUANTILES:
        shape = np.maximum(
            [weighted_quantile(distance[:, i], weight, q) for i in range(features.shape[1])], floor
        )
        # From a scale keeping every pair within every radius, down by bisection.
        hi = float((distance / shape).max()) * (1 + 1e-9)
        lo = 0.0
        for _ in range(_STEPS):
            mid = 0.5 * (lo + hi)
            lo, hi = (lo, mid) if recall_at(mid * shape) >= target_recall else (mid, hi)
        radius = np.maximum(hi * shape, floor)
        survive = float(
            surviving(features[a], features[b], radius, low, high, max_entries, width_factor).mean()
        )
        if best is None or survive < best[1]:
            best = (radius, survive)
    return best


def psi_pairs(signatures, n_anchors, rng, *, n_jobs=None):
    """Pairs (clip, its nearest other clip by psi) for up to ``n_anchors`` clips.

    Without labels, the similar clips are the repetitions psi finds: keeping
    these pairs in the candidate sets is keeping each query's exact psi 1-NN.
    """
    weights, vectors = signatures
    n = len(weights)
    first = np.sort(rng.choice(n, size=min(n, n_anchors), replace=False))
    rows = range(0, len(first), 256)

    def nearest(start):
        block = first[start : start + 256]
        similarity = psi_from_signatures(weights[block], vectors[block], weights, vectors)
        similarity[np.arange(len(block)), block] = -np.inf
        return similarity.argmax(axis=1)

    second = np.concatenate(parallel_map(nearest, rows, n_jobs=n_jobs))
    return first, second, np.ones(len(first))


def radius_for_recall(
    tree_features, similar, target_recall, rng, *, max_entries=64, width_factor=1.0, n_jobs=None
):
    """:func:`learn_radius` on the similar pairs of labels or of psi signatures.

    ``similar`` is the clips' encoded labels (an int array: same label =
    similar) or their psi signatures ``(weights, vectors)`` (each clip and its
    psi nearest neighbour are similar). Returns ``(radius, survival)``.
    """
    if isinstance(similar, tuple):
        pairs = psi_pairs(similar, _PSI_ANCHORS, rng, n_jobs=n_jobs)
    else:
        pairs = label_pairs(similar, _MAX_PAIRS, rng)
    return learn_radius(
        tree_features,
        *pairs,
        target_recall,
        rng,
        max_entries=max_entries,
        width_factor=width_factor,
    )
