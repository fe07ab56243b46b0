"""Figures of the motion database: tree layers, transition graphs, window profiles."""

import numpy as np

from ._pyplot import _pyplot

__all__ = ["plot_motion_tree_layer", "plot_motion_tree_layers", "plot_motion_tree_profile"]


def _node_spread(tree, layer):
    """Largest standard deviation of each node (Yamane et al. size nodes by it)."""
    cov = tree.covariances(layer)
    if tree.covariance_type == "full":
        return np.sqrt(np.linalg.eigvalsh(cov)[:, -1])
    if tree.covariance_type == "diag":
        return np.sqrt(cov.max(axis=1))
    return np.sqrt(cov)


def _edges(graphs, layer, graph, min_probability):
    """Transitions between different nodes seen in the graph, with probability >= the threshold."""
    counts = graphs.counts(layer, graph).tocoo()
    totals = graphs.row_totals(layer)[graph]
    prob = (counts.data + graphs.pseudo_count(layer)) / (totals[counts.row] + graphs.smoothing)
    keep = (counts.row != counts.col) & (prob >= min_probability)
    return counts.row[keep], counts.col[keep], prob[keep]


def plot_motion_tree_layer(
    tree, graphs=None, layer=-1, *, graph=0, axes=(0, 1), min_probability=0.05, ax=None
):
    """The nodes of one layer on the first principal axes, with a transition graph.

    The figures 3-5 of Yamane, Yamaguchi and Nakamura (2011).

    Each node is drawn at its mean frame projected on principal axes of all
    frames (``tree.principal_axes``), with an area that grows with its frame
    count and a colour for its spread (largest standard deviation); each seen
    transition between two different nodes whose probability reaches
    ``min_probability`` is a line, darker for likelier transitions.

    Parameters
    ----------
    tree : MotionTree
    graphs : TransitionGraphs, default=None
        The transition graphs (e.g. ``model.global_graph_`` or ``model.graphs_``);
        None draws the nodes only.
    layer : int, default=-1
    graph : int, default=0
        Which graph of ``graphs`` (a class or a clip).
    axes : tuple of two int, default=(0, 1)
        Which principal axes to plot.
    min_probability : float, default=0.05
        Transitions below it are not drawn.
    ax : matplotlib Axes, default=None
        Where to draw; a new figure by default.

    Returns
    -------
    ax : matplotlib Axes

    Examples
    --------
    >>> import pytest
    >>> matplotlib = pytest.importorskip("matplotlib")
    >>> matplotlib.use("Agg")
    >>> from skmotion.datasets import make_motions
    >>> from skmotion.plotting import plot_motion_tree_layer
    >>> from skmotion.tree import MotionTreeHMM
    >>> data = make_motions(n_clips_per_class=2, classes=["walk", "jump"], random_state=0)
    >>> model = MotionTreeHMM(max_depth=4).fit([c[:, 6:] for c in data.clips], data.target)
    >>> ax = plot_motion_tree_layer(model.tree_, model.global_graph_, layer=3)
    >>> len(ax.collections[0].get_offsets()) == int(model.n_nodes_[3])
    True
    """
    plt = _pyplot()
    layer = tree.check_layer(layer)
    if ax is None:
        _, ax = plt.subplots(figsize=(5, 4))
    basis = tree.principal_axes[list(axes)]
    xy = (tree.means(layer) - tree.mean[0]) @ basis.T
    if graphs is not None:
        src, dst, prob = _edges(graphs, layer, graph, min_probability)
        for a, b, p in zip(src, dst, prob):
            ax.plot(
                xy[[a, b], 0],
                xy[[a, b], 1],
                color="tab:red",
                alpha=float(min(1.0, 0.15 + p)),
                lw=0.8,
                zorder=1,
            )
    counts = tree.counts(layer)
    spread = np.maximum(_node_spread(tree, layer), 1e-12)
    wide = spread.max() > 10 * spread.min()
    nodes = ax.scatter(
        xy[:, 0],
        xy[:, 1],
        s=20 + 200 * counts / counts.max(),
        c=spread,
        cmap="viridis",
        # Spreads span orders of magnitude (a few wide nodes); a log scale keeps the rest apart.
        norm=plt.matplotlib.colors.LogNorm(spread.min(), spread.max()) if wide else None,
        edgecolors="k",
        linewidths=0.4,
        zorder=2,
    )
    ax.figure.colorbar(nodes, ax=ax, label="node spread (largest std)" + (", log" if wide else ""))
    from matplotlib.lines import Line2D

    handles = [
        Line2D([], [], marker="o", ls="", mfc="w", mec="k", ms=4, label="node, small: few frames"),
        Line2D([], [], marker="o", ls="", mfc="w", mec="k", ms=11, label="node, large: many"),
    ]
    if graphs is not None:
        handles.append(
            Line2D([], [], color="tab:red", lw=0.8, label=f"transition, p >= {min_probability:g}")
        )
    ax.legend(handles=handles, loc="best", fontsize="x-small")
    ax.set_xlabel(f"principal axis {axes[0] + 1}")
    ax.set_ylabel(f"principal axis {axes[1] + 1}")
    ax.set_title(f"layer {layer}: {len(counts)} nodes")
    return ax


