"""MotionClassifier: the recommended recogniser, markers -> tree vocabulary -> linear model."""

import copy
from numbers import Integral, Real

import numpy as np
from sklearn.base import BaseEstimator, ClassifierMixin
from sklearn.linear_model import LogisticRegression
from sklearn.preprocessing import StandardScaler
from sklearn.utils.multiclass import check_classification_targets
from sklearn.utils.validation import check_is_fitted

from skmotion.base import ClipEstimatorMixin, MotionTags
from skmotion.io import Motion
from skmotion.kinematics import Skeleton
from skmotion.kinematics._layouts import Layout
from skmotion.preprocessing import VirtualMarkerTransform
from skmotion.recognition._covariance_rows import covariance_rows
from skmotion.tree import MotionTreeEncoder
from skmotion.tree._build import TREE_CONSTRAINTS
from skmotion.tree._calibration import mixture_novelty
from skmotion.utils._clips import check_clips, stack_clips
from skmotion.utils._progress import say
from skmotion.utils._sklearn_compat import Interval, StrOptions, _fit_context

__all__ = ["MotionClassifier", "block_scales", "clip_covariances"]

# Fewer clips than this share of the columns: the linear model is solved in their span.
_SPAN_SHARE = 0.25


def block_scales(frames, blocks, weights):
    """One scale per block of channels: each block's frames to unit spread, times its weight.

    Positions and velocities of markers share units within their block (metres or
    body heights; per second), so each block is divided by one number, its
    root-mean-square deviation over all of its channels: a channel that barely
    moves stays small instead of having its noise blown up to unit variance, as
    per-channel standardisation would do.

    Parameters
    ----------
    frames : ndarray of shape (n_frames, n_channels)
    blocks : ndarray of int of shape (n_channels,)
        The block of each channel, ``0 .. n_blocks - 1``.
    weights : sequence of float
        The weight of each block after scaling.

    Returns
    -------
    scale : ndarray of shape (n_channels,)
        Divide the frames by it; a block with no spread gets scale ``1 / weight``.

    Examples
    --------
    >>> import numpy as np
    >>> frames = np.array([[0.0, 10.0, 1.0], [2.0, -10.0, 1.0]])
    >>> block_scales(frames, np.array([0, 0, 1]), [1.0, 0.5]).round(3).tolist()
    [7.106, 7.106, 2.0]
    """
    blocks = np.asarray(blocks)
    deviation = frames - frames.mean(axis=0)
    scale = np.empty(frames.shape[1])
    for block, weight in enumerate(weights):
        columns = blocks == block
        spread = np.sqrt(np.mean(np.square(deviation[:, columns]))) if columns.any() else 0.0
        scale[columns] = (spread if spread > 0 else 1.0) / weight
    return scale


def clip_covariances(clips, out=None):
    """The covariance of each clip's channels over its frames: the upper triangle, row by row.

    Which channels move together, and how much, whatever the order of the
    poses: the second moments beside the vocabulary's first (the channel
    means). A clip of one frame has covariance zero.

    Parameters
    ----------
    clips : list of ndarray of shape (n_frames_i, n_channels)

    out : ndarray of shape (n_clips, n_channels * (n_channels + 1) // 2), default=None
        Written in place and returned (e.g. the last columns of a larger table).

    Returns
    -------
    covariances : ndarray of shape (n_clips, n_channels * (n_channels + 1) // 2)
        Entry ``(j, k)``, ``j <= k``, of each clip's covariance (divided by its
        number of frames).

    Examples
    --------
    >>> import numpy as np
    >>> clip = np.array([[0.0, 0.0], [2.0, 1.0], [4.0, 2.0]])
    >>> clip_covariances([clip]).round(3).tolist()
    [[2.667, 1.333, 0.667]]
    """
    # one compiled pass: per clip its centred frames, one dsyrk, the triangle copied out
    frames, offsets = stack_clips(clips)
    return covariance_rows(np.ascontiguousarray(frames, dtype=np.float64), offsets, out)


