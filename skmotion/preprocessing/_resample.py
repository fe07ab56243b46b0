"""Resampling clips in time: to a fixed length or to another frame rate."""

import os
from numbers import Integral, Real

import numpy as np
from scipy.interpolate import CubicSpline
from sklearn.base import BaseEstimator
from sklearn.utils.validation import check_is_fitted

from skmotion.base import ClipTransformerMixin
from skmotion.utils._clips import check_clips
from skmotion.utils._features import channel_names_in
from skmotion.utils._sklearn_compat import Interval, StrOptions, _fit_context

__all__ = ["ResampleClips", "resample_clip"]


def _memory_bytes():
    """Physical memory of the machine, or None where the OS does not say."""
    try:
        return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (AttributeError, ValueError, OSError):
        return None


def resample_clip(clip, times, kind="linear"):
    """Values of a clip at fractional frame positions.

    Parameters
    ----------
    clip : ndarray of shape (n_frames, n_channels)
        The clip; frame ``i`` is at position ``i``.
    times : ndarray of shape (n_out,)
        Positions in ``[0, n_frames - 1]`` at which to sample.
    kind : {"linear", "cubic"}, default="linear"
        Piecewise-linear or cubic-spline (not-a-knot) interpolation.

    Returns
    -------
    resampled : ndarray of shape (n_out, n_channels)

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.preprocessing import resample_clip
    >>> resample_clip(np.array([[0.0], [2.0]]), np.array([0.0, 0.5, 1.0])).ravel()
    array([0., 1., 2.])
    """
    n = len(clip)
    if n == 1:
        return np.repeat(clip, len(times), axis=0)
    if kind == "cubic" and n >= 3:
        return CubicSpline(np.arange(n), clip, axis=0)(times)
    lower = np.clip(np.floor(times).astype(np.intp), 0, n - 2)
    weight = (times - lower)[:, None]
    return clip[lower] * (1.0 - weight) + clip[lower + 1] * weight


class ResampleClips(ClipTransformerMixin, BaseEstimator):
    """Resample every clip in time, to a fixed length or a new frame rate.

    With ``n_frames`` each clip is stretched or squeezed to exactly that many
    frames spanning its whole duration (time normalisation), which makes a
    collection of equal-length clips. With ``frame_rate`` and
    ``target_frame_rate`` each clip is resampled by any ratio (120 to 100 Hz,
    say), keeping its duration.

    Parameters
    ----------
    n_frames : int, default=None
        Frames per output clip. Give either this or ``target_frame_rate``.
    frame_rate : float, default=None
        Frame rate of the input in Hz; needed with ``target_frame_rate``.
    target_frame_rate : float, default=None
        Frame rate of the output in Hz. A clip of ``n`` frames becomes
        ``floor((n - 1) * target / frame_rate) + 1`` frames.
    kind : {"linear", "cubic"}, default="linear"
        Interpolation between frames.

    Attributes
    ----------
    n_features_in_ : int
        Number of channels seen in fit.
    feature_names_in_ : ndarray of str
        Channel names seen in fit, when given as DataFrame columns.

    See Also
    --------
    FlattenClips : one row per equal-length clip, for any sklearn model.

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.preprocessing import ResampleClips
    >>> clips = [np.zeros((50, 3)), np.ones((80, 3))]
    >>> ResampleClips(n_frames=20).fit_transform(clips)[1].shape
    (20, 3)
    >>> rs = ResampleClips(frame_rate=120, target_frame_rate=30)
    >>> [c.shape[0] for c in rs.fit_transform(clips)]
    [13, 20]
    """

    _parameter_constraints = {
        "n_frames": [Interval(Integral, 1, None, closed="left"), None],
        "frame_rate": [Interval(Real, 0, None, closed="neither"), None],
        "target_frame_rate": [Interval(Real, 0, None, closed="neither"), None],
        "kind": [StrOptions({"linear", "cubic"})],
    }

    def __init__(self, n_frames=None, *, frame_rate=None, target_frame_rate=None, kind="linear"):
        self.n_frames = n_frames
        self.frame_rate = frame_rate
        self.target_frame_rate = target_frame_rate
        self.kind = kind

    @_fit_context(prefer_skip_nested_validation=True)
    def fit(self, X, y=None):
        """Check the parameters and record the channel count.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_channels)
            Clips (or a 3-D array or a (clip, frame) DataFrame).
        y : None
            Ignored.

        Returns
        -------
        self : ResampleClips
            The fitted transformer.
        """
        if isinstance(self.n_frames, (bool, np.bool_)):
            # bool is an Integral to Python: True would silently mean one frame.
            raise TypeError(
                f"The 'n_frames' parameter of ResampleClips must be an int in the range "
                f"[1, inf) or None, not a bool (got {self.n_frames!r})."
            )
        by_length = self.n_frames is not None
        by_rate = self.target_frame_rate is not None
        if by_length == by_rate:
            raise ValueError(
                "Give exactly one of n_frames (fixed length) or target_frame_rate "
                f"(new rate); got n_frames={self.n_frames!r}, "
                f"target_frame_rate={self.target_frame_rate!r}."
            )
        if by_rate and self.frame_rate is None:
            raise ValueError("target_frame_rate needs the input's frame_rate.")
        check_clips(X, estimator=self, reset=True)
        return self

    def transform(self, X):
        """Resample each clip.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_channels)
            Clips (or a 3-D array or a (clip, frame) DataFrame).

        Returns
        -------
        X_new : list of ndarray of shape (n_frames_out_i, n_channels)
            Resampled clips, in the container kind of ``X``.
        """
        check_is_fitted(self)
        clips = check_clips(X, estimator=self)
        self._check_output_size(clips)
        out = [resample_clip(c, self._positions(len(c)), self.kind) for c in clips]
        return self._wrap_clips(out, clips)

    def _n_out(self, n):
        """Frames of the resampled clip of ``n`` frames."""
        if self.n_frames is not None:
            return int(self.n_frames)
        ratio = self.frame_rate / self.target_frame_rate
        return int(np.floor((n - 1) / ratio + 1e-9)) + 1

    def _positions(self, n):
        if self.n_frames is not None:
            return np.linspace(0.0, n - 1.0, self.n_frames)
        ratio = self.frame_rate / self.target_frame_rate
        return np.minimum(np.arange(self._n_out(n)) * ratio, n - 1.0)

    def _check_output_size(self, clips):
        """Refuse, before allocating, an output larger than the machine's memory."""
        n_out = np.array([self._n_out(len(c)) for c in clips], dtype=float)
        width = clips[0].shape[1] if len(clips) else 0
        # The output, plus the interpolation's temporaries for the largest clip.
        needed = 8.0 * (n_out.sum() * width + 4 * n_out.max(initial=0) * (width + 1))
        limit = _memory_bytes()
        if limit is not None and needed > limit:
            k = int(np.argmax(n_out))
            raise ValueError(
                f"ResampleClips would need {needed / 2**30:.1f} GiB (clip {k} alone becomes "
                f"{int(n_out[k])} frames x {width} channels), more than this machine's "
                f"{limit / 2**30:.1f} GiB of memory; lower n_frames or target_frame_rate."
            )

    def get_feature_names_out(self, input_features=None):
        """Output channel names: the input's.

        Parameters
        ----------
        input_features : array-like of str, default=None
            Input channel names.

        Returns
        -------
        feature_names_out : ndarray of str
        """
        check_is_fitted(self)
        return channel_names_in(self, input_features)
