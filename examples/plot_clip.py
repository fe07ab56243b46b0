"""
A clip as poses over time
=========================

``plot_clip`` draws a clip's poses as stick figures coloured by time, moved along the
direction of travel just enough not to overlap, with the root's path through them.
"""

import matplotlib.pyplot as plt

from skmotion.datasets import make_motions
from skmotion.plotting import plot_clip

data = make_motions(n_clips_per_class=1, classes=["walk", "squat"], random_state=0)
for clip, skeleton, label in zip(data.clips, data.skeletons, data.target):
    figure = plot_clip(clip, skeleton, frame_rate=data.frame_rate, n_poses=8)
    figure.suptitle(data.target_names[label])
plt.show()
