"""A* over (node, pose on the floor): the most probable node path that takes the root to a goal.

A state is a node of the transition graph and the root's pose on the floor
``(x, y, heading)`` at one frame. One step moves to a successor node (only
transitions seen in the data) and moves the root by the current node's
per-frame displacement, turned by the current heading. The search minimises

    cost = -log P(path) = -log P(n_0) - sum_i log p(n_i -> n_(i+1))

over paths whose root ends within ``tolerance`` of the goal in at most
``max_frames`` frames. The heuristic is a lower bound of the cost still to
pay: no frame moves the root farther than ``s_max`` and none costs less than
``c_min``, and no transition costs less than ``r`` per metre moved, so
``h = max(c_min * ceil((d - tol) / s_max), r * (d - tol))`` never
overestimates (admissible); with ``heuristic_weight = w > 1`` the search is
weighted A*, whose path costs at most ``w`` times the optimum, found faster.
Poses are merged into cells (``cell`` metres, ``heading_bins`` headings) per
node, the first (cheapest) arrival keeping its exact pose, as in hybrid A*.
"""

import math
from dataclasses import dataclass

import numpy as np

from skmotion.planning._astar_state import _LowerBound, _OpenSet

__all__ = ["SearchResult", "UnreachableGoalError", "astar_search"]


class UnreachableGoalError(ValueError):
    """The goal cannot be reached with the motions of the database (within ``max_frames``).

    Attributes
    ----------
    closest : float
        The smallest distance to the goal the search reached, in metres.
    """

    def __init__(self, message, closest=math.inf):
        super().__init__(message)
        self.closest = closest


@dataclass
class SearchResult:
    """Nodes and root poses of a path found by :func:`astar_search`.

    Attributes
    ----------
    nodes : ndarray of int of shape (n_frames,)
    poses : ndarray of shape (n_frames, 3)
        ``(x, y, heading)`` of the root at each frame.
    cost : float
        ``-log P(path)``.
    expansions : int
        States taken from the open list.
    """

    nodes: np.ndarray
    poses: np.ndarray
    cost: float
    expansions: int


def _graph_lists(indptr, indices, costs, steps, max_dwell, dwell_span):
    """Per node: its self-loop cost (or None), its other successors, and its dwell displacements.

    ``dwell[m][k]`` is the body-frame displacement after ``k`` frames in node
    ``m`` (a constant twist, composed exactly), for ``k`` from 0 (none) to
    ``dwell_span`` times the node's mean dwell ``1 / (1 - p(m -> m))``: a
    longer stay has probability below ``exp(-dwell_span)``.
    """
    loops, moves, dwell = [], [], []
    for m in range(len(indptr) - 1):
        succ = indices[indptr[m] : indptr[m + 1]]
        cost = costs[indptr[m] : indptr[m + 1]]
        own = succ == m
        loops.append(float(cost[own][0]) if own.any() else None)
        moves.append([(int(n), float(c)) for n, c in zip(succ[~own], cost[~own])])
        longest = 1
        if own.any():
            leave = -math.expm1(-float(cost[own][0]))  # 1 - p(m -> m)
            longest = (
                max_dwell if leave <= 0 else int(min(max_dwell, math.ceil(dwell_span / leave)))
            )
        dx, dy, dh = steps[m]
        dwell.append(np.vstack([np.zeros((1, 3)), _compose(dx, dy, dh, np.arange(1, longest + 1))]))
    return loops, moves, dwell


def _compose(dx, dy, dh, k):
    """``k`` repeats of the planar step ``(dx, dy, dh)``: an arc of the same constant twist."""
    if abs(dh) < 1e-12:
        return np.column_stack([k * dx, k * dy, np.zeros(len(k))])
    # One step is a rotation by dh about a fixed centre c: p -> c + R(dh) (p - c).
    cx = (dx - dy * math.sin(dh) / (1 - math.cos(dh))) / 2 if abs(1 - math.cos(dh)) > 1e-15 else 0.0
    cy = (dy + dx * math.sin(dh) / (1 - math.cos(dh))) / 2 if abs(1 - math.cos(dh)) > 1e-15 else 0.0
    a = k * dh
    return np.column_stack(
        [cx - (np.cos(a) * cx - np.sin(a) * cy), cy - (np.sin(a) * cx + np.cos(a) * cy), a]
    )


def _advance(pose, displacements):
    """World poses ``(x, y, heading)`` after body-frame displacements ``(k, 3)`` from ``pose``."""
    x, y, h = pose
    c, s = math.cos(h), math.sin(h)
    dx, dy, dh = displacements.T
    return x + c * dx - s * dy, y + s * dx + c * dy, h + dh


