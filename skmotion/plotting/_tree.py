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


def _robust_view(xy):
    """Axis limits around the bulk of the nodes; an outlying node would squash the rest.

    On an axis where the nodes' range is over three times the span of Tukey's
    far-out fences (the quartiles widened by three interquartile ranges), the
    view is the fences; nodes beyond are drawn on its edge (as triangles) and
    counted. Elsewhere the view holds every node.
    """
    q1, q3 = np.percentile(xy, [25, 75], axis=0)
    iqr = np.maximum(q3 - q1, 1e-12)
    low, high = xy.min(axis=0), xy.max(axis=0)
    fence_low = np.maximum(low, q1 - 3 * iqr)
    fence_high = np.minimum(high, q3 + 3 * iqr)
    squashed = (high - low) > 3 * (fence_high - fence_low)
    low = np.where(squashed, fence_low, low)
    high = np.where(squashed, fence_high, high)
    outside = ((xy < low) | (xy > high)).any(axis=1)
    return low, high, outside


def _node_classes(tree, layer, frames, labels):
    """Each node's most common label among the frames it holds, and that label's share."""
    nodes = tree.apply(frames, layer)
    labels = np.asarray(labels)
    names, codes = np.unique(labels, return_inverse=True)
    table = np.zeros((len(tree.counts(layer)), len(names)))
    np.add.at(table, (nodes, codes), 1)
    totals = np.maximum(table.sum(axis=1), 1)
    return names, table.argmax(axis=1), table.max(axis=1) / totals, table.sum(axis=1) > 0


