"""Optional matplotlib figures (install with ``pip install "skmotion[plot]"``).

matplotlib is imported inside the functions, so ``import skmotion.plotting`` is
cheap and works without it.
"""

from ._bodies import animate_clip, plot_clip, plot_pose
from ._body_data import BodyFrames, body_frames
from ._neighbors import plot_pruning_recall
from ._planning import plot_plan
from ._primitives import plot_eigenmovements
from ._tree import plot_motion_tree_layer, plot_motion_tree_layers, plot_motion_tree_profile

__all__ = [
    "BodyFrames",
    "animate_clip",
    "body_frames",
    "plot_clip",
    "plot_eigenmovements",
    "plot_motion_tree_layer",
    "plot_motion_tree_layers",
    "plot_motion_tree_profile",
    "plot_plan",
    "plot_pose",
    "plot_pruning_recall",
]