class _Search:
    """Weighted A* over (node, pose) with poses merged into cells; see :func:`astar_search`."""

    def __init__(self, graph, bound, goal, *, max_frames, cell, heading_bins, closest):
        self.loops, self.moves, self.dwell = graph
        self.bound, self.goal, self.max_frames = bound, goal, max_frames
        self.cell, self.heading_bins = cell, heading_bins
        self.open, self.best = _OpenSet(), {}
        self.expansions, self.fallback, self.closest = 0, -1, closest

    def key(self, node, x, y, h):
        """The cell of a pose in a node."""
        turn = (h % (2.0 * math.pi)) / (2.0 * math.pi)
        return (
            node,
            int(np.rint(x / self.cell)),
            int(np.rint(y / self.cell)),
            int(turn * self.heading_bins),
        )

    def keys(self, x, y, h):
        """The cells of arrays of poses, as int arrays ``(ix, iy, ih)``."""
        turn = (h % (2.0 * math.pi)) / (2.0 * math.pi)
        ix, iy = (np.rint(v / self.cell).astype(np.int64) for v in (x, y))
        return ix, iy, (turn * self.heading_bins).astype(np.int64)

    def run(self, max_expansions):
        """The index of the entry that ends the path found, or -1."""
        pop, best, cell_of = self.open.pop, self.best, self.key  # local names: the hot loop
        while self.open:
            entry = pop()
            _, i, node, x, y, h, _, _, cost, _ = entry
            if node < 0:
                return i
            key = cell_of(node, x, y, h)
            if best.get(key, math.inf) < cost:
                continue
            best[key] = cost
            self.expansions += 1
            if self.expansions > max_expansions:
                # Out of budget: the cheapest path found so far that ends at the goal, if any
                # (it reaches the goal on seen transitions, but its cost is not proven minimal).
                return self.fallback
            self.expand(i, entry)
        return -1

    def expand(self, i, entry):
        """Every dwell in the entry's node at once: an end at the goal, then the next nodes."""
        n = entry.node
        # poses at frames t .. t + k: k frames in n (k = 0 is the entry's own pose)
        x, y, h = _advance(entry.pose, self.dwell[n][: self.max_frames - entry.frame + 1])
        dist = np.hypot(self.goal[0] - x, self.goal[1] - y)
        self.closest = min(self.closest, float(dist.min()))
        # A node without a self-loop is left after one frame: j = 0 stays only.
        loop = self.loops[n] if self.loops[n] is not None else 0.0
        at_goal = np.flatnonzero(
            dist[: len(dist) - 1 if self.loops[n] is not None else 1] <= self.bound.tol
        )
        if len(at_goal):
            j = int(at_goal[0])  # end at frame t + j, after j self-loops
            cost = entry.cost + j * loop
            pose = (float(x[j]), float(y[j]), float(h[j]))
            end = self.open.push(cost, -1, pose, i, entry.frame + j, cost, j + 1)
            if self.fallback < 0 or cost < self.open.entry(self.fallback).cost:
                self.fallback = end
        self.push_moves(i, entry, loop, (x[1:], y[1:], h[1:]), dist[1:])

    def push_moves(self, i, entry, loop, poses, dist):
        """Leave the node after ``j + 1`` frames (pose ``poses[:, j]``) to each successor."""
        need = self.bound.frames(dist)
        ok = np.flatnonzero(entry.frame + np.arange(1, len(dist) + 1) + need < self.max_frames)
        moves = self.moves[entry.node]
        if not len(ok) or not moves:
            return
        lower = self.bound.cost(dist, need)
        ix, iy, ih = self.keys(*poses)
        # A longer dwell ending in the same cell as a shorter one costs more and would be
        # merged into it: only the first dwell into each cell is worth a push.
        fresh = np.ones(len(ix), dtype=bool)
        fresh[1:] = (np.diff(ix) != 0) | (np.diff(iy) != 0) | (np.diff(ih) != 0)
        ok = ok[fresh[ok]]
        ix, iy, ih, lower = ix.tolist(), iy.tolist(), ih.tolist(), lower.tolist()
        x, y, h = poses
        best_get, push = self.best.get, self.open.push  # local names: the hot loop
        for j in ok.tolist():
            base, pose, frame = entry.cost + j * loop, None, entry.frame + j + 1
            for m, cost in moves:
                g = base + cost
                if best_get((m, ix[j], iy[j], ih[j]), math.inf) <= g:
                    continue
                if pose is None:
                    pose = (float(x[j]), float(y[j]), float(h[j]))
                push(g + lower[j], m, pose, i, frame, g, j + 1)

    def result(self, found):
        """The path that ends at entry ``found``, frame by frame."""
        chain = self.open.chain(found)
        nodes, poses = [], []
        for a, b in zip(chain[:-1], chain[1:]):
            # entry a dwelt b.dwell frames in its node before b
            nodes += [a.node] * b.dwell
            poses.append(np.column_stack(_advance(a.pose, self.dwell[a.node][: b.dwell])))
        return SearchResult(
            nodes=np.array(nodes, dtype=np.intp),
            poses=np.vstack(poses),
            cost=chain[-1].cost,
            expansions=self.expansions,
        )


