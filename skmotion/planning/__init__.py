"""Motion planning on a motion database's transition graph, root motion recovery and IK (paper 000, V-C)."""

from skmotion.planning._ik import damped_ik, facing_pose, marker_jacobian, plan_axes
from skmotion.planning._root_motion import planar_step, rigid_root_velocity, skeleton_root_velocity

__all__ = [
    "damped_ik",
    "facing_pose",
    "marker_jacobian",
    "planar_step",
    "plan_axes",
    "rigid_root_velocity",
    "skeleton_root_velocity",
]