def fit_in_span(model, columns, y):
    """Fit an L2-penalised linear ``model`` in the span of the training rows, when they are few.

    The gradient of the loss and of the L2 penalty with respect to the weights
    is a combination of the rows, so the optimal weights are one too (the
    representer theorem): with ``n`` rows and ``d >> n`` columns the problem is
    solved on the rows' ``n`` coordinates in an orthonormal basis of their span,
    whose penalty is the same, and the weights are mapped back. The same optimum,
    with ``n`` instead of ``d`` unknowns per class; with ``n > d / 4`` the basis
    costs more than it saves and the model is fitted as it is.

    The basis comes from the rows' ``n x n`` Gram matrix ``K = X X^T = V L V^T``:
    ``B = X^T V L^(-1/2)`` is orthonormal and the rows' coordinates in it are
    ``X B = V L^(1/2)``, so ``B`` itself is never formed (one matrix product over
    the columns, against two passes for a QR factorisation: 0.042 s of CPU against
    0.409 s for the whole span fit of 114 clips x 22,740 columns, see the user
    guide's recognition page). Directions whose eigenvalue is within rounding of
    zero hold no part of any row and are left out.

    Parameters
    ----------
    model : LogisticRegression
        Unfitted, with an L2 penalty (or none) and an unpenalised intercept.
    columns : ndarray of shape (n_samples, n_features)
    y : ndarray of shape (n_samples,)

    Returns
    -------
    model : LogisticRegression
        Fitted; its ``coef_`` of shape (n_classes or 1, n_features) acts on ``columns``.

    Examples
    --------
    >>> import numpy as np
    >>> from sklearn.linear_model import LogisticRegression
    >>> rng = np.random.default_rng(0)
    >>> X, y = rng.normal(size=(20, 200)), np.repeat([0, 1], 10)
    >>> full = LogisticRegression(tol=1e-12, max_iter=10_000).fit(X, y)
    >>> span = fit_in_span(LogisticRegression(tol=1e-12, max_iter=10_000), X, y)
    >>> bool(np.allclose(span.coef_, full.coef_, atol=1e-6))
    True
    """
    n_samples, n_features = columns.shape
    if n_samples > _SPAN_SHARE * n_features:
        return model.fit(columns, y)
    values, vectors = np.linalg.eigh(columns @ columns.T)
    kept = values > values[-1] * n_samples * np.finfo(float).eps
    root = np.sqrt(values[kept])
    vectors = vectors[:, kept]
    model.fit(vectors * root, y)
    model.coef_ = ((model.coef_ / root) @ vectors.T) @ columns
    model.n_features_in_ = n_features
    return model


def _fold_columns(classifier, center, scale):
    """A copy of the linear ``classifier`` acting on unscaled columns.

    ``w . (x - center) / scale + b = (w / scale) . x + (b - (w / scale) . center)``:
    predicting this way skips two passes over a batch's (clips x columns) array.
    """
    readout = copy.copy(classifier)
    readout.coef_ = classifier.coef_ / scale
    readout.intercept_ = classifier.intercept_ - readout.coef_ @ center
    return readout


