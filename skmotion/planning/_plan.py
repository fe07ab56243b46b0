"""Planning on a motion database: root motion per node, the search, and the planned motion.

Knows nothing of sklearn: :func:`plan_from_database` (behind
:meth:`MotionTreeHMM.plan`) validates its input and calls :func:`plan_motion`
with the node means and transition counts of one layer.
"""

import math
import time
from dataclasses import dataclass, field

import numpy as np

from skmotion.io import Motion
from skmotion.kinematics import body_size as chain_size
from skmotion.kinematics import euler_to_matrix, matrix_to_euler, yaw_matrix
from skmotion.planning._ik import damped_ik, facing_pose, plan_axes
from skmotion.planning._root_motion import planar_step, rigid_root_velocity, skeleton_root_velocity
from skmotion.planning._search import astar_search

__all__ = ["MotionPlan", "SkeletonModel", "default_body_size", "node_root_velocity", "plan_motion"]


@dataclass
class SkeletonModel:
    """What turns body-frame markers into joint angles: a skeleton, its markers and their roles.

    Attributes
    ----------
    skeleton : Skeleton
    markers : MarkerSet
    root, left, right : int
        Marker indices of the root (the body frame's origin lies below it)
        and of the left and right facing markers.
    units_per_size : float
        Skeleton length units per unit of the marker data (the skeleton's
        body size along the size chain; 1 when the data were not normalised).
    """

    skeleton: object
    markers: object
    root: int
    left: int
    right: int
    units_per_size: float

    @classmethod
    def from_transformer(cls, transformer):
        """The model of a fitted :class:`VirtualMarkerTransform` with a skeleton."""
        skeleton = transformer.skeleton
        markers = transformer.marker_set(skeleton)
        root, (left, right), chain = (
            transformer.root_index_,
            transformer.facing_indices_,
            transformer.size_indices_,
        )
        size = 1.0
        if chain is not None:
            size = chain_size(
                markers.positions(skeleton, np.zeros((1, skeleton.n_channels))), chain
            )
        return cls(skeleton, markers, root, left, right, size)

    def solve(self, body_positions):
        """Channels whose markers fit body-frame positions ``(n, n_markers, 3)``; the RMS error.

        The error is in data units.
        """
        targets = body_positions * self.units_per_size @ plan_axes(self.skeleton.up_axis).T
        q0 = facing_pose(
            self.skeleton, self.markers, targets, root=self.root, left=self.left, right=self.right
        )
        q, rms = damped_ik(self.skeleton, self.markers, targets, q0)
        return q, rms / self.units_per_size


def node_root_velocity(means, *, model=None, damping=1e-3):
    """Root velocity ``(u_x, u_y, w)`` of each node mean, in data units per second.

    Parameters
    ----------
    means : ndarray of shape (n_nodes, 6 * n_markers)
        Node means, per marker ``(px, py, pz, vx, vy, vz)`` in the body frame.
    model : SkeletonModel, default=None
        With it, the skeleton's Jacobian at each node's IK pose; without, the
        rigid-body fit of all markers.
    damping : float, default=1e-3

    Returns
    -------
    velocity : ndarray of shape (n_nodes, 3)
    channels : ndarray of shape (n_nodes, n_channels) or None
        The nodes' IK poses (body frame), with a model.
    ik_rms : ndarray of shape (n_nodes,) or None
        Their RMS marker error, in data units.
    """
    states = means.reshape(len(means), -1, 6)
    if model is None:
        return rigid_root_velocity(states[..., :3], states[..., 3:], damping=damping), None, None
    channels, rms = model.solve(states[..., :3])
    velocity = skeleton_root_velocity(
        model.skeleton,
        model.markers,
        channels,
        states[..., 3:] * model.units_per_size,
        damping=damping,
    )
    return velocity / np.array([model.units_per_size, model.units_per_size, 1.0]), channels, rms


@dataclass
class MotionPlan:
    """A planned motion: the node path, its probability, the frames and the root on the floor.

    Attributes
    ----------
    nodes : ndarray of int of shape (n_frames,)
        Layer indices of the nodes, one per frame.
    log_probability : float
        ``log P(path)``: the start node's prior and every transition's probability.
    frames : ndarray of shape (n_frames, n_channels)
        The nodes' mean marker states (body frame, the database's units).
    root : ndarray of shape (n_frames, 3)
        ``(x, y, heading)`` of the root on the floor at each frame, metres and
        radians, in the planning frame (``x`` ahead of the start, ``y`` left).
    goal : ndarray of shape (2,)
    layer : int
    frame_rate : float
    body_size : float
        Metres per unit of the marker data.
    seen_counts : ndarray of int of shape (n_frames - 1,)
        The count in the global graph of every transition of the path (all > 0).
    expansions : int
        States the search expanded.
    search_seconds : float
        Wall time of the search alone (root motion and IK excluded).
    channels : ndarray of shape (n_frames, n_channels) or None
        Joint angles by damped least-squares IK, when a skeleton is known.
    skeleton : Skeleton or None
    ik_rms : ndarray of shape (n_frames,) or None
        RMS distance of the IK markers to the frames' markers, metres.
    """

    nodes: np.ndarray
    log_probability: float
    frames: np.ndarray
    root: np.ndarray
    goal: np.ndarray
    layer: int
    frame_rate: float
    body_size: float
    seen_counts: np.ndarray
    expansions: int
    search_seconds: float = 0.0
    channels: np.ndarray = None
    skeleton: object = None
    ik_rms: np.ndarray = field(default=None, repr=False)

    @property
    def n_frames(self):
        return len(self.nodes)

    @property
    def reached(self):
        """Distance from the last root position to the goal, metres."""
        return float(np.hypot(*(self.root[-1, :2] - self.goal)))

    def marker_positions(self):
        """World marker positions of the frames on the planning floor, metres.

        Shape ``(n_frames, n_markers, 3)``.
        """
        local = self.frames.reshape(self.n_frames, -1, 6)[..., :3] * self.body_size
        turn = yaw_matrix(self.root[:, 2], "z")
        out = np.einsum("fij,fmj->fmi", turn, local)
        out[..., :2] += self.root[:, None, :2]
        return out

    def to_motion(self):
        """The planned motion as a :class:`~skmotion.io.Motion`, to write with ``write_bvh``."""
        if self.channels is None:
            raise ValueError(
                "this plan has no joint angles: plan with a transformer that has a skeleton."
            )
        return Motion(self.skeleton, self.channels, frame_rate=self.frame_rate)


