"""Planning on a fitted motion database: parameters checked, one layer of its graph gathered.

:meth:`MotionTreeHMM.plan` delegates here. What the planner reads of the
model and of the transformer are public fitted attributes only.
"""

from numbers import Integral, Real

import numpy as np
from sklearn.utils.validation import check_is_fitted

from skmotion.planning._plan import SkeletonModel, default_body_size, plan_motion
from skmotion.utils._sklearn_compat import HasMethods, Interval, validate_params

__all__ = ["plan_from_database"]

_POSITIVE = Interval(Real, 0, None, closed="neither")


def _check_point(name, value, size, what):
    point = np.asarray(value, dtype=float)
    if point.shape != (size,) or not np.isfinite(point).all():
        raise ValueError(f"{name} must be a finite {what}; got {point.tolist()!r}.")
    return tuple(point)


def _skeleton_model(database, transformer):
    """The transformer's :class:`SkeletonModel` (None without a skeleton), checked."""
    if database.n_features_in_ % 6:
        raise ValueError(
            "plan needs virtual-marker clips, 6 channels (px, py, pz, vx, vy, vz) per marker; "
            f"the model has {database.n_features_in_} channels."
        )
    if transformer is None:
        return None
    check_is_fitted(transformer)
    if len(transformer.marker_names_) * 6 != database.n_features_in_:
        raise ValueError(
            f"transformer gives {6 * len(transformer.marker_names_)} channels, the model has "
            f"{database.n_features_in_}."
        )
    return None if transformer.skeleton is None else SkeletonModel.from_transformer(transformer)


@validate_params(
    {
        "database": [HasMethods(["decode"])],
        "start": ["array-like"],
        "goal": ["array-like"],
        "frame_rate": [_POSITIVE],
        "body_size": [_POSITIVE, None],
        "transformer": [HasMethods(["transform"]), None],
        "layer": [Integral, None],
        "max_frames": [Interval(Integral, 2, None, closed="left")],
        "tolerance": [_POSITIVE],
        "start_node": [Interval(Integral, 0, None, closed="left"), None],
        "heuristic_weight": [Interval(Real, 1, None, closed="left")],
        "cell": [_POSITIVE],
        "heading_bins": [Interval(Integral, 1, None, closed="left")],
        "max_expansions": [Interval(Integral, 1, None, closed="left")],
    },
    prefer_skip_nested_validation=True,
)
def plan_from_database(
    database,
    start,
    goal,
    *,
    frame_rate,
    body_size=None,
    transformer=None,
    layer=None,
    max_frames=300,
    tolerance=0.1,
    start_node=None,
    heuristic_weight=8.0,
    cell=0.05,
    heading_bins=36,
    max_expansions=500_000,
):
    """Plan a motion on a database's global graph that takes the root from ``start`` to ``goal``.

    A* over (node, root pose on the floor) finds the most probable node
    path (minimum ``-log P(path)``, the start node's frequency times the
    transition probabilities) whose root ends within ``tolerance`` of the
    goal, using only transitions seen in the data; the root's per-frame
    motion in each node comes from its mean marker velocities by a damped
    least-squares inverse of the marker Jacobian (Yamane, Yamaguchi and
    Nakamura, section V-C). :meth:`MotionTreeHMM.plan` calls this; see the user
    guide (``docs/planning.md``).

    Parameters
    ----------
    database : MotionTreeHMM
        Fitted on virtual-marker clips, per marker ``(px, py, pz, vx, vy, vz)``
        in the body frame (:class:`~skmotion.preprocessing.VirtualMarkerTransform`).
    start : tuple of (float, float, float)
        The root's ``(x, y, heading)`` on the floor at the first frame
        (metres, radians; ``x`` ahead and ``y`` left at heading 0).
    goal : tuple of (float, float)
        The goal position on the floor, metres.
    frame_rate : float
        Frames per second of the training clips (velocities are per second).
    body_size : float, default=None
        Metres per unit of the marker data: with the transformer's default
        size normalisation, the subject's size (ankle to head top along
        the body) in metres. None takes it from the transformer's skeleton
        when its units are known, else 1.0 (plan in body sizes).
    transformer : VirtualMarkerTransform, default=None
        The fitted transform that made the training clips. With a
        skeleton, root motion uses the skeleton's Jacobian and the plan
        gets joint angles (``plan.to_motion()`` for ``write_bvh``);
        without, the rigid-body fit of all markers.
    layer : int, default=None
        The layer to plan at; the model's ``layer_`` by default.
    max_frames : int, default=300
        The longest plan.
    tolerance : float, default=0.1
        The plan ends when the root is this close to the goal, metres.
    start_node : int, default=None
        The node of the first frame; None lets the search choose (costed
        by the node's share of the training frames).
    heuristic_weight : float, default=8.0
        Weighted A*: the path's cost is at most this times the optimum
        (1 is plain A*, optimal but slow: its lower bound of the cost
        still to go is weak, see :func:`~skmotion.planning.astar_search`).
    cell, heading_bins : float, int, default=0.05, 36
        Poses closer than this (metres, heading bins) are one search state.
    max_expansions : int, default=500000
        After this many states the search returns the cheapest path to
        the goal it has found, or raises when it has found none.

    Returns
    -------
    plan : MotionPlan
        Nodes, log probability, frames, root trajectory and, with a
        skeleton, joint angles.

    Raises
    ------
    UnreachableGoalError
        (a ``ValueError``) when no motion of the database reaches the goal
        within ``max_frames``: the plan is never a wrong path.

    Examples
    --------
    >>> from skmotion.datasets import make_walks
    >>> from skmotion.io import as_motions
    >>> from skmotion.planning import plan_from_database
    >>> from skmotion.preprocessing import VirtualMarkerTransform
    >>> from skmotion.tree import MotionTreeHMM
    >>> walks = make_walks(2, directions=["forward", "left"], random_state=0)
    >>> motions = as_motions(walks.clips, walks.skeletons, walks.frame_rate)
    >>> X = VirtualMarkerTransform().fit_transform(motions)
    >>> database = MotionTreeHMM(max_depth=5, split="median").fit(X, walks.target)
    >>> plan = plan_from_database(database, (0, 0, 0), (2.0, 1.0), frame_rate=30, body_size=1.6,
    ...                           tolerance=0.15)
    >>> plan.reached < 0.15, bool((plan.seen_counts > 0).all())
    (True, True)
    """
    check_is_fitted(database)
    start = _check_point("start", start, 3, "(x, y, heading)")
    goal = _check_point("goal", goal, 2, "(x, y)")
    model = _skeleton_model(database, transformer)
    layer = database.layer_ if layer is None else database.tree_.check_layer(layer)
    n_nodes = database.tree_.n_nodes[layer]
    if start_node is not None and start_node >= n_nodes:
        raise ValueError(
            f"start_node must be below {n_nodes}, the nodes of layer {layer}; got {start_node}."
        )
    if body_size is None:
        body_size = default_body_size(model) or 1.0
    graph = database.global_graph_
    return plan_motion(
        database.tree_.means(layer) * database.scale_ + database.center_,
        (graph.counts(layer, 0), lambda src, dst: graph.log_prob(layer, 0, src, dst)),
        graph.visits(layer)[0],
        start,
        goal,
        frame_rate=frame_rate,
        body_size=body_size,
        start_node=start_node,
        model=model,
        layer=layer,
        max_frames=max_frames,
        tolerance=tolerance,
        heuristic_weight=heuristic_weight,
        cell=cell,
        heading_bins=heading_bins,
        max_expansions=max_expansions,
    )
