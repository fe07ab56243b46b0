"""Optional matplotlib figures (install with ``pip install "skmotion[plot]"``).

matplotlib is imported inside the functions, so ``import skmotion.plotting`` is
cheap and works without it.
"""

from skmotion._lazy import attach

__getattr__, __dir__ = attach(
    __name__,
    {
        "skmotion.plotting._bodies": ["animate_clip", "plot_clip", "plot_pose"],
        "skmotion.plotting._body_data": ["BodyFrames", "body_frames"],
        "skmotion.plotting._neighbors": ["plot_pruning_recall"],
        "skmotion.plotting._planning": ["plot_plan"],
        "skmotion.plotting._primitives": ["plot_eigenmovements"],
        "skmotion.plotting._tree": [
            "plot_motion_tree_layer",
            "plot_motion_tree_layers",
            "plot_motion_tree_profile",
        ],
    },
)

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