def plot_motion_tree_layer(
    tree,
    graphs=None,
    layer=-1,
    *,
    graph=0,
    axes=(0, 1),
    min_probability=0.05,
    frames=None,
    labels=None,
    ax=None,
):
    """The nodes of one layer on the first principal axes, with a transition graph.

    The figures 3-5 of Yamane, Yamaguchi and Nakamura (2011).

    Each node is drawn at its mean frame projected on principal axes of all
    frames (``tree.principal_axes``), with an area that grows with its frame
    count; each seen transition between two different nodes whose probability
    reaches ``min_probability`` is a line, darker for likelier transitions.
    Given the training ``frames`` and their ``labels`` (the class, or the
    clip, of each frame), a node takes the colour of the label most of its
    frames carry, paler when fewer of them do; without them, the colour is
    the node's spread (largest standard deviation). The view holds the bulk
    of the nodes: a far outlying node is drawn on the edge as a triangle and
    counted in the title, instead of squashing the others onto a line.

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
    frames : ndarray of shape (n_frames, n_channels), default=None
        Frames in the tree's units (for a MotionTreeHMM, standardised:
        ``(x - model.center_) / model.scale_``), to colour nodes by label.
    labels : array-like of shape (n_frames,), default=None
        The label of each of ``frames``.
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
    >>> import numpy as np
    >>> from skmotion.datasets import make_motions
    >>> from skmotion.plotting import plot_motion_tree_layer
    >>> from skmotion.tree import MotionTreeHMM
    >>> data = make_motions(n_clips_per_class=2, classes=["walk", "jump"], random_state=0)
    >>> clips = [c[:, 6:] for c in data.clips]
    >>> model = MotionTreeHMM(max_depth=4).fit(clips, data.target)
    >>> frames = (np.vstack(clips) - model.center_) / model.scale_
    >>> labels = np.repeat(data.target_names[data.target], [len(c) for c in clips])
    >>> ax = plot_motion_tree_layer(model.tree_, model.global_graph_, layer=3,
    ...                             frames=frames, labels=labels)
    >>> len(ax.collections[0].get_offsets()) == int(model.n_nodes_[3])
    True
    >>> [t.get_text() for t in ax.get_legend().get_texts()][2:4]
    ['jump', 'walk']
    """
    plt = _pyplot()
    layer = tree.check_layer(layer)
    if ax is None:
        _, ax = plt.subplots(figsize=(5, 4))
    basis = tree.principal_axes[list(axes)]
    xy = (tree.means(layer) - tree.mean[0]) @ basis.T
    low, high, outside = _robust_view(xy)
    shown = np.clip(xy, low, high)
    if graphs is not None:
        src, dst, prob = _edges(graphs, layer, graph, min_probability)
        for a, b, p in zip(src, dst, prob):
            ax.plot(
                shown[[a, b], 0],
                shown[[a, b], 1],
                color="0.45",
                alpha=float(min(1.0, 0.1 + p)),
                lw=0.7,
                zorder=1,
            )
    counts = tree.counts(layer)
    sizes = 20 + 200 * counts / counts.max()
    from matplotlib.lines import Line2D

    handles = [
        Line2D([], [], marker="o", ls="", mfc="w", mec="k", ms=4, label="node, small: few frames"),
        Line2D([], [], marker="o", ls="", mfc="w", mec="k", ms=11, label="node, large: many"),
    ]
    if frames is not None and labels is not None:
        names, majority, share, seen = _node_classes(tree, layer, frames, labels)
        palette = plt.get_cmap("tab10" if len(names) <= 10 else "tab20")
        colours = np.array([palette(k % palette.N) for k in majority])
        colours[:, 3] = np.where(seen, 0.35 + 0.65 * share, 0.15)  # paler: mixed nodes
        style = {"c": colours}
        handles += [
            Line2D([], [], marker="o", ls="", mfc=palette(k % palette.N), mec="k", ms=6,
                   label=str(name))
            for k, name in enumerate(names)
        ]  # fmt: skip
        colour_text = "colour: most frames' label"
    else:
        spread = np.maximum(_node_spread(tree, layer), 1e-12)
        wide = spread.max() > 10 * spread.min()
        style = {
            "c": spread,
            "cmap": "viridis",
            # Spreads span orders of magnitude (a few wide nodes); a log scale keeps the rest apart.
            "norm": plt.matplotlib.colors.LogNorm(spread.min(), spread.max()) if wide else None,
        }
        colour_text = None
    inside = ~outside
    nodes = ax.scatter(
        shown[:, 0], shown[:, 1], s=np.where(inside, sizes, 0), edgecolors="k", linewidths=0.4,
        zorder=2, **style,
    )  # fmt: skip
    if outside.any():
        ax.scatter(
            shown[outside, 0], shown[outside, 1], s=40, marker="^", c="none", edgecolors="k",
            linewidths=0.8, zorder=3,
        )  # fmt: skip
        handles.append(
            Line2D([], [], marker="^", ls="", mfc="none", mec="k", ms=6, label="node off the view")
        )
    if colour_text is None:
        ax.figure.colorbar(
            nodes, ax=ax, label="node spread (largest std)" + (", log" if style["norm"] else "")
        )
    if graphs is not None:
        handles.append(
            Line2D([], [], color="0.45", lw=0.8, label=f"transition, p >= {min_probability:g}")
        )
    ax.legend(handles=handles, loc="center left", bbox_to_anchor=(1.01, 0.5), fontsize="x-small")
    ax.set_xlim(low[0] - 0.02 * (high[0] - low[0]), high[0] + 0.02 * (high[0] - low[0]))
    ax.set_ylim(low[1] - 0.02 * (high[1] - low[1]), high[1] + 0.02 * (high[1] - low[1]))
    ax.set_xlabel(f"principal axis {axes[0] + 1}")
    ax.set_ylabel(f"principal axis {axes[1] + 1}")
    off = f", {int(outside.sum())} off the view (triangles at the edge)" if outside.any() else ""
    ax.set_title(f"layer {layer}: {len(counts)} nodes{off}", fontsize="medium")
    return ax


def plot_motion_tree_layers(
    tree,
    graphs=None,
    layers=None,
    *,
    graph=0,
    axes=(0, 1),
    min_probability=0.05,
    frames=None,
    labels=None,
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
    frames, labels : default=None
        As in :func:`plot_motion_tree_layer`: colour the nodes by label.

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
    fig, panels = plt.subplots(1, len(layers), figsize=(6.5 * len(layers), 4.6), squeeze=False)
    for ax, layer in zip(panels[0], layers):
        plot_motion_tree_layer(
            tree, graphs, layer, graph=graph, axes=axes, min_probability=min_probability,
            frames=frames, labels=labels, ax=ax,
        )  # fmt: skip
    for ax in panels[0][:-1]:
        ax.get_legend().remove()  # one legend, beside the last panel, serves them all
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
