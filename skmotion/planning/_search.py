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


def _graph_lists(indptr, indices, costs, steps, max_dwell, dwell_span):
    """Per node: its self-loop cost (or None), its other successors, and its dwell displacements.

    ``dwell[m][k - 1]`` is the body-frame displacement after ``k`` frames in
    node ``m`` (a constant twist, composed exactly), for ``k`` from 1 to
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
        k = np.arange(1, longest + 1)
        dx, dy, dh = steps[m]
        dwell.append(_compose(dx, dy, dh, k))
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
    >>> r = astar_search(indptr, indices, costs, steps, np.array([0.0, np.inf]), (0, 0, 0), (0.5, 0.3),
    ...                  tolerance=0.01, max_frames=20)
    >>> r.nodes.tolist(), r.poses[-1].round(6).tolist()
    ([0, 0, 0, 0, 0, 1, 1, 1, 1], [0.5, 0.3, 0.0])
    """
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
    loops, moves, dwell = _graph_lists(indptr, indices, costs, steps, max_frames, dwell_span)

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
            f"{s_max * (max_frames - 1):.3f} m in max_frames={max_frames} frames.",
            closest=d0,
        )
    two_pi = 2.0 * math.pi

    def key_of(n, x, y, h):
        return (
            n,
            int(np.rint(x / cell)),
            int(np.rint(y / cell)),
            int((h % two_pi) / two_pi * heading_bins),
        )

    # A search node enters graph node n at frame t with pose (x, y, h) and cost g; expanding it
    # chooses how many frames to dwell in n (self-loops) and the next node. A terminal entry
    # (n = -1) is a path that ends inside its last dwell, at the goal.
    nodes, poses, parents, frames, gs, dwells = [], [], [], [], [], []
    heap, best = [], {}

    def push(n, pose, parent, t, g, f, k=0):
        nodes.append(n)
        poses.append(pose)
        parents.append(parent)
        frames.append(t)
        gs.append(g)
        dwells.append(k)
        heapq.heappush(heap, (f, len(nodes) - 1))

    for n in np.flatnonzero(np.isfinite(start_costs)):
        push(
            int(n),
            tuple(map(float, start)),
            -1,
            0,
            float(start_costs[n]),
            float(start_costs[n]) + heuristic(d0),
        )
    closest, expansions, found, fallback = d0, 0, -1, -1
    while heap:
        _, i = heapq.heappop(heap)
        n, g, t = nodes[i], gs[i], frames[i]
        if n < 0:
            found = i
            break
        x, y, h = poses[i]
        key = key_of(n, x, y, h)
        if best.get(key, math.inf) < g:
            continue
        best[key] = g
        expansions += 1
        if expansions > max_expansions:
            # Out of budget: the cheapest path found so far that ends at the goal, if any
            # (it reaches the goal on seen transitions, but its cost is not proven minimal).
            found = fallback
            break
        # Every dwell of k frames in n at once: poses of its frames t .. t + k - 1 and after it.
        room = max_frames - t
        table = dwell[n][:room]
        c, s = math.cos(h), math.sin(h)
        px = np.concatenate([[x], x + c * table[:, 0] - s * table[:, 1]])
        py = np.concatenate([[y], y + s * table[:, 0] + c * table[:, 1]])
        ph = np.concatenate([[h], h + table[:, 2]])
        dist = np.hypot(gx - px, gy - py)
        closest = min(closest, float(dist.min()))
        loop = loops[n] if loops[n] is not None else math.inf
        at_goal = (
            np.flatnonzero(dist[: len(table)] <= tol)
            if loops[n] is not None
            else np.flatnonzero(dist[:1] <= tol)
        )
        if len(at_goal):
            j = int(at_goal[0])  # end at frame t + j, after j self-loops
            push(
                -1,
                (float(px[j]), float(py[j]), float(ph[j])),
                i,
                t + j,
                g + j * loop,
                g + j * loop,
                j + 1,
            )
            if fallback < 0 or gs[-1] < gs[fallback]:
                fallback = len(nodes) - 1
        # All dwells at once: the frame after, the lower bound still to go, the cell keys.
        ks = np.arange(1, len(table) + 1)
        dk = dist[1:]
        need = (
            np.where(dk <= tol, 0, np.ceil((dk - tol) / s_max - 1e-12))
            if s_max > 0
            else np.where(dk <= tol, 0, np.inf)
        )
        ok = np.flatnonzero(t + ks + need < max_frames)
        if not len(ok) or not moves[n]:
            continue
        hk = np.where(dk <= tol, 0.0, w * np.maximum(c_min * need, r * (dk - tol)))
        ix = np.rint(px[1:] / cell).astype(np.int64)
        iy = np.rint(py[1:] / cell).astype(np.int64)
        ih = ((ph[1:] % two_pi) / two_pi * heading_bins).astype(np.int64)
        # A longer dwell ending in the same cell as a shorter one costs more and would be
        # merged into it: only the first dwell into each cell is worth a push.
        fresh = np.ones(len(ix), dtype=bool)
        fresh[1:] = (np.diff(ix) != 0) | (np.diff(iy) != 0) | (np.diff(ih) != 0)
        ok = ok[fresh[ok]]
        ix, iy, ih, hk = ix.tolist(), iy.tolist(), ih.tolist(), hk.tolist()
        for j in ok.tolist():
            base = g + j * loop
            pose = None
            for m, cost in moves[n]:
                ng = base + cost
                if best.get((m, ix[j], iy[j], ih[j]), math.inf) <= ng:
                    continue
                if pose is None:
                    pose = (float(px[j + 1]), float(py[j + 1]), float(ph[j + 1]))
                push(m, pose, i, t + j + 1, ng, ng + hk[j], j + 1)
    if found < 0:
        why = (
            f"gave up after max_expansions={max_expansions} expansions"
            if heap
            else "every path was explored"
        )
        raise UnreachableGoalError(
            f"no path of the transition graph takes the root within {tol:g} m of the goal in max_frames={max_frames} "
            f"frames ({why}); the closest approach was {closest:.3f} m.",
            closest=closest,
        )
    # Unroll: each entry dwelt dwells[child] frames in its node before the child's node.
    chain = []
    while found >= 0:
        chain.append(found)
        found = parents[found]
    chain.reverse()
    out_nodes, out_poses = [], []
    for a, b in zip(chain[:-1], chain[1:]):
        k = dwells[b]
        x, y, h = poses[a]
        table = np.vstack([[0.0, 0.0, 0.0], dwell[nodes[a]][: k - 1]])
        c, s = math.cos(h), math.sin(h)
        out_nodes += [nodes[a]] * k
        out_poses.append(
            np.column_stack(
                [
                    x + c * table[:, 0] - s * table[:, 1],
                    y + s * table[:, 0] + c * table[:, 1],
                    h + table[:, 2],
                ]
            )
        )
    return SearchResult(
        nodes=np.array(out_nodes, dtype=np.intp),
        poses=np.vstack(out_poses),
        cost=gs[chain[-1]],
        expansions=expansions,
    )
