"""Max-product dynamic programming on batches of small trellises, in log space.

A trellis of ``n_steps`` steps and ``n_states`` states per step is given by the
log score of each state at the first step (``initial``) and, for every later
step ``t``, the log score of moving from state ``i`` at ``t - 1`` to state ``j``
at ``t`` *including* the score of ``j`` itself (``steps[t - 1, i, j]``). A
sequence's score is the sum of its terms.

Arrays are time-major with the problems on the *last* axis, so every operation
runs over contiguous rows of all problems at once (numpy reduces a short axis
many times faster when it is not the innermost one). The recursion runs step
after step, as it must.
"""

import numpy as np

__all__ = ["kbest_viterbi", "max_marginals"]


def max_marginals(initial, steps):
    """The score of the best sequence through each state at each step.

    Parameters
    ----------
    initial : ndarray of shape (n_states, n_problems)
        Log scores of the states at the first step (``-inf``: not a state).
    steps : ndarray of shape (n_steps - 1, n_states, n_states, n_problems)
        Log scores of the moves, the arrival state's own score included.

    Returns
    -------
    marginals : ndarray of shape (n_steps, n_states, n_problems)
        ``marginals[t, j, b]``: the best score of a sequence of problem ``b``
        that is in state ``j`` at step ``t`` (forward plus backward max-product).

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.tree import max_marginals
    >>> initial = np.log([[0.9], [0.1]])
    >>> steps = np.log(0.5 * np.array([[[[0.2], [0.8]], [[0.2], [0.8]]]]))
    >>> np.round(np.exp(max_marginals(initial, steps)[:, :, 0]), 3).tolist()
    [[0.36, 0.04], [0.09, 0.36]]
    """
    n_steps = len(steps) + 1
    forward = np.empty((n_steps,) + initial.shape)
    forward[0] = initial
    for t in range(1, n_steps):
        np.max(forward[t - 1][:, None, :] + steps[t - 1], axis=0, out=forward[t])
    backward = np.zeros_like(forward)
    for t in range(n_steps - 2, -1, -1):
        np.max(steps[t] + backward[t + 1][None, :, :], axis=1, out=backward[t])
    forward += backward
    return forward


def _top_ranks(scores, n_paths, n_lists):
    """The ``n_paths`` best entries along axis 0 of ``scores``, best first.

    ``scores`` has shape ``(n_ranks * n_lists, n_states, n_problems)``: entry
    ``r * n_lists + i`` is rank ``r`` of list ``i``, and each list decreases
    with its rank, so the ``r``-th best entry is among the first ``r + 1``
    ranks. Each pick is one ``argmax`` over those entries (the first maximum:
    ties go to the lower entry), which is then set to ``-inf``; numpy's sort
    along a short axis is many times slower. ``scores`` is overwritten.

    Returns
    -------
    order : ndarray of shape (n_paths, n_states, n_problems)
        Entry index of each pick.
    best : ndarray of shape (n_paths, n_states, n_problems)
        Its score.
    """
    n_entries, shape = len(scores), scores.shape[1:]
    flat = scores.reshape(n_entries, -1)
    cols = np.arange(flat.shape[1])
    order = np.empty((n_paths, flat.shape[1]), dtype=np.intp)
    best = np.empty((n_paths, flat.shape[1]))
    for r in range(n_paths):
        pick = flat[: min((r + 1) * n_lists, n_entries)].argmax(axis=0)
        order[r] = pick
        best[r] = flat[pick, cols]
        if r + 1 < n_paths:
            flat[pick, cols] = -np.inf
    return order.reshape((n_paths,) + shape), best.reshape((n_paths,) + shape)


def kbest_viterbi(initial, steps, n_paths):
    """The ``n_paths`` best state sequences of each trellis (list Viterbi).

    Parameters
    ----------
    initial : ndarray of shape (n_states, n_problems)
        Log scores of the states at the first step (``-inf``: not a state).
    steps : ndarray of shape (n_steps - 1, n_states, n_states, n_problems)
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
        to lower ranks, then lower state indices.

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.tree import kbest_viterbi
    >>> initial = np.log([[0.9], [0.1]])
    >>> steps = np.log(0.5 * np.array([[[[0.2], [0.8]], [[0.2], [0.8]]]]))
    >>> paths, scores = kbest_viterbi(initial, steps, 2)
    >>> paths[0].tolist(), np.round(np.exp(scores[0]), 3).tolist()
    ([[0, 1], [0, 0]], [0.36, 0.09])
    """
    n_states, n_problems = initial.shape
    n_steps = len(steps) + 1
    p = int(n_paths)
    # delta[r, j, b]: score of the rank-r sequence ending in state j (decreasing in r).
    delta = np.full((p, n_states, n_problems), -np.inf)
    delta[0] = initial
    # back[t, r, j, b]: its predecessor, as rank * n_states + state.
    back = np.zeros((n_steps, p, n_states, n_problems), dtype=np.intp)
    for t in range(1, n_steps):
        s = (delta[:, :, None, :] + steps[t - 1][None]).reshape(p * n_states, n_states, n_problems)
        back[t], delta = _top_ranks(s, p, n_states)
    order, scores = _top_ranks(delta.reshape(p * n_states, 1, n_problems), p, n_states)
    rank, state = np.divmod(order[:, 0].T, n_states)
    scores = scores[:, 0].T
    paths = np.empty((n_problems, p, n_steps), dtype=np.intp)
    cols = np.arange(n_problems)[:, None]
    for t in range(n_steps - 1, -1, -1):
        paths[:, :, t] = state
        if t:
            rank, state = np.divmod(back[t, rank, state, cols], n_states)
    paths[~np.isfinite(scores)] = -1
    return paths, scores
