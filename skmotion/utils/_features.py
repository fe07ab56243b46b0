"""Channel names for ``get_feature_names_out``."""

import numpy as np

__all__ = ["channel_names_in"]


def channel_names_in(estimator, input_features=None):
    """The input channel names of a fitted estimator.

    ``input_features`` when given (checked against the fitted names and count),
    else ``feature_names_in_`` when fit saw a DataFrame with string columns, else
    ``channel_0, channel_1, ...``.

    Parameters
    ----------
    estimator : fitted estimator
        Must have ``n_features_in_``.
    input_features : array-like of str, default=None
        Names to use.

    Returns
    -------
    names : ndarray of object
    """
    n = estimator.n_features_in_
    fitted = getattr(estimator, "feature_names_in_", None)
    if input_features is None:
        if fitted is not None:
            return np.asarray(fitted, dtype=object)
        return np.asarray([f"channel_{i}" for i in range(n)], dtype=object)
    input_features = np.asarray(input_features, dtype=object)
    if len(input_features) != n:
        raise ValueError(
            f"input_features has {len(input_features)} names, but "
            f"{type(estimator).__name__} was fitted with {n} channels."
        )
    if fitted is not None and not np.array_equal(input_features, fitted):
        raise ValueError("input_features differ from the feature_names_in_ seen in fit.")
    return input_features
