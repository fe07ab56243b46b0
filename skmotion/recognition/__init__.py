"""Recognition as users run it: one estimator from clips to labels, with measured defaults."""

from skmotion.recognition._motion_classifier import MotionClassifier, block_scales, clip_covariances

__all__ = ["MotionClassifier", "block_scales", "clip_covariances"]
