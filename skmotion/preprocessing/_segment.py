"""Cutting a clip into movement segments: zero-velocity crossings and energy.

Both rules return a clip's segments as ``(start, stop)`` frame pairs, in the
slice convention (``clip[start:stop]``). A segment runs from one boundary frame
to the next one, both included, so consecutive segments of one stroke share
their boundary frame.
"""

from numbers import Real

import numpy as np
from scipy.signal import find_peaks

from skmotion.preprocessing._filter import lowpass_filter
from skmotion.utils._sklearn_compat import Interval, validate_params

__all__ = [
    "SEGMENTATION_RULES",
    "energy_segments",
    "movement_energy",
    "segment_clip",
    "zvc_segments",
    "zero_velocity_crossings",
]

#: The segmentation rules, by name.
SEGMENTATION_RULES = ("energy", "zvc")

# A frame rate of zero, a negative or NaN one, or a string would give silently
# wrong velocities; inside an estimator's fit (already validated) this is skipped.
_POSITIVE = Interval(Real, 0, None, closed="neither")


def _velocity(clip, frame_rate):
    if len(clip) < 2:
        return np.zeros_like(clip, dtype=float)
    return np.gradient(np.asarray(clip, dtype=float), axis=0) * frame_rate


@validate_params({"frame_rate": [_POSITIVE]}, prefer_skip_nested_validation=True)
def movement_energy(clip, *, frame_rate=1.0):
    """The sum of squared channel velocities, ``z(t) = sum_j (dtheta_j/dt)^2``.

    Velocities are central differences (one-sided at the ends) times the frame
    rate, so ``z`` is in (units per second) squared.

    Parameters
    ----------
    clip : ndarray of shape (n_frames, n_channels)
        The clip, time first.
    frame_rate : float, default=1.0
        Frames per second; ``1.0`` gives units per frame.

    Returns
    -------
    z : ndarray of shape (n_frames,)

    Raises
    ------
    ValueError
        For a ``frame_rate`` that is not a positive, finite number of Hz
        (sklearn's ``InvalidParameterError``).

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.preprocessing import movement_energy
    >>> clip = np.c_[np.arange(4.0), 2 * np.arange(4.0)]
    >>> movement_energy(clip, frame_rate=10).tolist()
    [500.0, 500.0, 500.0, 500.0]
    """
    v = _velocity(clip, frame_rate)
    return np.einsum("ij,ij->i", v, v)


def zero_velocity_crossings(clip, *, min_movement=0.0):
    """Frames where a channel's velocity crosses zero: its turning points.

    A channel's velocity crosses zero where the channel turns back, at a local
    maximum or minimum (the middle of a flat top). Noise adds tiny turns, so a
    turning point counts only when its prominence (how far the channel moves
    away from it before turning back past it, ``scipy.signal.find_peaks``)
    exceeds ``min_movement``. A channel that stops and goes on in the same
    direction has no crossing there; turns at the clip's ends are not seen.

    Parameters
    ----------
    clip : ndarray of shape (n_frames, n_channels)
        The clip, time first.
    min_movement : float, default=0.0
        Prominence a turning point must exceed, in the clip's units.

    Returns
    -------
    frames : ndarray of int of shape (n_crossings,)
        Frame of each crossing, in increasing order.
    channels : ndarray of int of shape (n_crossings,)
        Channel of each crossing.

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.preprocessing import zero_velocity_crossings
    >>> t = np.linspace(0, 2 * np.pi, 41)
    >>> frames, channels = zero_velocity_crossings(np.c_[np.sin(t), np.cos(t)])
    >>> frames.tolist(), channels.tolist()
    ([10, 20, 30], [0, 1, 0])
    """
    clip = np.asarray(clip, dtype=float)
    frames, channels = [], []
    for j in range(clip.shape[1]):
        for sign in (1.0, -1.0):
            peaks, props = find_peaks(sign * clip[:, j], prominence=(None, None))
            keep = peaks[props["prominences"] > min_movement]
            frames.append(keep)
            channels.append(np.full(len(keep), j))
    frames, channels = np.concatenate(frames), np.concatenate(channels)
    order = np.lexsort((channels, frames))
    return frames[order].astype(np.intp), channels[order].astype(np.intp)


def _keep_moving(clip, segments, min_movement):
    """Segments of at least two frames whose largest channel range exceeds the threshold."""
    segments = segments[segments[:, 1] - segments[:, 0] >= 2]
    if len(segments) == 0:
        return segments
    ranges = np.array([np.ptp(clip[a:b], axis=0).max() for a, b in segments])
    return segments[ranges > min_movement]


def _as_segments(pairs):
    return np.asarray(pairs, dtype=np.intp).reshape(-1, 2)


