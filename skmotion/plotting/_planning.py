"""The planned root path on the floor with the goal (paper 000, Figure 13 left)."""

import numpy as np

from ._pyplot import _pyplot

__all__ = ["plot_plan"]


def plot_plan(plan, *, ax=None, arrows=10):
    """The root's path on the floor, its heading every few frames, the start and the goal.

    Parameters
    ----------
    plan : MotionPlan
        From :meth:`MotionTreeHMM.plan`.
    ax : matplotlib Axes, default=None
        Where to draw; a new figure by default.
    arrows : int, default=10
        Heading arrows drawn along the path.

    Returns
    -------
    figure : matplotlib.figure.Figure

    Examples
    --------
    >>> import pytest
    >>> _ = pytest.importorskip("matplotlib")
    >>> import numpy as np
    >>> from types import SimpleNamespace
    >>> from skmotion.plotting import plot_plan
    >>> root = np.column_stack([np.linspace(0, 2, 50), np.r_[np.zeros(25), np.linspace(0, 1, 25)], np.zeros(50)])
    >>> figure = plot_plan(SimpleNamespace(root=root, goal=np.array([2.0, 1.0]), nodes=np.zeros(50, int)))
    >>> len(figure.axes[0].get_lines())
    3
    """
    plt = _pyplot()
    if ax is None:
        figure, ax = plt.subplots(figsize=(5, 4))
    else:
        figure = ax.figure
    x, y, heading = plan.root[:, 0], plan.root[:, 1], plan.root[:, 2]
    # The planning frame has x ahead and y to the left: draw y leftwards as in a map seen from above.
    ax.plot(-y, x, "-", color="tab:blue", label="root path")
    ax.plot([-y[0]], [x[0]], "o", color="tab:green", label="start")
    ax.plot([-plan.goal[1]], [plan.goal[0]], "*", color="tab:red", markersize=14, label="goal")
    every = np.linspace(0, len(x) - 1, max(arrows, 2)).astype(int)
    ax.quiver(
        -y[every],
        x[every],
        -np.sin(heading[every]),
        np.cos(heading[every]),
        angles="xy",
        scale=12,
        width=0.004,
        color="tab:gray",
    )
    ax.set_xlabel("left  <-  y (m)")
    ax.set_ylabel("x, ahead (m)")
    ax.set_aspect("equal")
    ax.set_title(f"planned root path ({len(x)} frames)")
    ax.legend(loc="best")
    return figure
