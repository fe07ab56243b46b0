"""How a motion tree is built.

Offers :class:`TreeParams` and ``TREE_CONSTRAINTS`` (``_params.py``: the one
description of the build's parameters, and the paper's settings
``PAPER_TREE`` and ``PAPER_SETTINGS``), the split rules (``_split.py``:
``SPLIT_RULES``, :func:`best_split`) and :func:`build_nodes` (``_nodes.py``:
principal axes and 1-D cuts, layer by layer), whose arrays make a
:class:`~skmotion.tree.MotionTree`.
"""

from skmotion.tree._build._nodes import build_nodes
from skmotion.tree._build._params import PAPER_SETTINGS, PAPER_TREE, TREE_CONSTRAINTS, TreeParams
from skmotion.tree._build._split import SPLIT_CRITERIA, SPLIT_RULES, best_split, split_scores

__all__ = [
    "PAPER_SETTINGS",
    "PAPER_TREE",
    "SPLIT_CRITERIA",
    "SPLIT_RULES",
    "TREE_CONSTRAINTS",
    "TreeParams",
    "best_split",
    "build_nodes",
    "split_scores",
]
