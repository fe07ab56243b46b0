"""The planned root path on the floor with the goal (Yamane et al. 2011, Figure 13 left)."""

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
    >>> x, y = np.linspace(0, 2, 50), np.r_[np.zeros(25), np.linspace(0, 1, 25)]
    >>> root = np.column_stack([x, y, np.zeros(50)])  # x ahead, y left, heading
    >>> plan = SimpleNamespace(root=root, goal=np.array([2.0, 1.0]), nodes=np.zeros(50, int))
    >>> figure = plot_plan(plan)
    >>> [line.get_label() for line in figure.axes[0].get_lines()]
    ['root path', 'start', 'goal']
    >>> figure.axes[0].get_lines()[2].get_xydata().tolist()  # 2 m ahead, 1 m left
    [[2.0, 1.0]]
    """
    plt = _pyplot()
    if ax is None:
        figure, ax = plt.subplots(figsize=(5, 4))
    else:
        figure = ax.figure
    x, y, heading = plan.root[:, 0], plan.root[:, 1], plan.root[:, 2]
    # The planning frame as the planner reports it: x ahead (to the right), y to the left (up),
    # a map seen from above with its usual right-handed axes; a goal "1 m left" is at y = +1.
    ax.plot(x, y, "-", color="tab:blue", label="root path")
    ax.plot([x[0]], [y[0]], "o", color="tab:green", label="start")
    ax.plot([plan.goal[0]], [plan.goal[1]], "*", color="tab:red", markersize=14, label="goal")
    every = np.linspace(0, len(x) - 1, max(arrows, 2)).astype(int)
    ax.quiver(
        x[every],
        y[every],
        np.cos(heading[every]),
        np.sin(heading[every]),
        angles="xy",
        scale=12,
        width=0.004,
        color="tab:gray",
        label="heading",
    )
    ax.set_xlabel("x, ahead (m)")
    ax.set_ylabel("y, left (m)")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_title(f"planned root path ({len(x)} frames)")
    ax.legend(loc="best")
    return figure
