"""What the A* search of :mod:`skmotion.planning._search` keeps.

The lower bound of the cost still to go (admissible, weighted), the search
entries and the open set that orders them.
"""

import functools
import heapq
import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np


@dataclass(frozen=True)
class _LowerBound:
    """The admissible lower bound of the cost still to go, and the frames a distance needs.

    No frame moves the root farther than ``s_max`` and none costs less than
    ``c_min``, and no transition costs less than ``r`` per metre moved; the
    bound is weighted by ``w`` (see the module notes).
    """

    tol: float
    s_max: float
    c_min: float
    r: float
    w: float

    @classmethod
    def of_graph(cls, indptr, costs, steps, tolerance, heuristic_weight):
        lengths = np.hypot(steps[:, 0], steps[:, 1])
        costs = np.asarray(costs, dtype=float)
        src = np.repeat(np.arange(len(indptr) - 1), np.diff(indptr))
        moving = lengths[src] > 0
        return cls(
            tol=float(tolerance),
            s_max=float(lengths.max()) if len(lengths) else 0.0,
            c_min=float(costs.min()) if len(costs) else math.inf,
            r=float((costs[moving] / lengths[src][moving]).min()) if moving.any() else 0.0,
            w=float(heuristic_weight),
        )

    def frames(self, d):
        """The fewest frames that take the root from distance ``d`` to within ``tol``."""
        if self.s_max == 0:
            return np.where(d <= self.tol, 0, np.inf)
        return np.where(d <= self.tol, 0, np.ceil((d - self.tol) / self.s_max - 1e-12))

    def cost(self, d, frames):
        """The weighted lower bound at distance ``d``, which needs ``frames`` more frames.

        Called where some transition is seen (``c_min`` finite) or ``d > tol``.
        """
        bound = self.w * np.maximum(self.c_min * frames, self.r * (d - self.tol))
        return np.where(d <= self.tol, 0.0, bound)


class _Entry(NamedTuple):
    """A search entry: the path enters graph ``node`` at ``frame``, pose ``(x, y, h)``, ``cost``.

    Entries order as tuples: by ``priority`` (the cost plus the lower bound
    still to go), ties to the lower ``index`` (the order they were made in).
    ``node`` -1 is a path that ends at the goal inside its parent's dwell;
    ``dwell`` is how many frames the parent stayed in its node before this entry.
    """

    priority: float
    index: int
    node: int
    x: float
    y: float
    h: float
    parent: int
    frame: int
    cost: float
    dwell: int

    @property
    def pose(self):
        return self.x, self.y, self.h


# An entry kept as a plain tuple, handed out as an _Entry (C-level, unlike _Entry's own __new__).
_as_entry = functools.partial(tuple.__new__, _Entry)


class _OpenSet:
    """Every entry made (by index), and a heap of the open ones, the least first.

    Entries are stored as plain tuples in :class:`_Entry`'s field order and
    handed out as :class:`_Entry`: the garbage collector stops tracking a plain
    tuple of numbers (never a tuple subclass), which keeps its passes short
    however many entries a search makes.
    """

    def __init__(self):
        self._entries = []
        self._heap = []

    def __bool__(self):
        return bool(self._heap)

    def push(self, priority, node, pose, parent, frame, cost, dwell):
        """Make an entry and open it; returns its index."""
        entry = (priority, len(self._entries), node, *pose, parent, frame, cost, dwell)
        self._entries.append(entry)
        heapq.heappush(self._heap, entry)
        return entry[1]

    def pop(self):
        """The open entry of the least priority, closed."""
        return _as_entry(heapq.heappop(self._heap))

    def entry(self, i):
        return _as_entry(self._entries[i])

    def chain(self, i):
        """The entries from a start to entry ``i``."""
        out = []
        while i >= 0:
            out.append(self.entry(i))
            i = out[-1].parent
        return out[::-1]
