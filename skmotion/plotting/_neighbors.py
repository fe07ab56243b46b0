"""Figures of the interval index: pruning and recall against epsilon."""

from ._pyplot import _pyplot

__all__ = ["plot_pruning_recall"]


def plot_pruning_recall(rows, *, n_levels=7):
    """Pruning efficiency and recall against ``epsilon``, one panel per dataset.

    Li and Prabhakaran's (2006) Figures 9-11 from a results table such as
    ``benchmarks/bench_neighbors_pruning.py`` writes.

    Parameters
    ----------
    rows : list of dict
        Each with ``dataset``, ``features``, ``n_levels``, ``epsilon``,
        ``pruning`` and ``recall``.
    n_levels : int, default=7
        The tree depth to show.

    Returns
    -------
    figure : matplotlib.figure.Figure

    Examples
    --------
    >>> import pytest
    >>> _ = pytest.importorskip("matplotlib")
    >>> from skmotion.plotting import plot_pruning_recall
    >>> rows = [
    ...     {"dataset": "toy", "features": "first", "n_levels": 7, "epsilon": e,
    ...      "pruning": 1 - e / 2, "recall": min(1.0, e)}
    ...     for e in (0.5, 0.8, 1.0)
    ... ]
    >>> figure = plot_pruning_recall(rows)
    >>> len(figure.axes)
    1
    """
    plt = _pyplot()
    datasets = sorted({r["dataset"] for r in rows})
    figure, axes = plt.subplots(1, len(datasets), figsize=(4.2 * len(datasets), 3.4), squeeze=False)
    for ax, name in zip(axes[0], datasets):
        for features, style in (("first", "-"), ("first_two", "--")):
            mine = sorted(
                (
                    r
                    for r in rows
                    if r["dataset"] == name
                    and r["features"] == features
                    and r["n_levels"] == n_levels
                ),
                key=lambda r: r["epsilon"],
            )
            if not mine:
                continue
            eps = [r["epsilon"] for r in mine]
            for measure, marker, color in (("pruning", "o", "C0"), ("recall", "s", "C1")):
                ax.plot(
                    eps,
                    [r[measure] for r in mine],
                    marker + style,
                    color=color,
                    label=f"{measure} ({features})",
                )
        ax.set_title(f"{name}, {n_levels} levels")
        ax.set_xlabel("entry interval factor epsilon")
        ax.set_ylim(0, 1.02)
        ax.grid(alpha=0.3)
    axes[0][0].legend(fontsize=7, loc="lower left")
    figure.tight_layout()
    return figure
