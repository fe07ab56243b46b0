"""How wide the interval index's entries are: the paper's delta rule."""

import numpy as np

__all__ = ["learn_delta"]


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