def plot_motion_tree_layers(
    tree, graphs=None, layers=None, *, graph=0, axes=(0, 1), min_probability=0.05
):
    """Several layers side by side (Yamane et al. 2011, Figure 5, show layers 4 and 7).

    Parameters
    ----------
    tree : MotionTree
    graphs : TransitionGraphs, default=None
    layers : sequence of int, default=None
        By default three layers: a third of the way down, two thirds, and the bottom.
    graph : int, default=0
    axes : tuple of two int, default=(0, 1)
    min_probability : float, default=0.05

    Returns
    -------
    fig : matplotlib Figure

    Examples
    --------
    >>> import pytest
    >>> matplotlib = pytest.importorskip("matplotlib")
    >>> matplotlib.use("Agg")
    >>> from skmotion.datasets import make_motions
    >>> from skmotion.plotting import plot_motion_tree_layers
    >>> from skmotion.tree import MotionTreeHMM
    >>> data = make_motions(n_clips_per_class=2, classes=["walk", "jump"], random_state=0)
    >>> model = MotionTreeHMM(max_depth=4).fit([c[:, 6:] for c in data.clips], data.target)
    >>> len(plot_motion_tree_layers(model.tree_, model.global_graph_).axes)  # panels, colour bars
    6
    """
    plt = _pyplot()
    if layers is None:
        bottom = tree.n_layers - 1
        layers = sorted({max(1, bottom // 3), max(1, 2 * bottom // 3), bottom})
    fig, panels = plt.subplots(1, len(layers), figsize=(5.5 * len(layers), 4.2), squeeze=False)
    for ax, layer in zip(panels[0], layers):
        plot_motion_tree_layer(
            tree, graphs, layer, graph=graph, axes=axes, min_probability=min_probability, ax=ax
        )
    fig.tight_layout()
    return fig


def plot_motion_tree_profile(profile, classes, *, step=1, frame_rate=None, ax=None):
    """Class probabilities of sliding windows over one clip (Yamane et al. 2011, Figs. 10-12).

    Parameters
    ----------
    profile : ndarray of shape (n_windows, n_classes)
        One clip's result of ``MotionTreeHMM.predict_proba_windows``.
    classes : array-like of shape (n_classes,)
        Class names (``model.classes_``).
    step : int, default=1
        The windows' step in frames, to put window starts on the x axis.
    frame_rate : float, default=None
        With it, the x axis is in seconds.
    ax : matplotlib Axes, default=None

    Returns
    -------
    ax : matplotlib Axes

    Examples
    --------
    >>> import pytest
    >>> matplotlib = pytest.importorskip("matplotlib")
    >>> matplotlib.use("Agg")
    >>> import numpy as np
    >>> from skmotion.plotting import plot_motion_tree_profile
    >>> ax = plot_motion_tree_profile(np.array([[0.9, 0.1], [0.4, 0.6]]), ["walk", "jump"], step=5)
    >>> [line.get_label() for line in ax.get_lines()]
    ['walk', 'jump']
    """
    plt = _pyplot()
    if ax is None:
        _, ax = plt.subplots(figsize=(6, 3))
    profile = np.asarray(profile)
    starts = np.arange(len(profile)) * step
    x = starts / frame_rate if frame_rate else starts
    for column, name in enumerate(classes):
        ax.plot(x, profile[:, column], label=str(name))
    ax.set_xlabel("window start (s)" if frame_rate else "window start (frame)")
    ax.set_ylabel("probability")
    ax.set_ylim(-0.02, 1.02)
    ax.legend(loc="best", fontsize="small")
    return ax
