"""EigenMovementPCA: PCA of segmented movement (eigenmovements).

The estimator, whole: segmenting clips (the rules of
:mod:`skmotion.preprocessing._segment`), fitting the components, coding
segments, and rebuilding movement from codes. The work on arrays (resampled
segment vectors, re-timing, assembling clips, the codes' container) is in the
free functions of ``_segment_vectors``; the components come from
``_principal_axes``.
"""

import time
from numbers import Integral, Real

import numpy as np
from sklearn.base import BaseEstimator
from sklearn.utils.validation import check_is_fitted

from skmotion.base import ClipEstimatorMixin, MotionTags, _OutputConfigMixin
from skmotion.decomposition._principal_axes import principal_axes
from skmotion.decomposition._segment_vectors import (
    SegmentCodes,
    assemble_segments,
    check_magnitude,
    check_segments,
    codes_frame,
    frame_counts,
    retime_segments,
    segment_vectors,
    vectors_to_segments,
)
from skmotion.preprocessing._filter import filter_min_frames
from skmotion.preprocessing._segment import segment_clip
from skmotion.utils._clips import check_clips, to_container
from skmotion.utils._parallel import parallel_map
from skmotion.utils._progress import say
from skmotion.utils._sklearn_compat import Interval, StrOptions, _fit_context

__all__ = ["EigenMovementPCA"]

# Inputs up to this magnitude are handled exactly as at unit scale (they are divided by a
# power of two inside); beyond it the variances, in squared input units, overflow float64.
_MAX_MAGNITUDE = 1e150


