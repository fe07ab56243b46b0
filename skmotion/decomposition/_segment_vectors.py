"""Segments as fixed-length vectors, and back to clips of real duration.

A segment of any length becomes ``n_samples`` samples per channel (a cubic
spline through its frames), laid out channel after channel in one vector, as in
the eigenmovement paper: ``[ch0 s0..s99, ch1 s0..s99, ...]``. The way back
stretches the samples to the segment's real number of frames with a cubic
spline and puts the segments in place in a clip. Segments of equal length are
resampled together, as the columns of one array, by
:func:`skmotion.preprocessing.resample_clip`.
"""

import numpy as np
import pandas as pd

from skmotion.preprocessing._resample import resample_clip

__all__ = [
    "assemble_segments",
    "check_segments",
    "frame_counts",
    "retime_segments",
    "segment_vectors",
    "vectors_to_segments",
]


def _by_length(lengths):
    """Groups of row indices whose segments have the same length."""
    for length in np.unique(lengths):
        yield int(length), np.flatnonzero(lengths == length)


def _stretch(pieces, n_out):
    """Resample ``(n_in, n_pieces, n_channels)`` to ``n_out`` frames in one spline fit."""
    n_in = pieces.shape[0]
    flat = pieces.reshape(n_in, -1)
    out = resample_clip(flat, np.linspace(0.0, n_in - 1.0, n_out), kind="cubic")
    return out.reshape(n_out, *pieces.shape[1:])


def segment_vectors(clips, segments, n_samples):
    """The segments of all clips, each resampled and flattened channel-major.

    Parameters
    ----------
    clips : list of ndarray of shape (n_frames_i, n_channels)
        The clips.
    segments : list of ndarray of int of shape (n_segments_i, 2)
        Per clip, ``(start, stop)`` of each segment.
    n_samples : int
        Samples per channel.

    Returns
    -------
    vectors : list of ndarray of shape (n_segments_i, n_channels * n_samples)
        Per clip, one row per segment.
    """
    n_channels = clips[0].shape[1]
    owner = np.repeat(np.arange(len(clips)), [len(s) for s in segments])
    pairs = np.concatenate([s.reshape(-1, 2) for s in segments]).astype(np.intp)
    out = np.empty((len(pairs), n_channels * n_samples))
    for _length, rows in _by_length(pairs[:, 1] - pairs[:, 0]):
        pieces = np.stack([clips[owner[r]][pairs[r, 0] : pairs[r, 1]] for r in rows], axis=1)
        samples = _stretch(
            pieces.astype(float, copy=False), n_samples
        )  # (n_samples, n_rows, n_channels)
        out[rows] = samples.transpose(1, 2, 0).reshape(len(rows), -1)
    offsets = np.cumsum([0] + [len(s) for s in segments])
    return [out[a:b] for a, b in zip(offsets[:-1], offsets[1:])]


