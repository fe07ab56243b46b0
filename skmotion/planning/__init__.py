"""Motion planning on a motion database's transition graph, root motion recovery and IK
(Yamane, Yamaguchi and Nakamura, section V-C); and path following by motion matching.
"""

from skmotion.planning._database import plan_from_database
from skmotion.planning._ik import damped_ik, facing_pose, marker_jacobian, plan_axes
from skmotion.planning._motion_matching import (
    MatchedPath,
    follow_path,
    path_distance,
    path_from_velocities,
)
from skmotion.planning._plan import MotionPlan, SkeletonModel, node_root_velocity, plan_motion
from skmotion.planning._root_motion import planar_step, rigid_root_velocity, skeleton_root_velocity
from skmotion.planning._search import SearchResult, UnreachableGoalError, astar_search

__all__ = [
    "MatchedPath",
    "MotionPlan",
    "SearchResult",
    "SkeletonModel",
    "UnreachableGoalError",
    "astar_search",
    "damped_ik",
    "facing_pose",
    "follow_path",
    "marker_jacobian",
    "node_root_velocity",
    "path_distance",
    "path_from_velocities",
    "plan_axes",
    "plan_from_database",
    "plan_motion",
    "planar_step",
    "rigid_root_velocity",
    "skeleton_root_velocity",
]
