"""Zero-phase Butterworth low-pass filtering of clips."""

from functools import lru_cache
from numbers import Integral, Real

import numpy as np
from scipy.signal import butter, sosfiltfilt
from sklearn.base import BaseEstimator
from sklearn.utils.validation import check_is_fitted

from skmotion.base import ClipTransformerMixin, MotionTags
from skmotion.utils._clips import check_clips
from skmotion.utils._features import channel_names_in
from skmotion.utils._parallel import parallel_map
from skmotion.utils._sklearn_compat import Interval, _fit_context

__all__ = ["LowPassFilter", "filter_min_frames", "lowpass_filter"]


@lru_cache(maxsize=32)
def _design(order, cutoff):
    # Designing costs milliseconds, more than filtering a clip: design once.
    return butter(order, cutoff, btype="lowpass", output="sos")


def _check_design(sos, order, cutoff):
    """Refuse a design that double precision cannot hold (its gain at 0 Hz is not 1).

    At very low cutoffs the poles crowd 1 and the sections lose their digits; the
    filter's initial state then solves a singular system. A design whose DC gain
    is off by more than 1e-6 is refused with the reason, not run.
    """
    with np.errstate(all="ignore"):
        gain = np.prod(sos[:, :3].sum(axis=1) / sos[:, 3:].sum(axis=1))
    if not abs(gain - 1.0) <= 1e-6:
        raise ValueError(
            f"cutoff={cutoff!r} is too low for an order-{order} Butterworth filter in double "
            f"precision (its gain at 0 Hz is {gain:.6g}, not 1). Use a cutoff of at least "
            "about 1e-5 (a fraction of the Nyquist frequency), a lower order, or resample the "
            "clips to a lower frame rate first."
        )


def _padlen(sos):
    # scipy's default for sosfiltfilt: the signal is extended by this many
    # frames at each end (odd reflection) before filtering forward and back.
    n_zeros = min(int((sos[:, 2] == 0).sum()), int((sos[:, 5] == 0).sum()))
    return 3 * (2 * len(sos) + 1 - n_zeros)


def filter_min_frames(order=10, cutoff=0.25):
    """The fewest frames a clip needs for :func:`lowpass_filter`.

    Zero-phase filtering extends each end of the clip by ``padlen`` frames
    (scipy's rule, ``3 * (2 * n_sections + 1)`` for a Butterworth design), and
    the clip must be longer than that.

    Parameters
    ----------
    order : int, default=10
        Order of the Butterworth design.
    cutoff : float, default=0.25
        Cutoff frequency as a fraction of the Nyquist frequency, in ``(0, 1)``.

    Returns
    -------
    min_frames : int

    Examples
    --------
    >>> from skmotion.preprocessing import filter_min_frames
    >>> filter_min_frames(10, 0.25), filter_min_frames(2, 0.25)
    (34, 10)
    """
    return _padlen(_design(order, cutoff)) + 1


def lowpass_filter(clip, *, order=10, cutoff=0.25):
    """Zero-phase Butterworth low-pass filter of one clip, channel by channel.

    The filter runs forward and backward over time (``scipy.signal.sosfiltfilt``
    on second-order sections), so it shifts nothing in time; the squared
    magnitude of the Butterworth response is applied, i.e. the attenuation in
    dB is doubled and the gain at ``cutoff`` is 1/2.

    Parameters
    ----------
    clip : ndarray of shape (n_frames, n_channels)
        The clip, time first.
    order : int, default=10
        Order of the Butterworth design (the paper's 10).
    cutoff : float, default=0.25
        Cutoff frequency as a fraction of the Nyquist frequency (half the frame
        rate), in ``(0, 1)``; the paper's 0.25 is 15 Hz at 120 Hz.

    Returns
    -------
    filtered : ndarray of shape (n_frames, n_channels)

    Raises
    ------
    ValueError
        When the clip has no more than ``filter_min_frames(order, cutoff) - 1``
        frames.

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.preprocessing import lowpass_filter
    >>> t = np.arange(200)
    >>> slow, fast = np.sin(2 * np.pi * t / 100), np.sin(2 * np.pi * t / 3)
    >>> out = lowpass_filter((slow + fast)[:, None])
    >>> float(np.abs(out[40:-40, 0] - slow[40:-40]).max()) < 0.01
    True
    """
    sos = _design(order, cutoff).copy()  # scipy's filter wants a writable array
    _check_design(sos, order, cutoff)
    needed = _padlen(sos) + 1
    if len(clip) < needed:
        raise ValueError(
            f"The clip has {len(clip)} frames; a zero-phase Butterworth filter of "
            f"order {order} needs at least {needed}. Lower the order or leave out "
            "the filter for short clips."
        )
    return sosfiltfilt(sos, clip, axis=0)


