"""KMeansPrimitiveController: movement primitives as K-means clusters of segment codes."""

from numbers import Integral, Real

import numpy as np
from sklearn.base import BaseEstimator
from sklearn.cluster import KMeans
from sklearn.utils import check_random_state
from sklearn.utils.validation import check_is_fitted

from skmotion.base import ClipFeatureMixin, MotionTags
from skmotion.control._simulate import ArmSimulation, simulate_arm
from skmotion.utils._clips import check_clips, split_frames
from skmotion.utils._sklearn_compat import Interval, _fit_context

__all__ = ["KMeansPrimitiveController"]


def _squared_distances(codes, centres):
    """Squared distance of each code to its nearest centre, and that centre's index."""
    d2 = (
        np.einsum("ij,ij->i", codes, codes)[:, None]
        - 2.0 * codes @ centres.T
        + np.einsum("ij,ij->i", centres, centres)[None, :]
    )
    labels = d2.argmin(axis=1)
    diff = codes - centres[labels]
    return np.einsum("ij,ij->i", diff, diff), labels


def _covered_runs(valid):
    """``(start, stop)`` of each run of consecutive True frames."""
    edges = np.diff(np.r_[0, valid.astype(np.int8), 0])
    return np.c_[np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)]


class KMeansPrimitiveController(ClipFeatureMixin, BaseEstimator):
    """Movement primitives: K-means clusters of eigenmovement segment codes.

    Takes, per clip, the codes of its segments (the output of
    :class:`~skmotion.decomposition.EigenMovementPCA`), clusters all segments'
    codes with K-means, and treats each cluster centre as a primitive: a
    commonly used movement that one controller can execute. ``transform``
    describes a clip by how often it uses each primitive, so a classifier can
    follow in a ``Pipeline``; ``quantize`` replaces each code by its primitive,
    and :meth:`simulate` executes the primitives on a simulated arm.

    Parameters
    ----------
    n_clusters : int, default=30
        Number of primitives.
    n_init : int, default=10
        K-means restarts; the best (lowest inertia) is kept.
    max_iter : int, default=300
        Iterations of one K-means run.
    tol : float, default=1e-4
        K-means convergence tolerance (sklearn's meaning).
    normalize : bool, default=True
        Whether ``transform`` gives usage fractions (rows sum to 1; a clip
        without segments gets zeros) rather than counts.
    random_state : int, RandomState instance or None, default=None
        Seed of the K-means initialisation.

    Attributes
    ----------
    cluster_centers_ : ndarray of shape (n_clusters, n_components)
        The primitives, in eigenmovement coordinates.
    kmeans_ : KMeans
        The fitted sklearn K-means.
    clustering_mse_ : float
        Mean squared distance of the training codes to their nearest centre.
    n_segments_ : int
        Number of training segments.
    n_features_in_ : int
        Number of code components seen in fit.
    feature_names_in_ : ndarray of str
        Component names seen in fit, when given as DataFrame columns.

    See Also
    --------
    skmotion.decomposition.EigenMovementPCA : the segment codes.
    simulate_arm : PD-servo tracking on a simulated arm.

    Notes
    -----
    Codes are orthonormal coordinates, so a segment rebuilt from its primitive
    misses the original by the projection error plus the clustering error:
    ``total MSE = EigenMovementPCA.projection_mse_ + clustering_mse_`` on the
    training segments (the two errors are orthogonal).

    References
    ----------
    .. [1] Fod, Mataric and Jenkins, "Automated derivation of primitives for
       movement classification", Autonomous Robots 12 (2002), section 6.

    Examples
    --------
    >>> import numpy as np
    >>> from sklearn.linear_model import LogisticRegression
    >>> from sklearn.pipeline import make_pipeline
    >>> from skmotion.control import KMeansPrimitiveController
    >>> from skmotion.datasets import make_motions
    >>> from skmotion.decomposition import EigenMovementPCA
    >>> data = make_motions(n_clips_per_class=4, random_state=0)
    >>> angles = [c[:, 6:] for c in data.clips]  # joint angles, without the root
    >>> codes = EigenMovementPCA(n_components=10).fit_transform(angles)
    >>> controller = KMeansPrimitiveController(n_clusters=12, random_state=0).fit(codes)
    >>> controller.transform(codes).shape
    (28, 12)
    >>> model = make_pipeline(EigenMovementPCA(n_components=10),
    ...                       KMeansPrimitiveController(n_clusters=12, random_state=0),
    ...                       LogisticRegression(max_iter=1000))
    >>> bool(model.fit(angles, data.target).score(angles, data.target) > 0.8)
    True
    """

    _parameter_constraints = {
        "n_clusters": [Interval(Integral, 1, None, closed="left")],
        "n_init": [Interval(Integral, 1, None, closed="left")],
        "max_iter": [Interval(Integral, 1, None, closed="left")],
        "tol": [Interval(Real, 0, None, closed="left")],
        "normalize": ["boolean"],
        "random_state": ["random_state"],
    }
    # A clip without segments has no codes: empty code arrays are valid input.
    _motion_tags = MotionTags(output_kind="table", min_frames=0)

    def __init__(
        self, n_clusters=30, *, n_init=10, max_iter=300, tol=1e-4, normalize=True, random_state=None
    ):
        self.n_clusters = n_clusters
        self.n_init = n_init
        self.max_iter = max_iter
        self.tol = tol
        self.normalize = normalize
        self.random_state = random_state

    def _codes(self, X, reset=False):
        return check_clips(X, estimator=self, reset=reset)

    @_fit_context(prefer_skip_nested_validation=True)
    def fit(self, X, y=None):
        """Cluster the codes of all segments of all clips.

        Parameters
        ----------
        X : list of ndarray of shape (n_segments_i, n_components)
            Per clip, its segment codes (a clip may have none).
        y : None
            Ignored.

        Returns
        -------
        self : KMeansPrimitiveController
            The fitted controller.
        """
        codes = np.concatenate(self._codes(X, reset=True))
        if len(codes) < self.n_clusters:
            raise ValueError(
                f"n_clusters={self.n_clusters} needs at least as many segments; the "
                f"{len(X)} clips hold {len(codes)}."
            )
        rng = check_random_state(self.random_state)
        self.kmeans_ = KMeans(
            n_clusters=self.n_clusters,
            n_init=self.n_init,
            max_iter=self.max_iter,
            tol=self.tol,
            random_state=rng.randint(np.iinfo(np.int32).max),
        ).fit(codes)
        self.cluster_centers_ = self.kmeans_.cluster_centers_
        self.clustering_mse_ = float(_squared_distances(codes, self.cluster_centers_)[0].mean())
        self.n_segments_ = len(codes)
        return self

    def _per_clip(self, codes, values):
        """Per-segment ``values`` of all clips, stacked, split back into one array per clip."""
        return split_frames(values, np.concatenate([[0], np.cumsum(codes.lengths)]))

    def _labels(self, codes):
        """The nearest centre of every segment of every clip, stacked."""
        return _squared_distances(np.concatenate(codes), self.cluster_centers_)[1]

    def _quantized(self, codes):
        return self._per_clip(codes, self.cluster_centers_[self._labels(codes)])

    def predict(self, X):
        """The primitive of each segment of each clip.

        Parameters
        ----------
        X : list of ndarray of shape (n_segments_i, n_components)
            Per clip, its segment codes.

        Returns
        -------
        labels : list of ndarray of int of shape (n_segments_i,)
            Per clip, the nearest cluster centre of each segment.
        """
        check_is_fitted(self)
        codes = self._codes(X)
        return self._per_clip(codes, self._labels(codes))

    def transform(self, X):
        """Primitive-usage histogram of each clip.

        Parameters
        ----------
        X : list of ndarray of shape (n_segments_i, n_components)
            Per clip, its segment codes.

        Returns
        -------
        usage : ndarray of shape (n_clips, n_clusters)
            How many segments of the clip use each primitive (fractions with
            ``normalize=True``). A DataFrame after ``set_output(transform="pandas")``.
        """
        check_is_fitted(self)
        codes = self._codes(X)
        labels = self._labels(codes)
        clip_of = np.repeat(np.arange(len(codes)), [len(c) for c in codes])
        usage = np.zeros((len(codes), self.n_clusters))
        np.add.at(usage, (clip_of, labels), 1.0)
        if self.normalize:
            totals = usage.sum(axis=1, keepdims=True)
            usage = np.divide(usage, totals, out=np.zeros_like(usage), where=totals > 0)
        return self._wrap_table(usage, codes)

    def quantize(self, X):
        """Each segment code replaced by its primitive (nearest cluster centre).

        Parameters
        ----------
        X : list of ndarray of shape (n_segments_i, n_components)
            Per clip, its segment codes.

        Returns
        -------
        codes : list of ndarray of shape (n_segments_i, n_components)
            Per clip, the cluster centre of each segment; rebuild movement from
            them with ``EigenMovementPCA.inverse_transform``.
        """
        check_is_fitted(self)
        return self._quantized(self._codes(X))

    def score(self, X, y=None):
        """Negative clustering MSE: mean squared distance of codes to their primitive.

        Parameters
        ----------
        X : list of ndarray of shape (n_segments_i, n_components)
            Per clip, its segment codes.
        y : None
            Ignored.

        Returns
        -------
        score : float
            Higher is better.
        """
        check_is_fitted(self)
        codes = np.concatenate(self._codes(X))
        if len(codes) == 0:
            raise ValueError("X holds no segment codes: nothing to score.")
        return -float(_squared_distances(codes, self.cluster_centers_)[0].mean())

    def get_feature_names_out(self, input_features=None):
        """Names of the usage columns: ``primitive0``, ``primitive1``, ...

        Parameters
        ----------
        input_features : None
            Ignored.

        Returns
        -------
        feature_names_out : ndarray of str
        """
        check_is_fitted(self)
        return np.asarray([f"primitive{k}" for k in range(self.n_clusters)], dtype=object)

    def simulate(
        self, X, segments, *, eigenmovements, arm, frame_rate, degrees=False, quantize=True, **servo
    ):
        """Execute each clip's primitives on a simulated arm with PD servos.

        Each clip's codes (replaced by their primitives with ``quantize=True``)
        are rebuilt into joint trajectories at the segments' real timing by
        ``eigenmovements.inverse_transform``; every stretch of consecutive
        frames that the segments cover is then tracked by
        :func:`simulate_arm`.

        Parameters
        ----------
        X : list of ndarray of shape (n_segments_i, n_components)
            Per clip, its segment codes.
        segments : list of ndarray of int of shape (n_segments_i, 2)
            Per clip, ``(start, stop)`` of each segment (``EigenMovementPCA.segment``).
        eigenmovements : EigenMovementPCA
            The fitted eigenmovements the codes belong to; its channels are the
            arm's joints, in the order of ``arm.dof_names``.
        arm : ArmModel
            The simulated arm.
        frame_rate : float
            Frames per second of the clips.
        degrees : bool, default=False
            Whether the channels are in degrees (converted to radians for the
            arm); results are in radians either way.
        quantize : bool, default=True
            Execute the primitives (cluster centres) rather than the codes.
        **servo : dict
            ``kp``, ``kd`` and ``timestep`` of :func:`simulate_arm`.

        Returns
        -------
        simulations : list of ArmSimulation
            Per clip, the simulated motion on all its frames (NaN where no
            segment covers a frame).
        """
        check_is_fitted(self)
        codes = self._codes(X)
        if eigenmovements.n_features_in_ != arm.n_dof:
            raise ValueError(
                f"The eigenmovements have {eigenmovements.n_features_in_} channels but the arm "
                f"has {arm.n_dof} joints."
            )
        if quantize:
            codes = self._quantized(codes)
        targets = eigenmovements.inverse_transform(list(codes), segments)
        return [self._execute(t, arm, frame_rate, degrees, servo) for t in targets]

    @staticmethod
    def _execute(target, arm, frame_rate, degrees, servo):
        target = np.deg2rad(target) if degrees else target
        n_frames = len(target)
        fields = {
            name: np.full((n_frames, arm.n_dof), np.nan)
            for name in ("angles", "velocities", "torques")
        }
        tip = np.full((n_frames, 3), np.nan)
        for start, stop in _covered_runs(~np.isnan(target).any(axis=1)):
            if stop - start < 2:
                continue
            run = simulate_arm(target[start:stop], arm=arm, frame_rate=frame_rate, **servo)
            fields["angles"][start:stop] = run.angles
            fields["velocities"][start:stop] = run.velocities
            fields["torques"][start:stop] = run.torques
            tip[start:stop] = run.tip
        desired = np.where(np.isnan(fields["angles"]), np.nan, target)
        return ArmSimulation(np.arange(n_frames) / frame_rate, desired, tip=tip, **fields)
