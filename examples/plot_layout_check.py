"""
Is the joint order right?
=========================

Joint positions read in another tracker's order run silently; ``check_layout`` names the
joints that do not fit. Here Kinect v1 clips are read once in their own order and once in
an order that starts with the head, as some trackers write it.
"""

import matplotlib.pyplot as plt

from skmotion.datasets import make_position_motions
from skmotion.kinematics import Layout, check_layout, get_layout
from skmotion.plotting import plot_pose

data = make_position_motions("kinect_v1", n_clips_per_class=1, random_state=0)
v1 = get_layout("kinect_v1")
print("own order:", check_layout(data.clips, v1))

head_first = ["Head", "ShoulderCenter", "Spine", "HipCenter", *v1.joints[4:]]
wrong = Layout(
    "head_first", head_first, root=v1.root, left_hip="HipLeft", right_hip="HipRight",
    left_shoulder="ShoulderLeft", right_shoulder="ShoulderRight", size_chain=v1.size_chain,
    landmarks=v1.landmarks,
)  # fmt: skip
for problem in check_layout(data.clips, wrong):
    print("head-first order:", problem)

# %%
# The first pose in each reading: the wrong order stands on its head.
pose = data.clips[0][:1]
plot_pose(pose, v1, title="read as kinect_v1")
plot_pose(pose, wrong, title="read head first")
plt.show()