class EigenMovementPCA(ClipEstimatorMixin, _OutputConfigMixin, BaseEstimator):
    """Eigenmovements: PCA of movement segments, each coded by a few numbers.

    Each clip is cut into segments (strokes from rest to rest), each segment is
    resampled to ``n_samples`` samples per channel with a cubic spline and
    flattened channel after channel into one vector, and PCA over the training
    segments gives the eigenmovements. A segment's code is its projection on
    the first ``n_components`` of them. Reconstruction back-projects a code,
    splits it per channel and stretches it to the segment's real duration with
    a cubic spline.

    Parameters
    ----------
    n_components : int or None, default=30
        Eigenmovements kept; ``None`` keeps ``min(n_segments, n_features)``.
    n_samples : int, default=100
        Samples per channel of a resampled segment.
    segmentation : {"energy", "zvc", "none"}, default="energy"
        ``"energy"``: boundaries where the sum of squared velocities is low
        (SEG-2, :func:`~skmotion.preprocessing.energy_segments`); ``"zvc"``:
        zero-velocity crossings of several channels within ``zvc_window``
        (SEG-1, :func:`~skmotion.preprocessing.zvc_segments`); ``"none"``: each
        clip is one segment (for data cut into segments already).
    frame_rate : float, default=None
        Frames per second. Needed by ``"zvc"`` (its window is in seconds) and by
        an explicit ``energy_threshold``; the automatic energy threshold does
        not depend on it.
    filter_order : int or None, default=10
        Order of the zero-phase Butterworth low-pass applied before segmenting
        (the segments themselves are cut from the unfiltered input); ``None``
        segments the raw input.
    filter_cutoff : float, default=0.25
        Cutoff of that filter as a fraction of the Nyquist frequency.
    energy_threshold : float, default=None
        SEG-2 threshold in (units per second) squared; by default
        ``energy_ratio`` times each clip's mean energy.
    energy_ratio : float, default=0.1
        The automatic SEG-2 threshold as a fraction of the clip's mean energy.
    zvc_window : float, default=0.3
        SEG-1: seconds within which crossings of different channels coincide.
    zvc_min_channels : int, default=2
        SEG-1: channels that must cross together to make a boundary.
    min_movement : float, default=0.0
        Both rules keep a segment only when some channel moves more than this
        within it (input units); SEG-1 also ignores turning points of smaller
        prominence.
    n_jobs : int, default=None
        Jobs over clips for segmenting and resampling (``None`` is serial).
    verbose : int, default=0
        1 reports the steps of ``fit`` (segmenting, PCA) and their times on
        standard error.

    Attributes
    ----------
    components_ : ndarray of shape (n_components_, n_channels * n_samples)
        The eigenmovements, channel after channel; row ``i`` reshaped to
        ``(n_channels, n_samples)`` is one time-normalised movement per channel.
    explained_variance_ : ndarray of shape (n_components_,)
        Eigenvalues of the kept eigenmovements (covariance divided by
        ``n_segments_``).
    explained_variance_ratio_ : ndarray of shape (n_components_,)
        Their share of the total variance.
    mean_ : ndarray of shape (n_channels * n_samples,)
        The mean segment vector.
    n_components_ : int
        Number of eigenmovements kept.
    n_segments_ : int
        Number of training segments.
    total_variance_ : float
        Mean squared distance of the training segment vectors to ``mean_``.
    projection_mse_ : float
        Sum of the dropped eigenvalues: the mean over training segments of the
        squared norm of the projection error (input units squared).
    projection_rms_ : float
        ``sqrt(projection_mse_ / (n_channels * n_samples))``: the RMS error per
        sample of a projected training segment.
    n_features_in_ : int
        Number of channels seen in fit.
    feature_names_in_ : ndarray of str
        Channel names seen in fit, when given as DataFrame columns.

    See Also
    --------
    skmotion.control.KMeansPrimitiveController : primitives from the codes.
    skmotion.preprocessing.energy_segments : the SEG-2 rule.
    skmotion.preprocessing.zvc_segments : the SEG-1 rule.

    Notes
    -----
    ``transform`` returns one array of codes per clip, ``(n_segments_i,
    n_components_)``, always as a list (clips differ in their number of
    segments, and a clip may have none); :meth:`segment` gives the matching
    ``(start, stop)`` frames. Errors are in the input's units: feed joint
    angles in degrees to get the paper's degrees.

    In a pipeline, the codes are a collection of sequences (one per clip), as
    clips are, so a step taking clips follows: :class:`KMeansPrimitiveController`
    turns them into one usage histogram per clip, for any classifier after it.
    ``make_pipeline(EigenMovementPCA(5), LogisticRegression())`` fails with a
    TypeError saying so (the codes refuse to become one table: see
    :class:`SegmentCodes`). With ``set_output(transform="pandas")`` the codes are
    one DataFrame with a ``(clip, segment)`` MultiIndex and the columns
    ``get_feature_names_out()``; a clip without segments has no rows there.

    The results scale with the input: clips multiplied by ``a`` give the same
    eigenmovements and segments, codes and ``mean_`` times ``a``, variances times
    ``a**2`` (inputs are divided by a power of two inside, so no square overflows).
    Clips beyond 1e150 in magnitude are refused: their variances exceed float64.

    References
    ----------
    .. [1] Fod, Mataric and Jenkins, "Automated derivation of primitives for
       movement classification", Autonomous Robots 12 (2002), 39-54.

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.datasets import make_motions
    >>> from skmotion.decomposition import EigenMovementPCA
    >>> data = make_motions(n_clips_per_class=4, random_state=0)
    >>> right_arm = [33, 34, 35, 37]  # RightArm Z, X, Y and RightForeArm X rotations
    >>> arm = [np.rad2deg(c[:, right_arm]) for c in data.clips]  # in degrees
    >>> pca = EigenMovementPCA(n_components=8).fit(arm)
    >>> pca.components_.shape
    (8, 400)
    >>> codes = pca.transform(arm)
    >>> len(codes) == len(arm), codes[0].shape[1]
    (True, 8)
    >>> bool(pca.score(arm) < 0)
    True
    """

    _parameter_constraints = {
        "n_components": [Interval(Integral, 1, None, closed="left"), None],
        "n_samples": [Interval(Integral, 2, None, closed="left")],
        "segmentation": [StrOptions({"energy", "zvc", "none"})],
        "frame_rate": [Interval(Real, 0, None, closed="neither"), None],
        "filter_order": [Interval(Integral, 1, None, closed="left"), None],
        "filter_cutoff": [Interval(Real, 0, 1, closed="neither")],
        "energy_threshold": [Interval(Real, 0, None, closed="left"), None],
        "energy_ratio": [Interval(Real, 0, None, closed="left")],
        "zvc_window": [Interval(Real, 0, None, closed="neither")],
        "zvc_min_channels": [Interval(Integral, 1, None, closed="left")],
        "min_movement": [Interval(Real, 0, None, closed="left")],
        "n_jobs": [Integral, None],
        "verbose": ["verbose"],
    }

    def __init__(
        self,
        n_components=30,
        *,
        n_samples=100,
        segmentation="energy",
        frame_rate=None,
        filter_order=10,
        filter_cutoff=0.25,
        energy_threshold=None,
        energy_ratio=0.1,
        zvc_window=0.3,
        zvc_min_channels=2,
        min_movement=0.0,
        n_jobs=None,
        verbose=0,
    ):
        self.n_components = n_components
        self.n_samples = n_samples
        self.segmentation = segmentation
        self.frame_rate = frame_rate
        self.filter_order = filter_order
        self.filter_cutoff = filter_cutoff
        self.energy_threshold = energy_threshold
        self.energy_ratio = energy_ratio
        self.zvc_window = zvc_window
        self.zvc_min_channels = zvc_min_channels
        self.min_movement = min_movement
        self.n_jobs = n_jobs
        self.verbose = verbose

    def __skmotion_tags__(self):
        return MotionTags(output_kind="segments", min_frames=self._min_frames())

    def _encode(self, vectors):
        """Codes, in input units, of segment vectors of normalised clips."""
        scale = self._scale
        return ((vectors - self.mean_ / scale) @ self.components_.T) * scale

    def _wrap_codes(self, codes, clips):
        """The codes as a SegmentCodes list or, with pandas output, a (clip, segment) DataFrame."""
        if self._output_config() != "pandas":
            return SegmentCodes(codes)
        return codes_frame(codes, clips.container, self.get_feature_names_out())

    # -- fitting -----------------------------------------------------------------------

    def _fit(self, X):
        clips = check_clips(X, estimator=self, reset=True)
        start = time.perf_counter()
        normalised = self._normalised(clips, reset=True)
        say(self.verbose, f"EigenMovementPCA: segmenting {len(clips)} clips ...")
        segments = self._segment_all(normalised)
        per_clip = self._vectors_all(normalised, segments)
        vectors = np.concatenate(per_clip)
        n_segments, n_features = vectors.shape
        if n_segments == 0:
            raise ValueError(
                f"No segments were found in the {len(clips)} training clips; lower "
                "min_movement or energy_ratio, or choose another segmentation."
            )
        limit = min(n_segments, n_features)
        n_components = limit if self.n_components is None else self.n_components
        if n_components > limit:
            raise ValueError(
                f"n_components={n_components} must be at most min(n_segments, n_features) = "
                f"min({n_segments}, {n_features}) = {limit}: the {len(clips)} training clips "
                f"gave {n_segments} segments."
            )
        say(self.verbose, f"EigenMovementPCA: PCA of {n_segments} segments x {n_features} ...")
        mean, axes, eigenvalues = principal_axes(vectors, n_components)
        scale, squared = self._scale, self._scale**2
        total = float(np.einsum("ij,ij->", vectors - mean, vectors - mean) / n_segments)
        self.mean_ = mean * scale
        self.components_ = axes
        self.explained_variance_ = eigenvalues[:n_components] * squared
        self.total_variance_ = total * squared
        self.explained_variance_ratio_ = (
            eigenvalues[:n_components] / total if total > 0 else np.zeros(n_components)
        )
        dropped = float(eigenvalues[n_components:].sum())
        self.projection_mse_ = dropped * squared
        self.projection_rms_ = float(np.sqrt(dropped / n_features)) * scale
        self.n_components_ = n_components
        self.n_segments_ = n_segments
        say(self.verbose, f"EigenMovementPCA: fitted in {time.perf_counter() - start:.1f} s")
        return per_clip, clips

    @_fit_context(prefer_skip_nested_validation=True)
    def fit(self, X, y=None):
        """Segment the clips and find the eigenmovements of their segments.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_channels)
            Clips (or a 3-D array or a (clip, frame) DataFrame).
        y : None
            Ignored.

        Returns
        -------
        self : EigenMovementPCA
            The fitted estimator.
        """
        self._fit(X)
        return self

    @_fit_context(prefer_skip_nested_validation=True)
    def fit_transform(self, X, y=None):
        """Fit, and return the codes of the training clips' segments.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_channels)
            Clips (or a 3-D array or a (clip, frame) DataFrame).
        y : None
            Ignored.

        Returns
        -------
        codes : SegmentCodes (a list) of ndarray of shape (n_segments_i, n_components_)
            One array per clip; a (clip, segment) DataFrame with pandas output.
        """
        per_clip, clips = self._fit(X)
        return self._wrap_codes([self._encode(v) for v in per_clip], clips)

    # -- per-clip queries ----------------------------------------------------------

    def transform(self, X):
        """Code each segment of each clip by its eigenmovement coordinates.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_channels)
            Clips (or a 3-D array or a (clip, frame) DataFrame).

        Returns
        -------
        codes : SegmentCodes (a list) of ndarray of shape (n_segments_i, n_components_)
            One array per clip, a row per segment (see :meth:`segment`); with
            ``set_output(transform="pandas")`` one DataFrame indexed by (clip, segment).
        """
        check_is_fitted(self)
        clips = check_clips(X, estimator=self)
        normalised = self._normalised(clips)
        vectors = self._vectors_all(normalised, self._segment_all(normalised))
        return self._wrap_codes([self._encode(v) for v in vectors], clips)

    def get_feature_names_out(self, input_features=None):
        """Names of the code columns: ``eigenmovementpca0``, ``eigenmovementpca1``, ...

        Parameters
        ----------
        input_features : array-like of str, default=None
            Ignored beyond a check against ``feature_names_in_`` (a code mixes
            every channel).

        Returns
        -------
        names : ndarray of str of shape (n_components_,)
        """
        check_is_fitted(self)
        if input_features is not None:
            expected = getattr(self, "feature_names_in_", None)
            given = np.asarray(input_features, dtype=object)
            if len(given) != self.n_features_in_ or (
                expected is not None and not np.array_equal(given, expected)
            ):
                raise ValueError(
                    f"input_features {list(given)} do not match the {self.n_features_in_} "
                    "channels seen in fit."
                )
        return np.asarray([f"eigenmovementpca{i}" for i in range(self.n_components_)], dtype=object)

    # -- segments ----------------------------------------------------------------------

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

    # -- reconstruction ----------------------------------------------------------------

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
