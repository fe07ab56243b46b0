"""The motion database: the motion tree, its transition graphs, decoding, and MotionTreeHMM."""

from skmotion.tree._motion_tree import MotionTree

__all__ = ["MotionTree"]
