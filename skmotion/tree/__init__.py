"""The motion database: the motion tree, its transition graphs, decoding, and MotionTreeHMM."""

from skmotion.tree._decode import NODE_PRIORS, beam_decode, exhaustive_viterbi, node_log_posterior
from skmotion.tree._encoder import MotionTreeEncoder
from skmotion.tree._hmm import MotionTreeHMM
from skmotion.tree._motion_tree import MotionTree
from skmotion.tree._recipes import PAPER_SETTINGS
from skmotion.tree._transitions import TransitionGraphs
from skmotion.tree._viterbi import kbest_viterbi, max_marginals

__all__ = [
    "MotionTree",
    "MotionTreeEncoder",
    "MotionTreeHMM",
    "NODE_PRIORS",
    "PAPER_SETTINGS",
    "TransitionGraphs",
    "beam_decode",
    "exhaustive_viterbi",
    "kbest_viterbi",
    "max_marginals",
    "node_log_posterior",
]
