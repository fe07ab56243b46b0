"""The motion database: the motion tree, its transition graphs, decoding, and MotionTreeHMM."""

import sys

from skmotion.tree import _encoding, _growth, _online
from skmotion.tree._build import PAPER_SETTINGS
from skmotion.tree._build._out_of_core import build_tree_out_of_core
from skmotion.tree._decoder import (
    NODE_PRIORS,
    beam_decode,
    exhaustive_viterbi,
    kbest_viterbi,
    max_marginals,
    node_log_posterior,
)
from skmotion.tree._encoder import MotionTreeEncoder
from skmotion.tree._hmm import MotionTreeHMM
from skmotion.tree._motion_tree import MotionTree
from skmotion.tree._transitions import TransitionGraphs

# Pickles made before the _growth, _online and _encoding sub-packages name these
# modules: they load from their new homes.
sys.modules.update(
    {
        "skmotion.tree._encoder_columns": _encoding._columns,
        "skmotion.tree._histograms": _encoding._histograms,
        "skmotion.tree._routing": _encoding._routing,
        "skmotion.tree._incremental": _growth._live,
        "skmotion.tree._moments": _growth._moments,
        "skmotion.tree._online_stream": _online._causal,
        "skmotion.tree._stream": _online._exact,
    }
)

__all__ = [
    "MotionTree",
    "MotionTreeEncoder",
    "MotionTreeHMM",
    "NODE_PRIORS",
    "PAPER_SETTINGS",
    "TransitionGraphs",
    "beam_decode",
    "build_tree_out_of_core",
    "exhaustive_viterbi",
    "kbest_viterbi",
    "max_marginals",
    "node_log_posterior",
]