class LowPassFilter(ClipTransformerMixin, BaseEstimator):
    """Zero-phase Butterworth low-pass filter of every clip.

    Removes high-frequency noise (marker vibration, jitter) without shifting the
    motion in time: the design is applied forward and backward with
    ``scipy.signal.sosfiltfilt`` in second-order sections, which stays stable at
    high orders.

    Parameters
    ----------
    order : int, default=10
        Order of the Butterworth design (the eigenmovement paper's 10).
    cutoff : float, default=0.25
        Cutoff frequency as a fraction of the Nyquist frequency (half the frame
        rate), in ``(0, 1)``.
    n_jobs : int, default=None
        Number of jobs over clips (``None`` is serial).

    Attributes
    ----------
    n_features_in_ : int
        Number of channels seen in fit.
    feature_names_in_ : ndarray of str
        Channel names seen in fit, when given as DataFrame columns.

    See Also
    --------
    lowpass_filter : the same on one clip.
    filter_min_frames : how short a clip may be.

    Notes
    -----
    A clip must be longer than the filter's padding (34 frames for order 10);
    shorter clips get a ValueError naming the clip.

    References
    ----------
    .. [1] Fod, Mataric and Jenkins, "Automated derivation of primitives for
       movement classification", Autonomous Robots 12 (2002), section 5.2.

    Examples
    --------
    >>> from skmotion.datasets import make_motions
    >>> from skmotion.preprocessing import LowPassFilter
    >>> clips = make_motions(n_clips_per_class=1, random_state=0).clips
    >>> smooth = LowPassFilter(order=4, cutoff=0.3).fit_transform(clips)
    >>> len(smooth) == len(clips), smooth[0].shape == clips[0].shape
    (True, True)
    """

    _parameter_constraints = {
        "order": [Interval(Integral, 1, None, closed="left")],
        "cutoff": [Interval(Real, 0, 1, closed="neither")],
        "n_jobs": [Integral, None],
    }

    def __init__(self, order=10, *, cutoff=0.25, n_jobs=None):
        self.order = order
        self.cutoff = cutoff
        self.n_jobs = n_jobs

    def __skmotion_tags__(self):
        return MotionTags(
            output_kind="clips", min_frames=filter_min_frames(self.order, self.cutoff)
        )

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
        self : LowPassFilter
            The fitted transformer.
        """
        _check_design(_design(self.order, self.cutoff), self.order, self.cutoff)
        check_clips(X, estimator=self, reset=True)
        return self

    def transform(self, X):
        """Filter each clip.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_channels)
            Clips (or a 3-D array or a (clip, frame) DataFrame).

        Returns
        -------
        X_new : list of ndarray of shape (n_frames_i, n_channels)
            Filtered clips, in the container kind of ``X``.
        """
        check_is_fitted(self)
        clips = check_clips(X, estimator=self)
        out = parallel_map(
            lambda c: lowpass_filter(c, order=self.order, cutoff=self.cutoff),
            clips,
            n_jobs=self.n_jobs,
        )
        return self._wrap_clips([np.asarray(o, dtype=c.dtype) for o, c in zip(out, clips)], clips)

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