def _place(model, channels, root, metres_per_unit):
    """Move body-frame IK poses to the planned root poses on the floor (world channels)."""
    skeleton = model.skeleton
    up = skeleton.up_axis
    axes_t = plan_axes(up)
    names = list(skeleton.channels[0])
    order = skeleton.rotation_orders[0]
    c = np.eye(3) if skeleton.axes is None else np.asarray(skeleton.axes)[0]
    rot_cols = [names.index(f"{a}rotation") if f"{a}rotation" in names else None for a in order]
    angles = np.zeros((len(channels), 3))
    for k, col in enumerate(rot_cols):
        if col is not None:
            angles[:, k] = channels[:, col]
    turn = yaw_matrix(root[:, 2], up)
    # The root's local rotation is C E C^T; turned by Y about the vertical: C E' C^T = Y C E C^T.
    new = matrix_to_euler(c.T @ turn @ c @ euler_to_matrix(angles, order), order)
    out = channels.copy()
    for k, col in enumerate(rot_cols):
        if col is not None:
            out[:, col] = new[:, k]
    pos_cols = [names.index(f"{a}position") for a in "XYZ"]
    offset = np.zeros((len(root), 3))
    offset[:, :2] = root[:, :2] / metres_per_unit
    out[:, pos_cols] = np.einsum("fij,fj->fi", turn, channels[:, pos_cols]) + offset @ axes_t.T
    return out


def plan_motion(
    means,
    transitions,
    visits,
    start,
    goal,
    *,
    frame_rate,
    body_size,
    start_node=None,
    model=None,
    damping=1e-3,
    layer=-1,
    **search,
):
    """Plan a motion on one layer of a motion database; see :meth:`MotionTreeHMM.plan`.

    Parameters
    ----------
    means : ndarray of shape (n_nodes, 6 * n_markers)
        Node means in the input's units.
    transitions : tuple of (scipy.sparse.csr_matrix, callable)
        The global graph's counts ``(n_nodes, n_nodes)``, and a function
        giving ``log p(src -> dst)`` for arrays of node indices.
    visits : ndarray of shape (n_nodes,)
        Frames per node (the start prior).
    start : tuple of (float, float, float)
    goal : tuple of (float, float)
    frame_rate, body_size : float
    start_node : int, default=None
    model : SkeletonModel, default=None
    damping : float, default=1e-3
        See :func:`node_root_velocity`.
    layer : int, default=-1
        Recorded in the plan.
    **search
        The keywords of :func:`astar_search`: ``tolerance`` and ``max_frames``
        (required), ``heuristic_weight``, ``cell``, ``heading_bins``,
        ``max_expansions``, ``dwell_span``.

    Returns
    -------
    plan : MotionPlan
    """
    counts, log_prob = transitions
    # Only transitions seen in the data: the non-zero counts, never the smoothing mass.
    counts = counts.tocsr(copy=True)
    counts.eliminate_zeros()
    counts.sort_indices()
    indptr, indices = counts.indptr, counts.indices
    costs = -log_prob(np.repeat(np.arange(len(indptr) - 1), np.diff(indptr)), indices)
    velocity, node_channels, node_rms = node_root_velocity(means, model=model, damping=damping)
    steps = planar_step(velocity * np.array([body_size, body_size, 1.0]), 1.0 / frame_rate)
    leaves = np.diff(indptr) > 0
    if start_node is None:
        with np.errstate(divide="ignore"):
            start_costs = np.where(leaves & (visits > 0), -np.log(visits / visits.sum()), np.inf)
    else:
        start_costs = np.full(len(means), np.inf)
        start_costs[start_node] = 0.0
    began = time.perf_counter()
    result = astar_search(indptr, indices, costs, steps, start_costs, start, goal, **search)
    search_seconds = time.perf_counter() - began
    nodes = result.nodes
    path_counts = np.asarray(counts[nodes[:-1], nodes[1:]]).ravel()
    plan = MotionPlan(
        nodes=nodes,
        log_probability=-result.cost,
        frames=means[nodes],
        root=result.poses,
        goal=np.asarray(goal, dtype=float),
        layer=layer,
        frame_rate=float(frame_rate),
        body_size=float(body_size),
        seen_counts=path_counts,
        expansions=result.expansions,
        search_seconds=search_seconds,
    )
    if model is not None:
        metres_per_unit = body_size / model.units_per_size
        plan.channels = _place(model, node_channels[nodes], result.poses, metres_per_unit)
        plan.skeleton = model.skeleton
        plan.ik_rms = node_rms[nodes] * body_size
    return plan


def default_body_size(model):
    """Metres per data unit from a skeleton of known units, else None."""
    if (
        model is None
        or model.skeleton.meters_per_unit is None
        or not math.isfinite(model.skeleton.meters_per_unit)
    ):
        return None
    return model.units_per_size * model.skeleton.meters_per_unit
