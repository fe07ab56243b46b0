"""The growing database of ``MotionTreeHMM.partial_fit``.

Offers :func:`grow` (``_step.py``: one call's growth, the database's arrays in,
new ones out) over :class:`LiveDatabase` (``_live.py``: the tree kept with every
node's exact :class:`Moments`, ``_moments.py``, and the clips; new frames routed
down, leaves split and subtrees rebuilt where due).
"""

from skmotion.tree._growth._live import LiveDatabase, check_growth_params
from skmotion.tree._growth._moments import Moments
from skmotion.tree._growth._step import Graphs, grow, regraph, union_classes

__all__ = [
    "Graphs",
    "LiveDatabase",
    "Moments",
    "check_growth_params",
    "grow",
    "regraph",
    "union_classes",
]