def vectors_to_segments(vectors, n_channels):
    """Vectors back to time-normalised segments ``(n_segments, n_samples, n_channels)``."""
    n_segments, n_features = vectors.shape
    return vectors.reshape(n_segments, n_channels, n_features // n_channels).transpose(0, 2, 1)


def retime_segments(normalised, lengths):
    """Stretch each time-normalised segment to its real number of frames (cubic spline).

    Parameters
    ----------
    normalised : ndarray of shape (n_segments, n_samples, n_channels)
        Segments on the normalised time scale.
    lengths : ndarray of int of shape (n_segments,)
        Frames of each segment, ``stop - start``.

    Returns
    -------
    pieces : list of ndarray of shape (lengths[i], n_channels)
    """
    pieces = [None] * len(normalised)
    for length, rows in _by_length(np.asarray(lengths)):
        stretched = _stretch(normalised[rows].transpose(1, 0, 2), length)
        for k, row in enumerate(rows):
            pieces[row] = stretched[:, k]
    return pieces


def assemble_segments(pieces, segments, n_frames, n_channels):
    """Put re-timed segments in place in a clip of ``n_frames`` frames.

    Frames shared by two segments (their common boundary) get the mean of the
    two; frames in no segment are NaN (missing), never guessed.

    Parameters
    ----------
    pieces : sequence of ndarray of shape (stop - start, n_channels)
        Each segment's frames.
    segments : ndarray of int of shape (n_segments, 2)
        ``(start, stop)`` of each segment.
    n_frames : int
        Length of the clip.
    n_channels : int
        Channels of the clip.

    Returns
    -------
    clip : ndarray of shape (n_frames, n_channels)
    """
    total = np.zeros((n_frames, n_channels))
    count = np.zeros(n_frames)
    for piece, (start, stop) in zip(pieces, segments):
        total[start:stop] += piece
        count[start:stop] += 1
    covered = count > 0
    total[covered] /= count[covered, None]
    total[~covered] = np.nan
    return total


def check_segments(segments, n_segments):
    """Validate per-clip ``(start, stop)`` arrays against the codes' segment counts.

    Parameters
    ----------
    segments : sequence of array-like of int of shape (n_segments_i, 2)
        Per clip, ``(start, stop)`` of each segment.
    n_segments : sequence of int
        Per clip, the number of code rows.

    Returns
    -------
    segments : list of ndarray of int of shape (n_segments_i, 2)
    """
    if not isinstance(segments, (list, tuple)) or len(segments) != len(n_segments):
        got = len(segments) if isinstance(segments, (list, tuple)) else type(segments).__name__
        raise ValueError(
            f"segments must be a list with one (n_segments_i, 2) array per clip of codes "
            f"({len(n_segments)} clips); got {got}."
        )
    checked = []
    for i, (pairs, expected) in enumerate(zip(segments, n_segments)):
        pairs = np.asarray(pairs)
        if pairs.size == 0:
            pairs = pairs.reshape(0, 2).astype(np.intp)
        if pairs.ndim != 2 or pairs.shape[1] != 2 or pairs.dtype.kind not in "iu":
            raise ValueError(
                f"segments: clip {i} must be an integer array of shape (n_segments, 2); "
                f"got dtype {pairs.dtype} and shape {pairs.shape}."
            )
        if len(pairs) != expected:
            raise ValueError(
                f"segments: clip {i} has {len(pairs)} segments but {expected} rows of codes."
            )
        bad = np.flatnonzero((pairs[:, 0] < 0) | (pairs[:, 1] <= pairs[:, 0]))
        if bad.size:
            raise ValueError(
                f"segments: clip {i}, segment {bad[0]} is {pairs[bad[0]].tolist()}; "
                "a segment is (start, stop) with 0 <= start < stop."
            )
        checked.append(pairs.astype(np.intp))
    return checked


def frame_counts(n_frames, segments):
    """Clip lengths for reconstruction: given (int or one per clip) or the last stop."""
    ends = [int(s[:, 1].max()) if len(s) else 0 for s in segments]
    if n_frames is None:
        return ends
    counts = np.asarray(n_frames)
    if counts.ndim == 0:
        counts = np.full(len(segments), counts)
    if counts.shape != (len(segments),) or counts.dtype.kind not in "iu":
        raise ValueError(
            f"n_frames must be an int or one int per clip ({len(segments)} clips); "
            f"got {n_frames!r}."
        )
    short = np.flatnonzero(counts < ends)
    if short.size:
        i = short[0]
        raise ValueError(
            f"n_frames: clip {i} is given {counts[i]} frames but its segments reach "
            f"frame {ends[i]}."
        )
    return [int(n) for n in counts]


class SegmentCodes(list):
    """Codes of ``EigenMovementPCA.transform``: an ``(n_segments_i, n_components)`` array per clip.

    A list that refuses to become one table: clips differ in their number of segments,
    so an estimator that needs one row per clip (``LogisticRegression``, say) cannot
    take it directly. Turning it into an array raises a TypeError that says what to
    put in between.
    """

    def __array__(self, dtype=None, copy=None):
        raise TypeError(
            "EigenMovementPCA returns one array of segment codes per clip (clips differ in "
            "their number of segments), not a table with one row per clip. Put a step that "
            "makes one row per clip between it and a table estimator: "
            "KMeansPrimitiveController (each clip's usage histogram of primitives), or "
            "ResampleClips(n_frames=k) then FlattenClips() (each code sequence resampled to k "
            "steps); "
            "np.concatenate(codes) gives one row per segment."
        )


def codes_frame(codes, container, columns):
    """Per-clip code arrays as one DataFrame indexed by (clip, segment).

    Every clip must have a segment: a clip without rows would vanish from the frame.
    """
    counts = np.array([len(c) for c in codes])
    if (counts == 0).any():
        k = int(np.flatnonzero(counts == 0)[0])
        raise ValueError(
            f"X: clip {k} has no segments, and a (clip, segment) DataFrame cannot hold a "
            "clip without rows; use the default output (a list) to keep every clip."
        )
    labels = container.clip_labels
    labels = np.arange(len(codes)) if labels is None else np.asarray(labels, dtype=object)
    names = container.index_names
    index = pd.MultiIndex.from_arrays(
        [np.repeat(labels, counts), np.concatenate([np.arange(n) for n in counts])],
        names=[names[0] if names else "clip", "segment"],
    )
    return pd.DataFrame(np.concatenate(codes), index=index, columns=columns)


def check_magnitude(clips, limit, owner):
    """The largest magnitude of the clips; a ValueError naming the clip beyond ``limit``."""
    peaks = np.array([np.max(np.abs(c)) if c.size else 0.0 for c in clips])
    too_big = np.flatnonzero(peaks > limit)
    if len(too_big):
        k = int(too_big[0])
        raise ValueError(
            f"X: clip {k} reaches {peaks[k]:.3g} in magnitude; {owner}'s variances (squared "
            f"input units) exceed float64's range beyond {limit:g}. Rescale the clips "
            "(degrees, radians, metres)."
        )
    return float(peaks.max(initial=0.0))
