"""
The motion tree, coloured by class
==================================

A ``MotionTreeHMM`` clusters the frames of the training clips into a binary tree. Each
node is drawn at its mean frame on the first principal axes, coloured by the class most
of its frames come from; lines are the likely transitions.
"""

import matplotlib.pyplot as plt
import numpy as np

from skmotion.datasets import make_motions
from skmotion.tree import MotionTreeHMM

data = make_motions(n_clips_per_class=4, classes=["walk", "jump", "squat"], random_state=0)
clips = [c[:, 6:] for c in data.clips]  # joint angles without the root's travel
model = MotionTreeHMM(max_depth=6).fit(clips, data.target_names[data.target])

from skmotion.plotting import plot_motion_tree_layers  # noqa: E402

frames = (np.vstack(clips) - model.center_) / model.scale_
labels = np.repeat(data.target_names[data.target], [len(c) for c in clips])
plot_motion_tree_layers(model.tree_, model.global_graph_, frames=frames, labels=labels)
plt.show()
