"""Flattening equal-length clips into one row each, for any sklearn model."""

import numpy as np
from sklearn.base import BaseEstimator
from sklearn.utils.validation import check_is_fitted

from skmotion.base import ClipFeatureMixin, MotionTags
from skmotion.utils._clips import check_clips
from skmotion.utils._features import channel_names_in
from skmotion.utils._sklearn_compat import _fit_context

__all__ = ["FlattenClips"]


class FlattenClips(ClipFeatureMixin, BaseEstimator):
    """Turn equal-length clips into rows ``(n_clips, n_frames * n_channels)``.

    Frames come one after another in each row (frame-major). All clips, at fit
    and after, must have the length seen in fit; put
    :class:`ResampleClips` first to make them so.

    Attributes
    ----------
    n_features_in_ : int
        Number of channels seen in fit.
    feature_names_in_ : ndarray of str
        Channel names seen in fit, when given as DataFrame columns.
    n_frames_ : int
        The clip length seen in fit.

    See Also
    --------
    ResampleClips : make clips equal length.

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.preprocessing import FlattenClips
    >>> FlattenClips().fit_transform([np.zeros((4, 3)), np.ones((4, 3))]).shape
    (2, 12)
    """

    _parameter_constraints = {}
    _motion_tags = MotionTags(output_kind="table", variable_length=False)

    def __init__(self):
        pass

    @_fit_context(prefer_skip_nested_validation=True)
    def fit(self, X, y=None):
        """Record the clip length and channel count.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames, n_channels)
            Equal-length clips.
        y : None
            Ignored.

        Returns
        -------
        self : FlattenClips
            The fitted transformer.
        """
        clips = check_clips(X, estimator=self, reset=True)
        self.n_frames_ = self._check_lengths(clips, len(clips[0]), "the first clip")
        return self

    def transform(self, X):
        """Flatten each clip into a row.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames, n_channels)
            Clips of the length seen in fit.

        Returns
        -------
        X_new : ndarray of shape (n_clips, n_frames * n_channels)
            Or a DataFrame after ``set_output(transform="pandas")``.
        """
        check_is_fitted(self)
        clips = check_clips(X, estimator=self)
        self._check_lengths(clips, self.n_frames_, "fit")
        table = np.stack(clips).reshape(len(clips), -1)
        return self._wrap_table(table, clips)

    @staticmethod
    def _check_lengths(clips, expected, source):
        lengths = clips.lengths
        bad = np.flatnonzero(lengths != expected)
        if bad.size:
            raise ValueError(
                f"FlattenClips needs clips of equal length: clip {bad[0]} has "
                f"{lengths[bad[0]]} frames, but {source} has {expected}. Put "
                "ResampleClips(n_frames=...) before it."
            )
        return int(expected)

    def get_feature_names_out(self, input_features=None):
        """Output feature names ``"<channel>@<frame>"``, frame-major.

        Parameters
        ----------
        input_features : array-like of str, default=None
            Input channel names.

        Returns
        -------
        feature_names_out : ndarray of str
        """
        check_is_fitted(self)
        names = channel_names_in(self, input_features)
        return np.asarray([f"{c}@{k}" for k in range(self.n_frames_) for c in names], dtype=object)
