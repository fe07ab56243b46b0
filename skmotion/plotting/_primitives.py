"""Figures of movement primitives: the eigenmovements."""

import numpy as np
from sklearn.utils.validation import check_is_fitted

from ._pyplot import _pyplot

__all__ = ["plot_eigenmovements"]


def plot_eigenmovements(
    estimator, n_components=4, *, channels=None, channel_names=None, figsize=None
):
    """The first eigenmovements, one row each, one panel per channel.

    Each panel shows how one channel moves over the normalised time of a
    segment in one eigenmovement (Fod, Mataric and Jenkins 2002, Fig. 7). The panels
    of a row share their vertical scale, so a channel's share of the
    eigenmovement shows.

    Parameters
    ----------
    estimator : EigenMovementPCA
        A fitted estimator.
    n_components : int, default=4
        How many eigenmovements (rows), from the first.
    channels : sequence of int, default=None
        Channels to show (columns); all by default.
    channel_names : sequence of str, default=None
        A title per channel shown; ``feature_names_in_`` or ``channel <j>`` by default.
    figsize : tuple of float, default=None
        Figure size in inches; by default 2.2 by 1.6 per panel.

    Returns
    -------
    figure : matplotlib.figure.Figure

    Examples
    --------
    >>> import numpy as np
    >>> import pytest; _ = pytest.importorskip("matplotlib")
    >>> import matplotlib
    >>> matplotlib.use("Agg")
    >>> from skmotion.datasets import make_motions
    >>> from skmotion.decomposition import EigenMovementPCA
    >>> from skmotion.plotting import plot_eigenmovements
    >>> clips = make_motions(n_clips_per_class=2, random_state=0).clips
    >>> pca = EigenMovementPCA(6).fit([np.degrees(c[:, [33, 34, 35, 37]]) for c in clips])
    >>> fig = plot_eigenmovements(pca, channel_names=["SFE z", "SAA x", "HR y", "elbow x"])
    >>> len(fig.axes)
    16
    """
    check_is_fitted(estimator)
    plt = _pyplot()
    n_channels = estimator.n_features_in_
    channels = list(range(n_channels)) if channels is None else [int(c) for c in channels]
    if not 1 <= n_components <= estimator.n_components_:
        raise ValueError(
            f"n_components must be in [1, {estimator.n_components_}]; got {n_components}."
        )
    if channel_names is None:
        names = getattr(estimator, "feature_names_in_", None)
        channel_names = [names[c] if names is not None else f"channel {c}" for c in channels]
    if len(channel_names) != len(channels):
        raise ValueError(
            f"channel_names has {len(channel_names)} names for {len(channels)} channels."
        )
    movements = estimator.components_[:n_components].reshape(n_components, n_channels, -1)
    time = np.linspace(0.0, 1.0, movements.shape[2])
    rows, cols = n_components, len(channels)
    figure, axes = plt.subplots(
        rows,
        cols,
        sharex=True,
        sharey="row",
        squeeze=False,
        figsize=figsize or (2.2 * cols, 1.6 * rows),
    )
    for i in range(rows):
        for k, c in enumerate(channels):
            ax = axes[i, k]
            (curve,) = ax.plot(time, movements[i, c], color="C0", label="eigenmovement")
            zero = ax.axhline(0.0, color="0.8", linewidth=0.8, label="zero")
            if i == 0:
                ax.set_title(channel_names[k], fontsize=9)
            if k == 0:
                ax.set_ylabel(f"eigenmovement {i + 1}", fontsize=8)
            if i == rows - 1:
                ax.set_xlabel("normalised time", fontsize=8)
            ax.tick_params(labelsize=7)
    figure.tight_layout(rect=(0, 0, 1, 0.93))
    # One legend for every panel: the curve is the channel's course over a segment.
    figure.legend(
        handles=[curve, zero],
        labels=["the channel's course in the eigenmovement (a unit vector)", "zero"],
        loc="upper center",
        ncol=2,
        fontsize=8,
    )
    return figure
