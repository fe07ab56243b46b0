"""The encoder's routing and readouts: a clip's frames down a motion tree, then summed per clip.

Offers :class:`TreeRouter` (``_routing.py``: every layer's node of all frames in
one compiled walk, ``_walk.pyx``, the standardisation folded into the splits), the
per-clip blocks over routed node labels (``_histograms.py``: occupancy with its
temporal pyramid, transitions, first- and second-order residuals, the clip's
moments; the residuals, the moments and the magnitude check are compiled passes over
each clip's frames in ``_readout_passes.pyx``) and the encoder's columns
(``_columns.py``: which layers it encodes, the depth to build, the columns' names).
:class:`MotionTreeEncoder` (``tree/_encoder.py``) is the estimator that holds them.
"""

from skmotion.tree._encoding._columns import build_depth, feature_names
from skmotion.tree._encoding._histograms import (
    feature_blocks,
    histogram_features,
    moment_features,
    node_variances,
    residual_features,
    second_order_features,
)
from skmotion.tree._encoding._routing import TreeRouter

__all__ = [
    "TreeRouter",
    "build_depth",
    "feature_blocks",
    "feature_names",
    "histogram_features",
    "moment_features",
    "node_variances",
    "residual_features",
    "second_order_features",
]
