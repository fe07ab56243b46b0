"""Values too large for the motion tree's arithmetic: a ValueError naming clip and channel.

Two limits, each the point past which an answer would be NaN, infinite or garbage
rather than a number:

- :func:`overflow_limit`: fitting and encoding sum squares of the values over the
  frames (variances, covariances, Fisher-vector terms, moments); past
  ``sqrt(max float / (4 n_frames n_channels))`` those sums overflow float64.
- :data:`SCORE_LIMIT`: a generation log-probability evaluates each Gaussian as an
  expanded quadratic form, whose rounding error grows as the square of the
  standardised deviation; past 1e5 training spreads from the training mean the
  error of a score reaches hundredths of a nat (at 4e6, whole nats; at 4e7 the
  scores of every class are rounding noise). ``predict_proba`` and
  ``novelty_score`` keep their own documented answers for such clips (uniform
  rows, ``-inf``); ``score_samples``, whose values are the answer, refuses them.
"""

import math
import sys

import numpy as np

from skmotion.tree._encoding._readout_passes import extremes_within

__all__ = ["SCORE_LIMIT", "check_magnitude", "check_stacked_magnitude", "overflow_limit"]

#: Standardised deviations past which a generation log-probability is not reliable.
SCORE_LIMIT = 1e5


def overflow_limit(clips):
    """The largest absolute value whose squares, summed over every frame and channel
    of ``clips`` (and after centring, which can double a value), stay finite."""
    n_values = sum(clip.size for clip in clips)
    # math's correctly rounded sqrt of the largest double: NumPy's value, without its calls
    return math.sqrt(sys.float_info.max / (4.0 * max(n_values, 1)))


def check_magnitude(clips, estimator, *, center=0.0, scale=1.0, limit=None, why=None):
    """Raise a ValueError naming the first clip and channel whose ``|(x - center) / scale|``
    passes ``limit`` (default :func:`overflow_limit`).

    Parameters
    ----------
    clips : list of ndarray of shape (n_frames_i, n_channels)
        Finite clips (``check_clips`` has refused NaN and infinity).
    estimator : estimator
        Named in the message.
    center, scale : float or ndarray of shape (n_channels,)
        Given, the limit is in training spreads from the training mean.
    limit : float, default=None
    why : str, default=None
        What passing the limit breaks, for the message.

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.tree._magnitude import check_magnitude
    >>> from skmotion.tree import MotionTreeEncoder
    >>> clips = [np.zeros((5, 2)), np.array([[0.0, 1e300]] * 5)]
    >>> check_magnitude(clips, MotionTreeEncoder())
    Traceback (most recent call last):
    ...
    ValueError: X: clip 1, channel 1 holds 1e+300; MotionTreeEncoder sums squares of the values, which overflow float64 past 1.5e+153: rescale the data (check its units).
    """  # noqa: E501
    limit = overflow_limit(clips) if limit is None else limit
    for i, clip in enumerate(clips):
        if not clip.size:
            continue
        # |x - c| / s is largest at a channel's maximum or minimum (the map is monotonic,
        # also in rounding): two reductions, no frame-sized temporaries on every call
        center_i = np.broadcast_to(center, clip.shape[1:])
        scale_i = np.broadcast_to(scale, clip.shape[1:])
        with np.errstate(over="ignore", invalid="ignore"):
            worst = _reach(clip.max(axis=0), clip.min(axis=0), center_i, scale_i)
        bad = np.flatnonzero(~(worst <= limit))
        if bad.size:
            _refuse(clip, i, int(bad[0]), center_i, scale_i, estimator, limit, why)


def check_stacked_magnitude(frames, offsets, estimator, checks):
    """:func:`check_magnitude` of stacked clips under several ``(center, scale, why)``
    checks in turn, from one maximum and minimum of each clip's channels.

    The same limit (:func:`overflow_limit` of the frames), the same first clip and
    channel named, the same message as :func:`check_magnitude` called once per check;
    the extremes are two reductions over all clips (``reduceat``), not two per clip and
    check, so a call costs about as much for one clip as for a batch's share of one.

    Parameters
    ----------
    frames : ndarray of shape (n_frames, n_channels)
        Finite stacked clips (``stack_clips``).
    offsets : ndarray of shape (n_clips + 1,)
        Clip ``i`` is ``frames[offsets[i]:offsets[i + 1]]``.
    estimator : estimator
        Named in the message.
    checks : sequence of (center, scale, why)
        As the arguments of :func:`check_magnitude` (``why`` None for its default).

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.tree._magnitude import check_stacked_magnitude
    >>> from skmotion.tree import MotionTreeEncoder
    >>> frames, offsets = np.array([[0.0, 1.0], [0.0, 1e300]]), np.array([0, 1, 2])
    >>> check_stacked_magnitude(frames, offsets, MotionTreeEncoder(), [(0.0, 1.0, None)])
    Traceback (most recent call last):
    ...
    ValueError: X: clip 1, channel 1 holds 1e+300; MotionTreeEncoder sums squares of the values, which overflow float64 past 3.35e+153: rescale the data (check its units).
    """  # noqa: E501
    if not frames.size:
        return
    limit = overflow_limit([frames])
    # all frames' extremes first, every check from one compiled pass (the arithmetic of
    # _reach): when they pass, every clip's do (|x - c| / s grows with |x - c|, also in
    # rounding); only else each clip's
    centers, scales = np.empty((2, len(checks), frames.shape[1]))
    for j, (center, scale, _) in enumerate(checks):
        centers[j], scales[j] = center, scale  # broadcast (np.broadcast_to costs 10 us)
    if extremes_within(np.ascontiguousarray(frames, dtype=np.float64), centers, scales, limit):
        return
    clip = np.flatnonzero(offsets[1:] > offsets[:-1])  # reduceat needs non-empty clips
    starts = offsets[clip]
    high, low = np.maximum.reduceat(frames, starts), np.minimum.reduceat(frames, starts)
    for center, scale, why in checks:
        with np.errstate(over="ignore", invalid="ignore"):
            worst = _reach(high, low, center, scale)
        bad = np.argwhere(~(worst <= limit))  # row-major: the first clip, then its channel
        if len(bad):
            row, j = int(bad[0, 0]), int(bad[0, 1])
            i = int(clip[row])
            rows = frames[offsets[i] : offsets[i + 1]]
            center_i = np.broadcast_to(center, rows.shape[1:])
            scale_i = np.broadcast_to(scale, rows.shape[1:])
            _refuse(rows, i, j, center_i, scale_i, estimator, limit, why)


def _reach(high, low, center, scale):
    """``|x - center| / scale`` at its largest over values between ``low`` and ``high``."""
    return np.maximum(np.abs(high - center), np.abs(low - center)) / scale


def _refuse(clip, i, j, center, scale, estimator, limit, why):
    """The ValueError naming clip ``i``'s channel ``j`` and its farthest value."""
    why = why or f"sums squares of the values, which overflow float64 past {limit:.3g}"
    with np.errstate(over="ignore", invalid="ignore"):
        reach = np.abs((clip[:, j] - center[j]) / scale[j])
    value = clip[np.argmax(reach), j]
    raise ValueError(
        f"X: clip {i}, channel {j} holds {value:.3g}; {type(estimator).__name__} "
        f"{why}: rescale the data (check its units)."
    )