def astar_search(
    indptr,
    indices,
    costs,
    steps,
    start_costs,
    start,
    goal,
    *,
    tolerance,
    max_frames,
    heuristic_weight=1.0,
    cell=0.05,
    heading_bins=36,
    max_expansions=500_000,
    dwell_span=3.0,
):
    """Search the most probable node path whose root reaches ``goal``; see the module notes.

    Parameters
    ----------
    indptr, indices, costs : ndarray
        The seen transitions in CSR form: node ``m``'s successors are
        ``indices[indptr[m]:indptr[m + 1]]`` at ``costs`` ``-log p(m -> n)``.
    steps : ndarray of shape (n_nodes, 3)
        Per node, the root's displacement during one frame in the body frame
        ``(dx, dy, dheading)``, metres and radians.
    start_costs : ndarray of shape (n_nodes,)
        ``-log P(n_0)``; ``inf`` for nodes the path may not start at.
    start : tuple of (float, float, float)
        The root's ``(x, y, heading)`` at the first frame.
    goal : tuple of (float, float)
    tolerance : float
        The path ends when the root is this close to the goal (metres).
    max_frames : int
    heuristic_weight : float, default=1.0
    cell : float, default=0.05
    heading_bins : int, default=36
    max_expansions : int, default=500000
        After this many expansions, return the cheapest path to the goal found
        so far, or give up (as unreachable) when there is none.
    dwell_span : float, default=3.0
        The longest stay in a node, in multiples of its mean stay
        ``1 / (1 - p_self)``.

    Returns
    -------
    result : SearchResult

    Raises
    ------
    UnreachableGoalError
        When no path within ``max_frames`` ends within ``tolerance`` of the goal.

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.planning import astar_search
    >>> # Node 0 walks 0.1 m forward per frame, node 1 steps 0.1 m left; 0 -> 0, 0 -> 1, 1 -> 1.
    >>> indptr, indices = np.array([0, 2, 3]), np.array([0, 1, 1])
    >>> costs = -np.log([0.9, 0.1, 1.0])
    >>> steps = np.array([[0.1, 0.0, 0.0], [0.0, 0.1, 0.0]])
    >>> r = astar_search(indptr, indices, costs, steps, np.array([0.0, np.inf]), (0, 0, 0),
    ...                  (0.5, 0.3), tolerance=0.01, max_frames=20)
    >>> r.nodes.tolist(), r.poses[-1].round(6).tolist()
    ([0, 0, 0, 0, 0, 1, 1, 1, 1], [0.5, 0.3, 0.0])
    """
    bound = _LowerBound.of_graph(indptr, costs, steps, tolerance, heuristic_weight)
    goal = (float(goal[0]), float(goal[1]))
    d0 = math.hypot(goal[0] - start[0], goal[1] - start[1])
    if bound.frames(d0) >= max_frames:
        raise UnreachableGoalError(
            f"the goal is {d0:.3f} m away, but the fastest motion of the database covers at most "
            f"{bound.s_max * (max_frames - 1):.3f} m in max_frames={max_frames} frames.",
            closest=d0,
        )
    search = _Search(
        _graph_lists(indptr, indices, costs, steps, max_frames, dwell_span),
        bound,
        goal,
        max_frames=max_frames,
        cell=cell,
        heading_bins=heading_bins,
        closest=d0,
    )
    start_bound = 0.0 if d0 <= bound.tol else float(bound.cost(d0, bound.frames(d0)))
    for n in np.flatnonzero(np.isfinite(start_costs)):
        cost = float(start_costs[n])
        search.open.push(cost + start_bound, int(n), tuple(map(float, start)), -1, 0, cost, 0)
    found = search.run(max_expansions)
    if found < 0:
        why = (
            f"gave up after max_expansions={max_expansions} expansions"
            if search.open
            else "every path was explored"
        )
        raise UnreachableGoalError(
            f"no path of the transition graph takes the root within {bound.tol:g} m of the goal "
            f"in max_frames={max_frames} frames ({why}); the closest approach was "
            f"{search.closest:.3f} m.",
            closest=search.closest,
        )
    return search.result(found)