def _group_starts(frames, width):
    """Greedy groups of sorted frames: a group spans less than ``width`` frames."""
    following = np.searchsorted(frames, frames + width, side="left")
    starts, i = [], 0
    while i < len(frames):  # one step per group, jumping over its members
        starts.append(i)
        i = following[i]
    return np.asarray(starts, dtype=np.intp)


@validate_params({"frame_rate": [_POSITIVE]}, prefer_skip_nested_validation=True)
def zvc_segments(clip, *, frame_rate, window=0.3, min_channels=2, min_movement=0.0):
    """Segments between zero-velocity crossings shared by several channels (SEG-1).

    A channel's zero-velocity crossings are its turning points whose prominence
    exceeds ``min_movement`` (see :func:`zero_velocity_crossings`). A boundary
    is where at least ``min_channels`` channels cross less than ``window``
    seconds apart: every crossing with such company is a candidate; candidates
    are grouped in time order, a group spanning less than ``window``, and each
    group's boundary is its mean frame (rounded). A segment runs from one
    boundary to the next and is kept when its movement (the largest
    peak-to-peak range of a channel within it) exceeds ``min_movement``. What
    lies before the first boundary or after the last is not a segment, so the
    rule need not cover the whole clip (the paper's "incomplete" SEG-1).

    Parameters
    ----------
    clip : ndarray of shape (n_frames, n_channels)
        The clip, time first; filter it first (see :func:`lowpass_filter`),
        since noise adds crossings.
    frame_rate : float
        Frames per second.
    window : float, default=0.3
        Seconds within which crossings of different channels coincide.
    min_channels : int, default=2
        Channels that must cross together to make a boundary.
    min_movement : float, default=0.0
        Prominence a turning point, and movement a segment, must exceed, in
        the clip's units.

    Returns
    -------
    segments : ndarray of int of shape (n_segments, 2)
        ``(start, stop)`` of each segment; ``clip[start:stop]`` holds it.

    Raises
    ------
    ValueError
        For a ``frame_rate`` that is not a positive, finite number of Hz
        (sklearn's ``InvalidParameterError``).

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.preprocessing import zvc_segments
    >>> t = np.arange(150) / 30  # both channels reverse every second
    >>> clip = np.c_[np.cos(np.pi * t), 2 * np.cos(np.pi * t)]
    >>> zvc_segments(clip, frame_rate=30).tolist()
    [[30, 61], [60, 91], [90, 121]]
    """
    frames, channels = zero_velocity_crossings(clip, min_movement=min_movement)
    width = window * frame_rate
    # Distinct channels with a crossing less than a window away from each crossing.
    company = np.zeros(len(frames), dtype=np.intp)
    for j in np.unique(channels):
        own = frames[channels == j]
        company += (
            np.searchsorted(own, frames + width, side="left")
            - np.searchsorted(own, frames - width, side="right")
        ) > 0
    candidates = frames[company >= min_channels]
    if len(candidates) < 2:
        return _as_segments([])
    starts = _group_starts(candidates, width)
    sums = np.add.reduceat(candidates.astype(float), starts)
    counts = np.diff(np.r_[starts, len(candidates)])
    boundaries = np.unique(np.rint(sums / counts).astype(np.intp))
    segments = np.c_[boundaries[:-1], boundaries[1:] + 1]
    return _keep_moving(clip, _as_segments(segments), min_movement)


