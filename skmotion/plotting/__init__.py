"""Optional matplotlib figures (install with ``pip install "skmotion[plot]"``).

matplotlib is imported inside the functions, so ``import skmotion.plotting`` is
cheap and works without it.
"""

from ._neighbors import plot_pruning_recall
from ._planning import plot_plan
from ._primitives import plot_eigenmovements
from ._tree import plot_motion_tree_layer, plot_motion_tree_layers, plot_motion_tree_profile

__all__ = [
    "plot_eigenmovements",
    "plot_motion_tree_layer",
    "plot_motion_tree_layers",
    "plot_motion_tree_profile",
    "plot_plan",
    "plot_pruning_recall",
]