class MotionClassifier(ClipEstimatorMixin, ClassifierMixin, BaseEstimator):
    """Recognise motions in one line: markers, the motion tree's vocabulary, a linear model.

    The chain measured best on multi-subject skeleton data, with its measured
    defaults (user guide, ``docs/recognition.md``):

    1. **markers** -- with a ``layout`` (joint positions from a tracker) or a
       ``skeleton`` (joint angles), :class:`~skmotion.preprocessing.VirtualMarkerTransform`
       puts every clip in the body frame (origin on the floor below the root,
       facing forward, lengths in body sizes) and appends the markers' velocities;
       without either, the clips' channels are used as they are;
    2. **scaling** -- marker positions and velocities are each scaled as one
       block (one number per block, velocities weighted by ``velocity_weight``);
       other channels are standardised one by one (their units differ);
    3. **vocabulary** -- a :class:`~skmotion.tree.MotionTreeEncoder` over the
       scaled frames: every clip becomes the occupancy of every tree layer over a
       (1, 2, 3) temporal pyramid, the residuals of two layers, and each
       channel's mean over the clip, its halves and its quarters (a coarse
       trajectory) with its root mean square; and the covariance of the
       channels over the clip (:func:`clip_covariances`: which channels move
       together), its columns weighted by ``covariance_weight``;
    4. **classifier** -- each column centred and divided by the square root of
       its spread (``column_power``), then a multinomial logistic regression
       (``C``, ``class_weight``), whose probabilities are the answer of
       :meth:`predict_proba`; with fewer clips than a quarter of the columns it is
       solved in the clips' span (the same optimum, see ``fit_in_span``).
       Full standardisation would give a leaf that a few training frames
       reach the weight of the commonest pose; no scaling would leave the
       occupancies (shares of frames) far quieter than the channel means. The
       square root, between the two, measured best over the development sets
       taken together (user guide: the defaults study).

    Parameters
    ----------
    layout : str or Layout, default=None
        The joint layout of position clips (a name from
        :data:`~skmotion.preprocessing.LAYOUTS`, e.g. ``"kinect_v2"``).
    skeleton : Skeleton, default=None
        The skeleton of joint-angle clips. Give a layout or a skeleton, not both;
        neither for :class:`~skmotion.io.Motion` clips (they carry their own
        skeleton, and go through the marker step) or for clips whose channels are
        features already (sensors, or markers computed before), which are used as
        they are.
    markers : "auto", str, MarkerSet or list, default="auto"
        The markers :class:`~skmotion.preprocessing.VirtualMarkerTransform`
        outputs (its ``markers`` parameter).
    frame_rate : float, default=None
        Frames per second of plain-array clips, needed for the markers'
        velocities (Motions carry their own).
    scaling : {"auto", "blocks", "channels"}, default="auto"
        ``"blocks"``: positions and velocities each as one block; ``"channels"``:
        every channel to zero mean and unit variance; ``"auto"``: blocks after
        the marker step, channels without it.
    velocity_weight : float, default=1.0
        The velocities' block weight against the positions' (``"blocks"`` only).
    max_depth : int, default=6
        The motion tree's deepest layer (its vocabulary: up to ``2 ** max_depth``
        poses).
    split : {"median", "two_means", "min_error"}, default="median"
        How the motion tree splits a node along its principal axis (see
        :class:`~skmotion.tree.MotionTreeEncoder`).
    residual_layers : array-like of int, default=(1, 3)
        The tree layers whose residuals are encoded.
    moment_pyramid : array-like of int, default=(1, 2, 4)
        The parts of the clip over which each channel's mean is taken.
    covariance_weight : float, default=0.2
        The weight of the channels' covariance over each clip beside the
        vocabulary (its columns scaled like the others, then times this
        weight); 0 leaves it out.
    column_power : float, default=0.5
        Each vocabulary column is divided by its standard deviation to this
        power before the linear model: 1 standardises the columns, 0 keeps
        their own units.
    C : float, default=1.0
        Inverse regularisation of the logistic regression.
    class_weight : "balanced", dict or None, default=None
        The logistic regression's class weights: ``"balanced"`` weighs each
        class inversely to its number of training clips (for classes recorded
        unevenly), None weighs every clip alike.
    n_jobs : int, default=None
        Clips turned into markers in parallel (joblib threads).
    verbose : int, default=0
        1 or more reports the steps of ``fit`` on standard error.

    Attributes
    ----------
    markers_ : VirtualMarkerTransform or None
        The fitted marker step (None without a layout or skeleton).
    scale_ : ndarray of shape (n_channels_encoded,)
        The scaling of the encoder's input channels.
    center_ : ndarray of shape (n_channels_encoded,)
        The centre subtracted before scaling (the training frames' mean).
    encoder_ : MotionTreeEncoder
        The fitted vocabulary.
    column_center_ : ndarray of shape (n_features,)
        The vocabulary columns' means over the training clips.
    column_scale_ : ndarray of shape (n_features,)
        The divisor of each column: its standard deviation to ``column_power``.
    classifier_ : LogisticRegression
        The linear model.
    classes_ : ndarray of shape (n_classes,)
        The class labels.
    n_features_in_ : int
        Number of input channels.
    feature_names_in_ : ndarray of str
        Input channel names, when fit saw a DataFrame with string columns.

    See Also
    --------
    MotionTreeEncoder : the vocabulary alone, for a classifier of one's own.
    MotionTreeHMM : the generative database (decoding, prediction, streaming).

    Examples
    --------
    >>> from skmotion.datasets import make_position_motions
    >>> from skmotion.recognition import MotionClassifier
    >>> data = make_position_motions("kinect_v2", n_clips_per_class=4, random_state=0)
    >>> train = data.groups != 3
    >>> X = data.clips
    >>> model = MotionClassifier(layout="kinect_v2", frame_rate=data.frame_rate)
    >>> model = model.fit([x for x, t in zip(X, train) if t], data.target[train])
    >>> float(model.score([x for x, t in zip(X, train) if not t], data.target[~train]))
    1.0
    """

    _parameter_constraints = {
        "layout": [str, Layout, None],
        "skeleton": [Skeleton, None],
        "markers": "no_validation",  # VirtualMarkerTransform validates it
        "frame_rate": [Interval(Real, 0, None, closed="neither"), None],
        "scaling": [StrOptions({"auto", "blocks", "channels"})],
        "velocity_weight": [Interval(Real, 0, None, closed="neither")],
        "max_depth": [Interval(Integral, 1, None, closed="left")],
        "split": TREE_CONSTRAINTS["split"],
        "residual_layers": ["array-like"],
        "moment_pyramid": ["array-like"],
        "covariance_weight": [Interval(Real, 0, None, closed="left")],
        "column_power": [Interval(Real, 0, 1, closed="both")],
        "C": [Interval(Real, 0, None, closed="neither")],
        "class_weight": [StrOptions({"balanced"}), dict, None],
        "n_jobs": [Integral, None],
        "verbose": ["verbose"],
    }
    _motion_tags = MotionTags(output_kind="labels")

    def __init__(
        self,
        *,
        layout=None,
        skeleton=None,
        markers="auto",
        frame_rate=None,
        scaling="auto",
        velocity_weight=1.0,
        max_depth=6,
        split="median",
        residual_layers=(1, 3),
        moment_pyramid=(1, 2, 4),
        covariance_weight=0.2,
        column_power=0.5,
        C=1.0,
        class_weight=None,
        n_jobs=None,
        verbose=0,
    ):
        self.layout = layout
        self.skeleton = skeleton
        self.markers = markers
        self.frame_rate = frame_rate
        self.scaling = scaling
        self.velocity_weight = velocity_weight
        self.max_depth = max_depth
        self.split = split
        self.residual_layers = residual_layers
        self.moment_pyramid = moment_pyramid
        self.covariance_weight = covariance_weight
        self.column_power = column_power
        self.C = C
        self.class_weight = class_weight
        self.n_jobs = n_jobs
        self.verbose = verbose

    @_fit_context(prefer_skip_nested_validation=False)
    def fit(self, X, y):
        """Fit the marker step, the vocabulary and the linear model.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_channels), or of Motion
            Training clips (or a 3-D array, or a ``(clip, frame)`` DataFrame).
        y : array-like of shape (n_clips,)
            The label of each clip.

        Returns
        -------
        self : MotionClassifier
            The fitted classifier.
        """
        if self.layout is not None and self.skeleton is not None:
            raise ValueError("give a layout (joint positions) or a skeleton (angles), not both.")
        y = np.asarray(y)
        check_classification_targets(y)
        self.markers_ = None
        motions = not isinstance(X, np.ndarray) and any(isinstance(x, Motion) for x in X)
        if self.layout is not None or self.skeleton is not None or motions:
            self.markers_ = VirtualMarkerTransform(
                skeleton=self.skeleton,
                layout=self.layout,
                markers=self.markers,
                frame_rate=self.frame_rate,
                n_jobs=self.n_jobs,
            )
            say(self.verbose, "MotionClassifier: markers")
            clips = self.markers_.fit_transform(X)
            self.n_features_in_ = self.markers_.n_features_in_
            if hasattr(self.markers_, "feature_names_in_"):
                self.feature_names_in_ = self.markers_.feature_names_in_
        else:
            clips = check_clips(X, estimator=self, reset=True)
        if len(y) != len(clips):
            raise ValueError(f"X holds {len(clips)} clips but y holds {len(y)} labels.")
        frames, _ = stack_clips(clips)
        self.center_ = frames.mean(axis=0)
        self.scale_ = self._scales(frames)
        scaled = self._scaled(clips)
        say(self.verbose, f"MotionClassifier: the vocabulary over {len(frames):,} frames")
        self.encoder_ = MotionTreeEncoder(
            max_depth=self.max_depth,
            split=self.split,
            layers="all",
            residual_layers=self.residual_layers,
            moment_pyramid=self.moment_pyramid,
            standardize=False,
            sparse_output=False,
        ).fit(scaled)
        # fitted state, so that a later set_params does not change what transform computes
        self._with_covariances = self.covariance_weight > 0
        features = self._vocabulary(scaled)
        # StandardScaler's mean and spread (a constant column gets spread 1), to a power
        columns = StandardScaler().fit(features)
        self.column_center_ = columns.mean_
        self.column_scale_ = columns.scale_**self.column_power
        if self._with_covariances:
            self.column_scale_[self.encoder_.n_features_out_ :] /= self.covariance_weight
        say(self.verbose, f"MotionClassifier: the classifier on {features.shape[1]} columns")
        # With fewer clips than columns (sets of tens of clips), the same optimum in
        # the clips' span costs a third of the time (fit_in_span)
        linear = LogisticRegression(C=self.C, class_weight=self.class_weight, max_iter=1000)
        self.classifier_ = fit_in_span(linear, self._columns(features), y)
        self.classes_ = self.classifier_.classes_
        self._readout = _fold_columns(self.classifier_, self.column_center_, self.column_scale_)
        return self

    def _scales(self, frames):
        scaling = self.scaling
        if scaling == "auto":
            scaling = "blocks" if self.markers_ is not None else "channels"
        if scaling == "channels":
            spread = frames.std(axis=0)
            return np.where(spread > 0, spread, 1.0)
        if self.markers_ is None:
            raise ValueError(
                "scaling='blocks' needs the marker step (a layout or a skeleton): its "
                "positions and velocities are the blocks. Use scaling='channels'."
            )
        names = self.markers_.get_feature_names_out()
        velocity = np.array([name.rsplit("_", 1)[-1].startswith("v") for name in names])
        return block_scales(frames, velocity.astype(int), [1.0, self.velocity_weight])

    def _scaled(self, clips):
        return [(clip - self.center_) / self.scale_ for clip in clips]

    def _clips(self, X):
        """Validated clips in the encoder's units."""
        check_is_fitted(self)
        if self.markers_ is not None:
            clips = self.markers_.transform(X)
        else:
            clips = check_clips(X, estimator=self)
        return self._scaled(clips)

    def transform(self, X):
        """The scaled vocabulary vector of each clip (the linear model's input).

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_channels), or of Motion

        Returns
        -------
        features : ndarray of shape (n_clips, n_features)
        """
        return self._columns(self._raw(X))

    def _raw(self, X):
        """The vocabulary before the columns' scaling (``_readout`` has it folded in)."""
        return self._vocabulary(self._clips(X))  # _clips checks that the model is fitted

    def _vocabulary(self, clips):
        encoded = self.encoder_.transform(clips)
        if not self._with_covariances:
            return encoded
        # the covariances written into their columns of the table (no copy of them after)
        n_channels, width = clips[0].shape[1], encoded.shape[1]
        table = np.empty((len(clips), width + n_channels * (n_channels + 1) // 2))
        table[:, :width] = encoded
        clip_covariances(clips, out=table[:, width:])
        return table

    def _columns(self, features):
        return (features - self.column_center_) / self.column_scale_

    def decision_function(self, X):
        """Per-class scores of each clip (the logistic regression's logits).

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_channels), or of Motion

        Returns
        -------
        scores : ndarray of shape (n_clips, n_classes)
            Or ``(n_clips,)`` for two classes (sklearn's convention).
        """
        scores = self._scores(X)
        return scores.ravel() if scores.shape[1] == 1 else scores

    def _scores(self, X):
        """The logits, ``features @ coef.T + intercept``: the doubles of the readout's
        ``decision_function`` (sklearn's product), without its input checks, which cost
        as much as the product (a fifth of a small batch's predict): the vocabulary is
        finite, the encoder having checked the clips' magnitudes."""
        features = self._raw(X)  # checks that the model is fitted first
        return features @ self._readout.coef_.T + self._readout.intercept_

    def predict_proba(self, X):
        """Class probabilities of each clip.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_channels), or of Motion

        Returns
        -------
        proba : ndarray of shape (n_clips, n_classes)
            Columns in the order of ``classes_``.
        """
        features = self._raw(X)  # checks that the model is fitted first
        return self._readout.predict_proba(features)

    def predict_log_proba(self, X):
        """Log of :meth:`predict_proba`.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_channels), or of Motion

        Returns
        -------
        log_proba : ndarray of shape (n_clips, n_classes)
        """
        features = self._raw(X)  # checks that the model is fitted first
        return self._readout.predict_log_proba(features)

    def predict(self, X):
        """The most probable class of each clip.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_channels), or of Motion

        Returns
        -------
        labels : ndarray of shape (n_clips,)
        """
        scores = self._scores(X)  # as the readout's predict: the sign, or the largest
        indices = (scores[:, 0] > 0).astype(np.intp) if scores.shape[1] == 1 else scores.argmax(1)
        return self.classes_[indices]

    def novelty_score(self, X):
        """Mean log density of each clip's frames under the vocabulary's deepest layer.

        The nodes of the tree's bottom layer as a Gaussian mixture (spherical,
        weighted by their share of the training frames), in the encoder's units:
        lower is more novel. Threshold it at a low quantile of the training
        clips' scores to reject clips unlike any seen in training.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_channels), or of Motion

        Returns
        -------
        score : ndarray of shape (n_clips,)
            Higher for clips like the training data.
        """
        frames, offsets = stack_clips(self._clips(X))
        tree = self.encoder_.tree_
        layer = tree.n_layers - 1
        counts = tree.counts(layer).astype(float)
        return mixture_novelty(tree, layer, frames, offsets, np.log(counts / counts.sum()))

    def __sklearn_tags__(self):
        tags = super().__sklearn_tags__()
        tags.classifier_tags.multi_class = True
        return tags
