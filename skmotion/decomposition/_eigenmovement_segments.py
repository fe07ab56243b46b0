"""How EigenMovementPCA cuts clips into segments and turns segments into vectors.

A mixin of :class:`~skmotion.decomposition.EigenMovementPCA` (the class stays in
``_eigenmovements``, where pickles look for it): the exact power-of-two scaling,
the segmentation rule applied to each clip, and the resampled segment vectors.
"""

import numpy as np
from sklearn.utils.validation import check_is_fitted

from skmotion.decomposition._segment_vectors import check_magnitude, segment_vectors
from skmotion.preprocessing._filter import filter_min_frames
from skmotion.preprocessing._segment import segment_clip
from skmotion.utils._clips import check_clips
from skmotion.utils._parallel import parallel_map

__all__ = []

# Inputs up to this magnitude are handled exactly as at unit scale (they are divided by a
# power of two inside); beyond it the variances, in squared input units, overflow float64.
_MAX_MAGNITUDE = 1e150


class _SegmentingMixin:
    """Scaling, segmenting and resampling clips (fit, transform and reconstruction share it)."""

    def _min_frames(self):
        if self.segmentation == "none" or self.filter_order is None:
            return 1
        return filter_min_frames(self.filter_order, self.filter_cutoff)

    def _segments_of(self, clip):
        """Segments of a clip already divided by ``self._scale`` (absolute thresholds too)."""
        if self.segmentation == "none":
            return np.array([[0, len(clip)]], dtype=np.intp)
        scale = self._scale
        threshold = self.energy_threshold
        return segment_clip(
            clip,
            rule=self.segmentation,
            frame_rate=self.frame_rate,
            filter_order=self.filter_order,
            filter_cutoff=self.filter_cutoff,
            energy_threshold=None if threshold is None else threshold / scale**2,
            energy_ratio=self.energy_ratio,
            zvc_window=self.zvc_window,
            zvc_min_channels=self.zvc_min_channels,
            min_movement=self.min_movement / scale,
        )

    def _normalised(self, clips, reset=False):
        """The clips divided by a power of two (exact), so that no square overflows.

        ``reset`` chooses the power from the training clips' largest magnitude.
        """
        peak = check_magnitude(clips, _MAX_MAGNITUDE, "EigenMovementPCA")
        if reset:
            self._scale = float(2.0 ** np.floor(np.log2(peak))) if peak > 0 else 1.0
        return [c / self._scale for c in clips]

    def _segment_all(self, clips):
        return parallel_map(self._segments_of, clips, n_jobs=self.n_jobs)

    def _vectors_all(self, clips, segments):
        return segment_vectors(clips, segments, self.n_samples)

    def segment(self, X):
        """The segments of each clip, as found by the segmentation rule.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_channels)
            Clips (or a 3-D array or a (clip, frame) DataFrame).

        Returns
        -------
        segments : list of ndarray of int of shape (n_segments_i, 2)
            Per clip, ``(start, stop)`` of each segment (``clip[start:stop]``),
            in the order of the rows of :meth:`transform`.
        """
        check_is_fitted(self)
        clips = check_clips(X, estimator=self)
        return self._segment_all(self._normalised(clips))

    def segment_vectors(self, X):
        """The segments of each clip, resampled and flattened (what PCA sees).

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_channels)
            Clips (or a 3-D array or a (clip, frame) DataFrame).

        Returns
        -------
        vectors : list of ndarray of shape (n_segments_i, n_channels * n_samples)
            Per clip, one row per segment, channel after channel.
        """
        check_is_fitted(self)
        normalised = self._normalised(check_clips(X, estimator=self))
        vectors = self._vectors_all(normalised, self._segment_all(normalised))
        return [v * self._scale for v in vectors]
