"""ToAeon: the last skmotion step of a Pipeline whose classifier comes from aeon or sktime."""

from sklearn.base import BaseEstimator
from sklearn.utils.validation import check_is_fitted

from skmotion.base import ClipEstimatorMixin, MotionTags, _OutputConfigMixin
from skmotion.utils._bridges import to_aeon
from skmotion.utils._clips import check_clips
from skmotion.utils._features import channel_names_in
from skmotion.utils._sklearn_compat import StrOptions, _fit_context

__all__ = ["ToAeon"]


class ToAeon(ClipEstimatorMixin, _OutputConfigMixin, BaseEstimator):
    """Hand clips to an aeon (or sktime) estimator: channels first, equal length or not.

    aeon's classifiers take a 3-D array ``(n_cases, n_channels, n_timepoints)``
    or, for series of different lengths, a list of ``(n_channels,
    n_timepoints_i)`` arrays; skmotion's clips are frames by channels. Put
    ``ToAeon()`` after the skmotion steps and before the aeon classifier in a
    :class:`~sklearn.pipeline.Pipeline`, and the pipeline fits, predicts,
    cross-validates and pickles as any scikit-learn model, on ragged clips
    when the classifier accepts unequal lengths (its tag
    ``capability:unequal_length``).

    Parameters
    ----------
    equal_length : {"auto", True, False}, default="auto"
        As in :func:`skmotion.utils.to_aeon`: ``"auto"`` passes a 3-D array
        when the clips share a length, else a list.

    Attributes
    ----------
    n_features_in_ : int
        Number of channels seen in fit.
    feature_names_in_ : ndarray of str
        Channel names seen in fit, when given as DataFrame columns.

    See Also
    --------
    skmotion.utils.to_aeon, skmotion.utils.from_aeon : the conversion itself.

    Examples
    --------
    >>> import pytest
    >>> _ = pytest.importorskip("aeon")
    >>> from aeon.classification.distance_based import KNeighborsTimeSeriesClassifier
    >>> from sklearn.pipeline import make_pipeline
    >>> from skmotion.datasets import make_motions
    >>> from skmotion.preprocessing import ToAeon, VirtualMarkerTransform
    >>> from skmotion.io import as_motions
    >>> data = make_motions(n_clips_per_class=3, classes=["walk", "jump"], random_state=0)
    >>> motions = as_motions(data.clips, data.skeletons, data.frame_rate)
    >>> model = make_pipeline(VirtualMarkerTransform(), ToAeon(),  # clips of any length
    ...                       KNeighborsTimeSeriesClassifier(distance="dtw"))
    >>> model.fit(motions[::2], data.target[::2]).predict(motions[1::2]).tolist()
    [0, 1, 1]
    >>> data.target[1::2].tolist()
    [0, 1, 1]
    """

    _parameter_constraints = {"equal_length": [StrOptions({"auto"}), "boolean"]}
    _motion_tags = MotionTags(output_kind="aeon")

    def __init__(self, equal_length="auto"):
        self.equal_length = equal_length

    @_fit_context(prefer_skip_nested_validation=True)
    def fit(self, X, y=None):
        """Record the channels.

        Parameters
        ----------
        X : clip collection
        y : None
            Ignored.

        Returns
        -------
        self : ToAeon
        """
        check_clips(X, estimator=self, reset=True)
        return self

    def transform(self, X):
        """The clips in aeon's form.

        Parameters
        ----------
        X : clip collection
            Clips with the channels seen in fit.

        Returns
        -------
        X_aeon : ndarray of shape (n_clips, n_channels, n_frames) or list of ndarray
        """
        check_is_fitted(self)
        check_clips(X, estimator=self)
        return to_aeon(X, equal_length=self.equal_length)

    def get_feature_names_out(self, input_features=None):
        """The channels, in the order of aeon's channel axis.

        Parameters
        ----------
        input_features : array-like of str, default=None

        Returns
        -------
        feature_names_out : ndarray of str
        """
        check_is_fitted(self)
        return channel_names_in(self, input_features)

    def set_output(self, *, transform=None):
        """Only ``"default"``: aeon's collections are not tables.

        Parameters
        ----------
        transform : {"default"}, default=None

        Returns
        -------
        self : ToAeon
        """
        if transform not in (None, "default"):
            raise ValueError(
                f"ToAeon.set_output(transform={transform!r}): ToAeon returns aeon's "
                "channels-first collections, which are not tables; only 'default' applies."
            )
        return super().set_output(transform=transform)
