"""skmotion: scikit-learn-compatible estimators for human motion capture clips.

Subpackages are imported on first use, so ``import skmotion`` stays light.
"""

import importlib

__version__ = "0.1.0"

_SUBPACKAGES = (
    "base",
    "control",
    "datasets",
    "decomposition",
    "estimator_checks",
    "io",
    "kinematics",
    "live",
    "metrics",
    "neighbors",
    "plotting",
    "preprocessing",
    "recognition",
    "utils",
    "tree",
    "planning",
)

__all__ = ["__version__", *_SUBPACKAGES]


def __getattr__(name):
    if name in _SUBPACKAGES:
        return importlib.import_module(f"skmotion.{name}")
    raise AttributeError(f"module 'skmotion' has no attribute {name!r}")


def __dir__():
    return sorted(__all__)
