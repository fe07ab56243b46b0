"""Where to cut sorted 1-D projections in two: the split criteria of the motion tree.

Each criterion scores every admissible cut of a sorted array in O(n) total with
prefix sums, so splitting a node costs no more than sorting its projections.
"""

import numpy as np

__all__ = ["SPLIT_CRITERIA", "best_split", "split_scores"]


def _prefix_moments(values):
    """Sizes, means and variances of every prefix/suffix pair of ``values``.

    Index ``j`` of each result describes the cut with ``i = j + 1`` values on the
    left. Values are centred first so the prefix sums lose little to cancellation.
    """
    n = len(values)
    centred = values - values.mean()
    cum1 = np.cumsum(centred)
    cum2 = np.cumsum(centred * centred)
    s1, s2 = cum1[:-1], cum2[:-1]
    total1, total2 = cum1[-1], cum2[-1]
    i = np.arange(1, n, dtype=np.float64)
    k = n - i
    mean1 = s1 / i
    mean2 = (total1 - s1) / k
    var1 = s2 / i - mean1 * mean1
    var2 = (total2 - s2) / k - mean2 * mean2
    return i, k, mean1, mean2, var1, var2


def _min_error(values, var_floor):
    """Kittler-Illingworth: ``i ln v1 + k ln v2 - 2 (i ln i + k ln k)``."""
    i, k, _, _, var1, var2 = _prefix_moments(values)
    floor = max(var_floor, np.finfo(np.float64).tiny)
    v1 = np.maximum(var1, floor)
    v2 = np.maximum(var2, floor)
    return i * np.log(v1) + k * np.log(v2) - 2.0 * (i * np.log(i) + k * np.log(k))


def _two_means(values, var_floor):
    """1-D 2-means: minus the between-sides sum of squares (the total is the same for every cut)."""
    i, k, mean1, mean2, _, _ = _prefix_moments(values)
    return -(i * mean1 * mean1 + k * mean2 * mean2)


def _median(values, var_floor):
    """The distance of the cut from the middle."""
    n = len(values)
    return np.abs(np.arange(1, n) - n / 2.0)


#: The split criteria :func:`best_split` knows: each scores every cut of sorted values.
SPLIT_RULES = {"min_error": _min_error, "two_means": _two_means, "median": _median}
SPLIT_CRITERIA = tuple(SPLIT_RULES)


def split_scores(sorted_values, criterion, *, var_floor=0.0):
    """The criterion's score of every cut of a sorted array (lower is better).

    Parameters
    ----------
    sorted_values : ndarray of shape (n,)
        Projections sorted in increasing order; ``n >= 2``.
    criterion : {"min_error", "two_means", "median"}
        ``"min_error"``: Kittler and Illingworth's minimum-error thresholding,
        ``J(i) = i ln v1 + (n-i) ln v2 - 2 (i ln i + (n-i) ln(n-i))`` with ``v1, v2``
        the variances of the first ``i`` and last ``n - i`` values.
        ``"two_means"``: the within-side sum of squares (1-D 2-means, optimal).
        ``"median"``: the distance of ``i`` from ``n / 2``.
    var_floor : float, default=0.0
        Variances below it are raised to it before taking logarithms (a side of
        identical values would otherwise score minus infinity).

    Returns
    -------
    scores : ndarray of shape (n - 1,)
        ``scores[j]`` is the score of putting the first ``j + 1`` values left.

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.tree._build._split import split_scores
    >>> values = np.array([0.0, 0.1, 0.2, 5.0, 5.1, 5.2])
    >>> int(np.argmin(split_scores(values, "two_means"))) + 1
    3
    """
    rule = SPLIT_RULES.get(criterion)
    if rule is None:
        raise ValueError(f"criterion must be one of {SPLIT_CRITERIA}, got {criterion!r}.")
    return rule(np.asarray(sorted_values, dtype=np.float64), var_floor)


def _nearest_middle_cut(sorted_values, leaf, tol):
    """The median rule's cut without its arrays of ``n`` scores: the admissible cut
    nearest the middle (the lower of two equally near), found in windows about the
    middle that double until one holds an admissible cut. Every cut outside a window
    is farther from the middle than every cut in it, so the first window's best is
    the best; its arrays are the window's size, not the node's."""
    n = len(sorted_values)
    half = n / 2.0
    width = 64
    while True:
        low = max(leaf, int(np.ceil(half - width)))  # the cuts i with |i - n/2| <= width
        high = min(n - leaf, int(np.floor(half + width)))
        cuts = np.arange(low, high + 1)
        gaps = sorted_values[low : high + 1] - sorted_values[low - 1 : high]
        found = cuts[gaps > tol]
        if len(found):
            return int(found[np.argmin(np.abs(found - half))])
        if low == leaf and high == n - leaf:
            return None
        width *= 2


def best_split(sorted_values, criterion, *, min_samples_leaf=1, tol=0.0):
    """The best admissible cut of sorted projections, or None.

    A cut after position ``i`` is admissible when both sides keep at least
    ``min_samples_leaf`` values and the gap ``sorted_values[i] - sorted_values[i-1]``
    exceeds ``tol``. The gap rule keeps equal (and nearly equal) values on the
    same side, so a threshold in the middle of the gap routes every value to the
    side it was put on, even after rounding.

    Parameters
    ----------
    sorted_values : ndarray of shape (n,)
        Projections sorted in increasing order.
    criterion : {"min_error", "two_means", "median"}
        See :func:`split_scores`.
    min_samples_leaf : int, default=1
        The fewest values each side may get.
    tol : float, default=0.0
        The smallest gap a cut may sit in; also the resolution used as the
        variance floor of ``"min_error"`` (``tol ** 2``).

    Returns
    -------
    n_left : int or None
        How many values go left, or None when no cut is admissible.

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.tree._build._split import best_split
    >>> values = np.r_[np.zeros(5), np.linspace(3, 3.5, 20)]
    >>> best_split(values, "min_error", min_samples_leaf=2)
    5
    >>> best_split(np.ones(10), "min_error") is None
    True
    """
    n = len(sorted_values)
    leaf = max(int(min_samples_leaf), 1)
    if n < 2 * leaf:
        return None
    if criterion == "median":
        return _nearest_middle_cut(sorted_values, leaf, tol)
    admissible = np.diff(sorted_values) > tol
    admissible[: leaf - 1] = False
    admissible[n - leaf :] = False
    if not admissible.any():
        return None
    scores = split_scores(sorted_values, criterion, var_floor=tol * tol)
    scores = np.where(admissible, scores, np.inf)
    return int(np.argmin(scores)) + 1
