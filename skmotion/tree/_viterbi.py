"""Max-product dynamic programming on batches of small trellises, in log space.

A trellis of ``n_steps`` steps and ``n_states`` states per step is given by the
log score of each state at the first step (``initial``) and, for every later
step ``t``, the log score of moving from state ``i`` at ``t - 1`` to state ``j``
at ``t`` *including* the score of ``j`` itself (``steps[t - 1, :, i, j]``). A
sequence's score is the sum of its terms. Arrays are time-major, so each step
reads one contiguous block; the recursion runs step after step (it is
sequential by nature), every step vectorised over all problems and states.
"""

import numpy as np

__all__ = ["kbest_viterbi", "max_marginals"]


def max_marginals(initial, steps):
    """The score of the best sequence through each state at each step.

    Parameters
    ----------
    initial : ndarray of shape (n_problems, n_states)
        Log scores of the states at the first step (``-inf``: not a state).
    steps : ndarray of shape (n_steps - 1, n_problems, n_states, n_states)
        Log scores of the moves, the arrival state's own score included.

    Returns
    -------
    marginals : ndarray of shape (n_steps, n_problems, n_states)
        ``marginals[t, b, j]``: the best score of a sequence of problem ``b``
        that is in state ``j`` at step ``t`` (forward plus backward max-product).

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.tree import max_marginals
    >>> initial = np.log([[0.9, 0.1]])
    >>> steps = np.log(0.5 * np.array([[[[0.2, 0.8], [0.2, 0.8]]]]))
    >>> np.round(np.exp(max_marginals(initial, steps)[:, 0]), 3).tolist()
    [[0.36, 0.04], [0.09, 0.36]]
    """
    n_steps = len(steps) + 1
    forward = np.empty((n_steps,) + initial.shape)
    forward[0] = initial
    for t in range(1, n_steps):
        np.max(forward[t - 1][:, :, None] + steps[t - 1], axis=1, out=forward[t])
    backward = np.zeros_like(forward)
    for t in range(n_steps - 2, -1, -1):
        np.max(steps[t] + backward[t + 1][:, None, :], axis=2, out=backward[t])
    forward += backward
    return forward


def kbest_viterbi(initial, steps, n_paths):
    """The ``n_paths`` best state sequences of each trellis (list Viterbi).

    Parameters
    ----------
    initial : ndarray of shape (n_problems, n_states)
        Log scores of the states at the first step (``-inf``: not a state).
    steps : ndarray of shape (n_steps - 1, n_problems, n_states, n_states)
        Log scores of the moves, the arrival state's own score included.
    n_paths : int
        How many sequences to return per problem.

    Returns
    -------
    paths : ndarray of shape (n_problems, n_paths, n_steps)
        State sequences, best first; rows of -1 where a problem has fewer than
        ``n_paths`` sequences of finite score.
    scores : ndarray of shape (n_problems, n_paths)
        Their log scores, decreasing (``-inf`` for missing sequences). Ties go
        to lower state indices.

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.tree import kbest_viterbi
    >>> initial = np.log([[0.9, 0.1]])
    >>> steps = np.log(0.5 * np.array([[[[0.2, 0.8], [0.2, 0.8]]]]))
    >>> paths, scores = kbest_viterbi(initial, steps, 2)
    >>> paths[0].tolist(), np.round(np.exp(scores[0]), 3).tolist()
    ([[0, 1], [0, 0]], [0.36, 0.09])
    """
    n_problems, n_states = initial.shape
    n_steps = len(steps) + 1
    p = int(n_paths)
    delta = np.full((n_problems, n_states, p), -np.inf)
    delta[:, :, 0] = initial
    # back[t, b, j, r]: flat (state * p + rank) of the predecessor of rank r at j.
    back = np.zeros((n_steps, n_problems, n_states, p), dtype=np.intp)
    for t in range(1, n_steps):
        if p == 1:
            s = delta[:, :, None, 0] + steps[t - 1]
            best = s.argmax(axis=1)
            back[t, :, :, 0] = best
            delta = np.take_along_axis(s, best[:, None, :], axis=1).reshape(n_problems, n_states, 1)
            continue
        s = steps[t - 1].transpose(0, 2, 1)[:, :, :, None] + delta[:, None, :, :]
        s = s.reshape(n_problems, n_states, n_states * p)
        best = np.argsort(-s, axis=2, kind="stable")[:, :, :p]
        back[t] = best
        delta = np.take_along_axis(s, best, axis=2)
    final = delta.reshape(n_problems, n_states * p)
    order = np.argsort(-final, axis=1, kind="stable")[:, :p]
    scores = np.take_along_axis(final, order, axis=1)
    state, rank = np.divmod(order, p)
    paths = np.empty((n_problems, p, n_steps), dtype=np.intp)
    rows = np.arange(n_problems)[:, None]
    for t in range(n_steps - 1, -1, -1):
        paths[:, :, t] = state
        if t:
            state, rank = np.divmod(back[t, rows, state, rank], p)
    paths[~np.isfinite(scores)] = -1
    return paths, scores
