"""The streams of ``MotionTreeHMM.stream``: answers as frames arrive.

Offers :class:`OnlineMotionStream` (``_causal.py``: the causal top-down beam,
whose per-frame update is the compiled kernel of ``_kernel.pyx``, ``_step.pyx``
and ``_answers.pyx`` over the C state of ``_structs.pxd``), the answers it
returns, :class:`OnlineState` (``_state.pyx``), and :class:`MotionStream`
(``_exact.py``: the batch answers of the frames so far, decoded again at each
update).
"""

from skmotion.tree._online._causal import OnlineMotionStream
from skmotion.tree._online._exact import MotionStream

# _from_values: the name under which pickles of an OnlineState made before this package find it
from skmotion.tree._online._state import OnlineState, _from_values  # noqa: F401

__all__ = ["MotionStream", "OnlineMotionStream", "OnlineState"]