@validate_params({"frame_rate": [_POSITIVE, None]}, prefer_skip_nested_validation=True)
def energy_segments(clip, *, threshold=None, ratio=0.1, frame_rate=None, min_movement=0.0):
    """Segments of high movement energy between low-energy boundaries (SEG-2).

    With ``z(t)`` the :func:`movement_energy`, frames where ``z < threshold``
    are boundary frames. Each run of frames with ``z >= threshold`` is a
    segment, widened on each side down the falling energy to its local minimum
    (so a stroke runs from rest to rest, and two strokes meeting at one dip
    share its frame). A long stretch of low energy (a held pose) lies between
    segments and belongs to none. Segments whose movement (the largest
    peak-to-peak range of a channel) does not exceed ``min_movement`` are
    dropped.

    Parameters
    ----------
    clip : ndarray of shape (n_frames, n_channels)
        The clip, time first.
    threshold : float, default=None
        The energy threshold in (units per second) squared; needs
        ``frame_rate``. By default it is ``ratio`` times the clip's mean energy,
        which does not depend on the frame rate or on the units.
    ratio : float, default=0.1
        The automatic threshold as a fraction of the mean energy.
    frame_rate : float, default=None
        Frames per second; needed only with an explicit ``threshold``.
    min_movement : float, default=0.0
        Movement a segment must exceed, in the clip's units.

    Returns
    -------
    segments : ndarray of int of shape (n_segments, 2)
        ``(start, stop)`` of each segment; ``clip[start:stop]`` holds it.

    Raises
    ------
    ValueError
        For a ``frame_rate`` that is not a positive, finite number of Hz
        (sklearn's ``InvalidParameterError``).

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.preprocessing import energy_segments
    >>> t = np.arange(90) / 30
    >>> clip = np.c_[np.cos(np.pi * t), 2 * np.cos(np.pi * t)]
    >>> energy_segments(clip).tolist()
    [[0, 31], [30, 61], [60, 90]]
    """
    if threshold is not None and frame_rate is None:
        raise ValueError(
            "An explicit energy threshold is in (units per second) squared and needs "
            "frame_rate; give frame_rate or leave threshold=None for the automatic rule."
        )
    z = movement_energy(clip, frame_rate=1.0 if threshold is None else frame_rate)
    n = len(z)
    if n < 2:
        return _as_segments([])
    threshold = ratio * z.mean() if threshold is None else threshold
    high = z >= threshold
    if not high.any():
        return _as_segments([])
    edges = np.diff(np.r_[0, high.astype(np.int8), 0])
    run_starts = np.flatnonzero(edges == 1)
    run_ends = np.flatnonzero(edges == -1) - 1
    low = ~high
    # Walk outward while the energy keeps falling within the low frames.
    falls_right = (z[1:] < z[:-1]) & low[1:]
    right_stops = np.r_[np.flatnonzero(~falls_right), n - 1]
    stop = right_stops[np.searchsorted(right_stops, run_ends)]
    falls_left = (z[:-1] < z[1:]) & low[:-1]
    left_stops = np.r_[0, np.flatnonzero(~falls_left) + 1]
    start = left_stops[np.searchsorted(left_stops, run_starts, side="right") - 1]
    return _keep_moving(clip, _as_segments(np.c_[start, stop + 1]), min_movement)


@validate_params({"frame_rate": [_POSITIVE, None]}, prefer_skip_nested_validation=True)
def segment_clip(
    clip,
    *,
    rule="energy",
    frame_rate=None,
    filter_order=10,
    filter_cutoff=0.25,
    energy_threshold=None,
    energy_ratio=0.1,
    zvc_window=0.3,
    zvc_min_channels=2,
    min_movement=0.0,
):
    """Low-pass filter a clip, then cut it by one of the segmentation rules.

    The filter only steers the boundaries: the segments are frame ranges, to be
    cut from the clip itself.

    Parameters
    ----------
    clip : ndarray of shape (n_frames, n_channels)
        The clip, time first.
    rule : {"energy", "zvc"}, default="energy"
        :func:`energy_segments` (SEG-2) or :func:`zvc_segments` (SEG-1).
    frame_rate : float, default=None
        Frames per second; needed by ``"zvc"`` and by an explicit
        ``energy_threshold``.
    filter_order : int or None, default=10
        Order of the zero-phase Butterworth low-pass (:func:`lowpass_filter`);
        ``None`` for no filter.
    filter_cutoff : float, default=0.25
        Its cutoff, as a fraction of the Nyquist frequency.
    energy_threshold, energy_ratio : float
        ``threshold`` and ``ratio`` of :func:`energy_segments`.
    zvc_window, zvc_min_channels : float, int
        ``window`` and ``min_channels`` of :func:`zvc_segments`.
    min_movement : float, default=0.0
        Movement a segment must exceed, in the clip's units.

    Returns
    -------
    segments : ndarray of int of shape (n_segments, 2)
        ``(start, stop)`` of each segment.

    Raises
    ------
    ValueError
        For a ``frame_rate`` that is not a positive, finite number of Hz
        (sklearn's ``InvalidParameterError``).

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.preprocessing import segment_clip
    >>> t = np.arange(150) / 30
    >>> clip = np.c_[np.cos(np.pi * t), 2 * np.cos(np.pi * t)]
    >>> segment_clip(clip, rule="zvc", frame_rate=30, filter_order=4).tolist()
    [[30, 61], [60, 91], [90, 121]]
    """
    if rule not in SEGMENTATION_RULES:
        raise ValueError(f"rule must be one of {list(SEGMENTATION_RULES)}; got {rule!r}.")
    if frame_rate is None and (rule == "zvc" or energy_threshold is not None):
        what = "segmentation='zvc'" if rule == "zvc" else "an explicit energy_threshold"
        raise ValueError(
            f"{what} needs frame_rate (frames per second); loaders report it, e.g. "
            "make_motions(...).frame_rate."
        )
    signal = (
        clip
        if filter_order is None
        else lowpass_filter(clip, order=filter_order, cutoff=filter_cutoff)
    )
    if rule == "zvc":
        return zvc_segments(
            signal,
            frame_rate=frame_rate,
            window=zvc_window,
            min_channels=zvc_min_channels,
            min_movement=min_movement,
        )
    return energy_segments(
        signal,
        threshold=energy_threshold,
        ratio=energy_ratio,
        frame_rate=frame_rate,
        min_movement=min_movement,
    )
