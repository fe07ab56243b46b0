"""The clip recogniser under a live estimator: the default, and its class probabilities."""

import numpy as np
from scipy.special import softmax

__all__ = ["class_proba", "default_recognizer", "recognizer_classes"]


def default_recognizer():
    """The recommended clip recogniser on channels that need no body frame.

    ``make_pipeline(MotionTreeEncoder(), LogisticRegression())``; joint
    positions of a tracker go first through a ``VirtualMarkerTransform`` with
    their layout (the user guide's MSRC-12 example).
    """
    from sklearn.linear_model import LogisticRegression
    from sklearn.pipeline import make_pipeline

    from skmotion.tree import MotionTreeEncoder

    return make_pipeline(MotionTreeEncoder(), LogisticRegression(max_iter=1000))


def recognizer_classes(recognizer):
    """The fitted recogniser's classes (a Pipeline reports its last step's)."""
    classes = getattr(recognizer, "classes_", None)
    if classes is None:
        raise TypeError(
            f"the recogniser {type(recognizer).__name__} has no classes_: "
            "it must be a fitted classifier."
        )
    return np.asarray(classes)


def class_proba(recognizer, windows):
    """Class probabilities of windows: ``predict_proba``, else a softmax of ``decision_function``.

    A binary ``decision_function`` (one column, the second class's margin) becomes
    ``[-d, d] / 2`` before the softmax, i.e. the logistic of ``d``.
    """
    if hasattr(recognizer, "predict_proba"):
        return np.asarray(recognizer.predict_proba(windows), dtype=float)
    if hasattr(recognizer, "decision_function"):
        margin = np.asarray(recognizer.decision_function(windows), dtype=float)
        if margin.ndim == 1:
            margin = np.column_stack([-margin, margin]) / 2
        return softmax(margin, axis=1)
    raise TypeError(
        f"the recogniser {type(recognizer).__name__} has neither predict_proba nor "
        "decision_function."
    )
