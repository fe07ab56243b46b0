"""How EigenMovementPCA rebuilds movement from codes, and scores the rebuilt clips.

A mixin of :class:`~skmotion.decomposition.EigenMovementPCA` (the class stays in
``_eigenmovements``, where pickles look for it): back-projection of codes, each
segment re-timed to its real duration and put in place, and the reconstruction error.
"""

import numpy as np
from sklearn.utils.validation import check_is_fitted

from skmotion.decomposition._segment_vectors import (
    assemble_segments,
    check_segments,
    frame_counts,
    retime_segments,
    vectors_to_segments,
)
from skmotion.utils._clips import check_clips, to_container

__all__ = []


class _ReconstructionMixin:
    """Inverse transform, reconstruction and score of an EigenMovementPCA."""

    def _decode(self, codes):
        return codes @ self.components_ + self.mean_

    def inverse_transform(self, codes, segments=None, n_frames=None):
        """Movement from codes: time-normalised segments, or clips re-timed.

        Parameters
        ----------
        codes : list of ndarray of shape (n_segments_i, n_components_)
            Per clip, one code per segment (as from :meth:`transform`).
        segments : list of ndarray of int of shape (n_segments_i, 2), default=None
            Per clip, ``(start, stop)`` of each segment (as from :meth:`segment`).
            Without it each segment is returned on the normalised time scale.
        n_frames : int or sequence of int, default=None
            With ``segments``: the length of each rebuilt clip (by default the
            last segment's stop).

        Returns
        -------
        movement : list of ndarray
            Without ``segments``, per clip an array ``(n_segments_i, n_samples,
            n_channels)``; with them, per clip ``(n_frames_i, n_channels)``: each
            segment stretched to ``stop - start`` frames by a cubic spline and put
            in place, the mean of the two at a shared boundary frame, NaN in
            frames no segment covers.
        """
        check_is_fitted(self)
        codes = check_clips(codes, min_frames=0, input_name="codes")
        if codes.n_channels != self.n_components_:
            raise ValueError(
                f"codes have {codes.n_channels} columns, but this EigenMovementPCA keeps "
                f"n_components_={self.n_components_}."
            )
        normalised = [vectors_to_segments(self._decode(c), self.n_features_in_) for c in codes]
        if segments is None:
            if n_frames is not None:
                raise ValueError("n_frames needs segments: without them, time is normalised.")
            return normalised
        segments = check_segments(segments, [len(c) for c in codes])
        lengths = frame_counts(n_frames, segments)
        return [self._place(*item) for item in zip(normalised, segments, lengths)]

    def _place(self, normalised, segments, n_frames):
        pieces = retime_segments(normalised, segments[:, 1] - segments[:, 0])
        return assemble_segments(pieces, segments, n_frames, self.n_features_in_)

    def _reconstruct(self, clips):
        normalised = self._normalised(clips)
        segments = self._segment_all(normalised)
        rebuilt = []
        for clip, seg, vectors in zip(clips, segments, self._vectors_all(normalised, segments)):
            projected = vectors_to_segments(
                self._decode(self._encode(vectors)), self.n_features_in_
            )
            rebuilt.append(self._place(projected, seg, len(clip)))
        return rebuilt

    def reconstruct(self, X):
        """Segment, code and rebuild each clip from its eigenmovement codes.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_channels)
            Clips (or a 3-D array or a (clip, frame) DataFrame).

        Returns
        -------
        X_rebuilt : list of ndarray of shape (n_frames_i, n_channels)
            In the container kind of ``X``; frames outside every segment are NaN.
        """
        check_is_fitted(self)
        clips = check_clips(X, estimator=self)
        return to_container(self._reconstruct(clips), clips.container)

    def score(self, X, y=None):
        """Negative RMS reconstruction error, in the input's units.

        The error is taken over every channel of every frame that some segment
        covers (see :meth:`reconstruct`), at the clips' real timing.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_channels)
            Clips (or a 3-D array or a (clip, frame) DataFrame).
        y : None
            Ignored.

        Returns
        -------
        score : float
            ``-sqrt(mean((x - x_rebuilt) ** 2))``; higher is better.
        """
        check_is_fitted(self)
        clips = check_clips(X, estimator=self)
        diff = np.concatenate([c - r for c, r in zip(clips, self._reconstruct(clips))])
        covered = ~np.isnan(diff)
        if not covered.any():
            raise ValueError(
                f"No segments were found in the {len(clips)} clips of X: nothing to score."
            )
        scaled = diff[covered] / self._scale  # no square underflows or overflows
        return -float(np.sqrt(np.mean(scaled**2))) * self._scale
