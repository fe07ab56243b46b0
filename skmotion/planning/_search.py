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

import heapq
import math
from dataclasses import dataclass

import numpy as np

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


def _successor_lists(indptr, indices, costs, steps):
    """Per node, a list of (successor, cost) and its own displacement; plain floats for speed."""
    out = []
    for m in range(len(indptr) - 1):
        lo, hi = indptr[m], indptr[m + 1]
        out.append([(int(n), float(c)) for n, c in zip(indices[lo:hi], costs[lo:hi])])
    return out, [tuple(map(float, s)) for s in steps]


def astar_search(indptr, indices, costs, steps, start_costs, start, goal, *, tolerance, max_frames,
                 heuristic_weight=1.0, cell=0.05, heading_bins=36, max_expansions=500_000):
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
        Give up (as unreachable) after this many expansions.

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
    >>> r = astar_search(indptr, indices, costs, steps, np.array([0.0, np.inf]), (0, 0, 0), (0.5, 0.3),
    ...                  tolerance=0.01, max_frames=20)
    >>> r.nodes.tolist(), r.poses[-1].round(6).tolist()
    ([0, 0, 0, 0, 0, 1, 1, 1, 1], [0.5, 0.3, 0.0])
    """
    succ, step = _successor_lists(indptr, indices, costs, steps)
    gx, gy = float(goal[0]), float(goal[1])
    tol = float(tolerance)
    lengths = np.hypot(steps[:, 0], steps[:, 1])
    s_max = float(lengths.max()) if len(lengths) else 0.0
    seen_costs = np.asarray(costs, dtype=float)
    c_min = float(seen_costs.min()) if len(seen_costs) else math.inf
    src = np.repeat(np.arange(len(indptr) - 1), np.diff(indptr))
    moving = lengths[src] > 0
    r = float((seen_costs[moving] / lengths[src][moving]).min()) if moving.any() else 0.0
    w = float(heuristic_weight)

    def frames_needed(d):
        if d <= tol:
            return 0
        return math.inf if s_max == 0 else math.ceil((d - tol) / s_max - 1e-12)

    def heuristic(d):
        if d <= tol:
            return 0.0
        return w * max(c_min * frames_needed(d), r * (d - tol))

    d0 = math.hypot(gx - start[0], gy - start[1])
    if frames_needed(d0) >= max_frames:
        raise UnreachableGoalError(
            f"the goal is {d0:.3f} m away, but the fastest motion of the database covers at most "
            f"{s_max * (max_frames - 1):.3f} m in max_frames={max_frames} frames.", closest=d0,
        )
    two_pi = 2.0 * math.pi
    key_of = lambda n, x, y, h: (n, round(x / cell), round(y / cell), int((h % two_pi) / two_pi * heading_bins))  # noqa: E731
    nodes, poses, parents, frames, gs = [], [], [], [], []
    heap, best = [], {}
    counter = 0
    for n in np.flatnonzero(np.isfinite(start_costs)):
        g = float(start_costs[n])
        nodes.append(int(n)); poses.append(tuple(map(float, start))); parents.append(-1); frames.append(0); gs.append(g)
        heapq.heappush(heap, (g + heuristic(d0), counter, len(nodes) - 1))
        counter += 1
    closest, expansions, found = d0, 0, -1
    while heap:
        _, _, i = heapq.heappop(heap)
        n, (x, y, h), g, t = nodes[i], poses[i], gs[i], frames[i]
        key = key_of(n, x, y, h)
        if best.get(key, math.inf) < g:
            continue
        best[key] = g
        d = math.hypot(gx - x, gy - y)
        closest = min(closest, d)
        if d <= tol:
            found = i
            break
        expansions += 1
        if expansions > max_expansions:
            break
        dx, dy, dh = step[n]
        c, s = math.cos(h), math.sin(h)
        nx, ny, nh = x + c * dx - s * dy, y + s * dx + c * dy, h + dh
        nd = math.hypot(gx - nx, gy - ny)
        if t + 1 + frames_needed(nd) >= max_frames:
            continue
        hh = heuristic(nd)
        for m, cost in succ[n]:
            ng = g + cost
            if best.get(key_of(m, nx, ny, nh), math.inf) <= ng:
                continue
            nodes.append(m); poses.append((nx, ny, nh)); parents.append(i); frames.append(t + 1); gs.append(ng)
            heapq.heappush(heap, (ng + hh, counter, len(nodes) - 1))
            counter += 1
    if found < 0:
        why = f"gave up after max_expansions={max_expansions} expansions" if heap else "every path was explored"
        raise UnreachableGoalError(
            f"no path of the transition graph takes the root within {tol:g} m of the goal in max_frames={max_frames} "
            f"frames ({why}); the closest approach was {closest:.3f} m.", closest=closest,
        )
    chain = []
    while found >= 0:
        chain.append(found)
        found = parents[found]
    chain.reverse()
    return SearchResult(
        nodes=np.array([nodes[i] for i in chain], dtype=np.intp),
        poses=np.array([poses[i] for i in chain]),
        cost=gs[chain[-1]],
        expansions=expansions,
    )
