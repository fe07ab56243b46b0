"""The compiled top-down beam decoder of a motion tree under its transition graphs.

Offers :func:`beam_decode` (one clip, any graphs: ``_decode.py`` over the
compiled search of ``_beam*.pyx``), :func:`decode_clips` (many clips, grouped by
length, in parallel: ``_batch.py``), :func:`exhaustive_viterbi` and
:func:`node_log_posterior` (the brute-force reference), and the numpy K-best
Viterbi :func:`kbest_viterbi` and :func:`max_marginals` (``_viterbi.py``).
``_tables.py`` lays a tree and its graphs out as the C arrays the compiled
modules (and those of ``tree/_online``) read; ``_emission.h`` holds the
Gaussian log-density loops both compile.
"""

from skmotion.tree._decoder._batch import decode_clips
from skmotion.tree._decoder._decode import (
    NODE_PRIORS,
    beam_decode,
    exhaustive_viterbi,
    node_log_posterior,
)
from skmotion.tree._decoder._viterbi import kbest_viterbi, max_marginals

__all__ = [
    "NODE_PRIORS",
    "beam_decode",
    "decode_clips",
    "exhaustive_viterbi",
    "kbest_viterbi",
    "max_marginals",
    "node_log_posterior",
]
