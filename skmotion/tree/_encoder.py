"""MotionTreeEncoder: a motion tree as a vocabulary of poses; a clip becomes a histogram vector."""

from numbers import Integral, Real

import numpy as np
import scipy.sparse as sp
from sklearn.base import BaseEstimator
from sklearn.utils.validation import check_is_fitted

from skmotion.base import ClipFeatureMixin, MotionTags
from skmotion.tree._build import TREE_CONSTRAINTS, TreeParams
from skmotion.tree._build._clip_build import build_from_clips
from skmotion.tree._build._standardise import StackedClips, column_mean_std, standardise_in_place
from skmotion.tree._encoding._columns import (
    _existing,
    _int_list,
    _is_all,
    build_depth,
    feature_names,
)
from skmotion.tree._encoding._histograms import (
    feature_blocks,
    histogram_features,
    moment_features,
    node_variances,
    residual_features,
    second_order_features,
)
from skmotion.tree._encoding._routing import TreeRouter
from skmotion.tree._magnitude import check_magnitude, check_stacked_magnitude
from skmotion.tree._motion_tree import MotionTree
from skmotion.utils._clips import check_clips, stack_clips
from skmotion.utils._features import channel_names_in
from skmotion.utils._progress import say
from skmotion.utils._sklearn_compat import Interval, StrOptions, _fit_context

__all__ = ["MotionTreeEncoder"]

# "auto" gives a sparse matrix from this many occupancy and transition columns on.
_SPARSE_FROM = 1024
# transform's second magnitude check: the moments sum squares in training spreads
_SPREADS_OVERFLOW = "sums squares of the values in training spreads, which overflow float64"
# fit builds the tree from the caller's clips, without a stacked standardised copy of their
# frames, from this many frames on (float64 clips of two channels or more): the same tree to
# the bit, in about half the memory and a few more passes over the frames (docs/scaling.md)
_LEAN_FROM_FRAMES = 1 << 18


class MotionTreeEncoder(ClipFeatureMixin, BaseEstimator):
    """Encode clips as histograms of their frames over the nodes of a motion tree.

    ``fit`` builds a :class:`MotionTree` over all frames of all clips (no labels
    needed). Every layer of the tree partitions frame space, so each layer is a
    vocabulary of poses at one resolution, from two coarse ones near the root
    to many fine ones at the bottom. A clip becomes, per layer, the share of its
    frames in each node (occupancy), also over the halves, thirds, ... of the
    clip (a temporal pyramid: *when* a pose occurs), optionally with the shares
    of its steps from node to node (transitions), all raised to ``power``
    (0.5: the Hellinger map, which stabilises the variance of small shares),
    and, by default, where its frames sit within the nodes of two layers
    (residuals) and the mean and root mean square of each channel over the
    clip (moments). A linear classifier on these vectors recognises motions;
    :class:`~skmotion.recognition.MotionClassifier` is the measured chain in one
    estimator (markers scaled by blocks, every layer's occupancy, the means over a
    temporal pyramid, a logistic regression)::

        MotionClassifier(layout="kinect_v2")  # or make_pipeline(..., MotionTreeEncoder(), ...)

    Parameters
    ----------
    max_depth : int, default=8
        The deepest layer of the tree (root: layer 0). The tree is only built
        as deep as the deepest layer encoded (layer 3 with the defaults).
    min_samples_leaf : int, default=4
        A split is only made when both sides keep this many frames.
    split : {"median", "two_means", "min_error"}, default="median"
        How a node's frames are cut on their first principal axis (see
        :meth:`MotionTree.build`); the median gives balanced trees, whose
        layers make even vocabularies.
    layers : "all" or array-like of int, default=()
        The layers whose occupancy is encoded; ``"all"`` is every layer but
        the root (whose occupancy is always 1). Layers deeper than the tree
        are left out. None by default: in the measurements behind the
        defaults, occupancy added nothing to the residuals on any data set and
        cost accuracy on JapaneseVowels and the CMU windows (user guide).
    pyramid : array-like of int, default=(1, 2, 3)
        Temporal pyramid: for each ``p``, occupancy over each ``1/p`` of the
        clip (1: the whole clip).
    transition_layers : array-like of int, default=()
        Layers whose node-to-node steps are counted (``n_nodes ** 2`` columns
        each, so coarse layers).
    residual_layers : array-like of int, default=(1, 3)
        Layers whose nodes also report where the clip's frames sit within
        them: per node, the mean offset of the clip's frames from the node's
        mean (standardised units, ``n_nodes * n_channels`` dense columns per
        layer; a VLAD code), each layer's block scaled to unit norm. Occupancy
        alone loses this continuous detail.
    residual_order : {1, 2}, default=1
        2 adds, after the residuals, their second order: per node of each
        residual layer and channel, the mean over the clip's frames in the
        node of ``(z - mean) ** 2 / variance - 1`` (the node's variance from
        the training frames; a Fisher vector's variance terms), each layer's
        block power-normalised and scaled to unit norm. In the defaults study
        it raised the CV accuracy on JapaneseVowels (0.978 against 0.967) and
        tied on the other sets, a margin too small to double the residual
        columns by default (user guide).
    moments : {0, 1, 2}, default=2
        The clip's moments at the root, per channel, in units of the training
        frames (mean 0, standard deviation 1): 1 adds each channel's mean over
        the clip, 2 also its root mean square minus 1 (the square root of the
        root node's second-order Fisher-vector term), ``moments * n_channels``
        dense columns after all others, not scaled to unit norm. They keep
        where the clip sits and how much it moves, which the unit-norm
        residual blocks lose; in the study behind the defaults they lifted the
        CMU windows from 0.78 to 0.86 and held the other sets (user guide).
        0 leaves them out.
    moment_pyramid : array-like of int, default=(1,)
        The means also over each ``1/p`` of the clip, for each ``p`` (1: the
        whole clip), ``sum(moment_pyramid) * n_channels`` columns: a coarse
        trajectory of every channel, which says *when* the clip is where (the
        root mean square stays over the whole clip). ``(1, 2, 4)`` is what
        :class:`~skmotion.recognition.MotionClassifier` uses on skeletons
        (user guide, ``docs/recognition.md``).
    power : float, default=0.5
        Every histogram entry is raised to this power; 1 keeps the shares.
    standardize : bool, default=True
        Scale every channel to zero mean and unit variance (training frames)
        before the tree's principal axes are found.
    sparse_output : bool or "auto", default="auto"
        Return a ``scipy.sparse`` CSR matrix; ``"auto"`` does when the
        occupancy and transition columns (mostly zeros) number at least 1024.
        ``set_output(transform="pandas")`` needs dense output: it raises a
        ``ValueError`` otherwise (pandas has no efficient sparse frames for this).
    verbose : int, default=0
        0 is silent; 1 or more reports the tree's build on standard error.

    Attributes
    ----------
    tree_ : MotionTree
        The tree over all training frames (standardised).
    layers_ : ndarray of int
        The encoded layers.
    transition_layers_ : ndarray of int
        The layers whose transitions are encoded.
    residual_layers_ : ndarray of int
        The layers whose residuals are encoded.
    moment_center_, moment_scale_ : ndarray of shape (n_features_in_,)
        The training frames' mean and standard deviation (1 where it is 0),
        the units of the moments.
    center_, scale_ : ndarray of shape (n_features_in_,)
        The standardisation.
    n_features_out_ : int
        Columns of the output.
    n_features_in_ : int
        Number of channels.
    feature_names_in_ : ndarray of str
        Channel names, when fit saw a DataFrame with string columns.

    See Also
    --------
    MotionTreeHMM : the same tree with transition graphs, for decoding and generation.

    Notes
    -----
    Routing is one compiled walk of all frames of all clips together, each
    frame down its own path (:class:`~skmotion.tree._encoding.TreeRouter`, the
    standardisation folded into the splits), and the histograms are one sparse
    matrix whose duplicate entries sum (one compiled pass into a dense array with
    ``sparse_output=False``): no Python step per clip or frame. The defaults come from a
    study over several data sets (user guide, ``docs/motion-database.md``).

    Memory: from 2**18 frames on (float64 clips of two channels or more),
    ``fit`` builds the tree from the clips themselves, read and standardised a
    block at a time, with each child of the root built in a copy of its own
    frames: the same tree to the bit as over a stacked standardised copy of all
    frames (what smaller fits make), in about half that copy's memory besides
    the caller's clips (user guide, ``docs/scaling.md``).

    Examples
    --------
    >>> from sklearn.linear_model import LogisticRegression
    >>> from sklearn.pipeline import make_pipeline
    >>> from skmotion.datasets import make_motions
    >>> from skmotion.tree import MotionTreeEncoder
    >>> data = make_motions(n_clips_per_class=4, classes=["walk", "jump"], random_state=0)
    >>> X = [clip[:, 6:] for clip in data.clips]
    >>> encoder = MotionTreeEncoder(max_depth=3, layers="all", pyramid=[1, 2], residual_layers=[1])
    >>> encoder = encoder.fit(X)
    >>> encoder.transform(X).shape, encoder.get_feature_names_out()[:2].tolist()
    ((8, 282), ['layer1_node0_part1of1', 'layer1_node1_part1of1'])
    >>> model = make_pipeline(MotionTreeEncoder(), LogisticRegression()).fit(X, data.target)
    >>> model.score(X, data.target)
    1.0
    """

    _parameter_constraints = {
        "max_depth": [Interval(Integral, 1, None, closed="left")],
        "min_samples_leaf": TREE_CONSTRAINTS["min_samples_leaf"],
        "split": TREE_CONSTRAINTS["split"],
        "layers": [StrOptions({"all"}), "array-like"],
        "pyramid": ["array-like"],
        "transition_layers": ["array-like"],
        "residual_layers": ["array-like"],
        "residual_order": [Interval(Integral, 1, 2, closed="both")],
        "moments": [Interval(Integral, 0, 2, closed="both")],
        "moment_pyramid": ["array-like"],
        "power": [Interval(Real, 0, 1, closed="right")],
        "standardize": ["boolean"],
        "sparse_output": ["boolean", StrOptions({"auto"})],
        "verbose": ["verbose"],
    }
    _motion_tags = MotionTags(output_kind="table")

    def __init__(
        self,
        *,
        max_depth=8,
        min_samples_leaf=4,
        split="median",
        layers=(),
        pyramid=(1, 2, 3),
        transition_layers=(),
        residual_layers=(1, 3),
        residual_order=1,
        moments=2,
        moment_pyramid=(1,),
        power=0.5,
        standardize=True,
        sparse_output="auto",
        verbose=0,
    ):
        self.max_depth = max_depth
        self.min_samples_leaf = min_samples_leaf
        self.split = split
        self.layers = layers
        self.pyramid = pyramid
        self.transition_layers = transition_layers
        self.residual_layers = residual_layers
        self.residual_order = residual_order
        self.moments = moments
        self.moment_pyramid = moment_pyramid
        self.power = power
        self.standardize = standardize
        self.sparse_output = sparse_output
        self.verbose = verbose

    @_fit_context(prefer_skip_nested_validation=True)
    def fit(self, X, y=None):
        """Build the tree over all frames of all clips.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_channels)
            Training clips (or a 3-D array, or a ``(clip, frame)`` DataFrame).
        y : None
            Ignored (the tree sees no labels).

        Returns
        -------
        self : MotionTreeEncoder
            The fitted encoder.
        """
        pyramid = _int_list("pyramid", self.pyramid, low=1)
        if not pyramid:
            raise ValueError("pyramid must name at least one level, e.g. (1,) or (1, 2, 3).")
        moment_pyramid = _int_list("moment_pyramid", self.moment_pyramid, low=1)
        if self.moments and not moment_pyramid:
            raise ValueError("moment_pyramid must name at least one level, e.g. (1,) or (1, 2, 4).")
        clips = check_clips(X, estimator=self, reset=True)
        check_magnitude(clips, self)
        stacked = StackedClips(clips)
        lean = (
            stacked.n_frames >= max(_LEAN_FROM_FRAMES, stacked.n_channels)
            and stacked.n_channels > 1
            and all(clip.dtype == np.float64 for clip in clips)
        )
        frames = None if lean else stack_clips(clips)[0]
        # no centred copy; over the clips themselves in the lean fit (the same doubles)
        self.moment_center_, spread = stacked.mean_std() if lean else column_mean_std(frames)
        self.moment_scale_ = np.where(spread > 0, spread, 1.0)
        self.center_ = np.zeros(stacked.n_channels)
        self.scale_ = np.ones(stacked.n_channels)
        if self.standardize:
            self.center_, self.scale_ = self.moment_center_, self.moment_scale_
        say(self.verbose, f"MotionTreeEncoder: building the tree over {stacked.n_frames:,} frames")
        depth = build_depth(
            self.max_depth, self.layers, self.transition_layers, self.residual_layers
        )
        params = TreeParams(
            max_depth=depth,
            min_samples_leaf=self.min_samples_leaf,
            split=self.split,
            covariance_type="spherical",  # routing uses the splits only
        )
        stacked.center, stacked.scale = self.center_, self.scale_
        if lean:  # the clips read a block at a time, standardised there: no stacked copy
            self.tree_ = build_from_clips(stacked, params)
            z_blocks = stacked.blocks
        else:  # standardised over the stacked copy itself, and the tree built in it
            z = standardise_in_place(frames, self.center_, self.scale_)
            self.tree_ = MotionTree.from_params(z, params, copy=False)
            z_blocks = _array_blocks(z)
        bottom = self.tree_.n_layers - 1
        wanted = range(1, bottom + 1) if _is_all(self.layers) else _int_list("layers", self.layers)
        self.layers_ = np.array(sorted({v for v in wanted if v <= bottom}), dtype=np.intp)
        self.transition_layers_ = _existing("transition_layers", self.transition_layers, bottom)
        self.residual_layers_ = _existing("residual_layers", self.residual_layers, bottom)
        if not (
            len(self.layers_)
            or len(self.transition_layers_)
            or len(self.residual_layers_)
            or self.moments
        ):
            raise ValueError(
                f"None of layers={self.layers!r}, transition_layers={self.transition_layers!r}, "
                f"residual_layers={self.residual_layers!r} exists in the tree (layers 0 to "
                f"{bottom}) and moments=0; nothing to encode."
            )
        self._pyramid = pyramid
        self._moment_pyramid = moment_pyramid
        self._router = TreeRouter(self.tree_, self.center_, self.scale_)
        self._blocks = feature_blocks(
            self.layers_, self.tree_.n_nodes, pyramid, self.transition_layers_
        )
        self._residual_means = [self.tree_.means(layer) for layer in self.residual_layers_]
        self._residual_variances = []
        if self.residual_order == 2 and len(self.residual_layers_):
            # routed as transform routes them (the raw frames), a group of clips at a time:
            # no second stacked copy of the frames
            nodes = self._router.route_clips(clips, self.residual_layers_)
            self._residual_variances = node_variances(z_blocks, nodes, self._residual_means)
        orders = 2 if self._residual_variances else 1
        n_residual = self.tree_.n_nodes[self.residual_layers_].sum() * orders
        n_moments = (sum(moment_pyramid) + self.moments - 1) if self.moments else 0
        self.n_features_out_ = sum(width for *_, width in self._blocks) + int(
            (n_residual + n_moments) * self.n_features_in_
        )
        return self

    def transform(self, X):
        """Histogram vector of each clip.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_channels)

        Returns
        -------
        X_new : ndarray or scipy.sparse.csr_matrix of shape (n_clips, n_features_out_)
            Or a DataFrame after ``set_output(transform="pandas")`` (dense output only).
        """
        if "tree_" not in self.__dict__:  # sklearn's check costs more than a one-clip encoding
            check_is_fitted(self, "tree_")
        clips = check_clips(X, estimator=self)
        if len(clips) == 1:  # transform only reads the frames: one clip needs no stacked copy
            frames, offsets = clips[0], np.array([0, len(clips[0])], dtype=np.intp)
        else:
            frames, offsets = stack_clips(clips)
        frames = np.asarray(frames, dtype=np.float64)  # float32 clips: converted once, here
        routed, residual_columns = self._transform_plan()
        # the raw values, then in training spreads (one compiled pass over all frames for
        # both; each clip's only when it fails, to name the clip and channel)
        checks = [(0.0, 1.0, None), (self.moment_center_, self.moment_scale_, _SPREADS_OVERFLOW)]
        check_stacked_magnitude(frames, offsets, self, checks)
        sparse = self._sparse()
        if sparse and self._output_config() == "pandas":
            raise ValueError(
                f"set_output(transform='pandas') needs dense output, but this encoder gives "
                f"{self.n_features_out_} columns as a sparse matrix: set sparse_output=False."
            )
        # moments alone need no routing
        nodes = self._router.route(frames, routed) if len(routed) else None
        residual_nodes = None
        if len(self.residual_layers_):
            residual_nodes = nodes[:, residual_columns]
        parts = []
        if self._blocks:
            parts.append(
                histogram_features(
                    nodes, offsets, routed, self._blocks, self.power, dense=not sparse
                )
            )
        if len(self.residual_layers_):
            parts.append(
                residual_features(
                    frames,
                    residual_nodes,
                    offsets,
                    self._residual_means,
                    self.center_,
                    self.scale_,
                    self.power,
                )
            )
        if self._residual_variances:
            parts.append(
                second_order_features(
                    frames,
                    residual_nodes,
                    offsets,
                    self._residual_means,
                    self._residual_variances,
                    self.center_,
                    self.scale_,
                    self.power,
                )
            )
        if self.moments:
            parts.append(
                moment_features(
                    frames,
                    offsets,
                    self.moment_center_,
                    self.moment_scale_,
                    self.moments,
                    self._moment_pyramid,
                )
            )
        if sparse:
            return sp.hstack(parts, format="csr") if len(parts) > 1 else sp.csr_matrix(parts[0])
        dense = [p.toarray() if sp.issparse(p) else p for p in parts]
        table = dense[0] if len(dense) == 1 else np.concatenate(dense, axis=1)
        return self._wrap_table(table, clips)

    def _transform_plan(self):
        """What transform works out once per fit (on its first call, as on one clip its
        making is felt): the layers routed (increasing), the residual layers' columns among
        them."""
        plan = self.__dict__.get("_plan")
        if plan is None or len(plan) != 3 or plan[0] is not self.tree_:  # or an older plan
            layer_sets = (self.layers_, self.transition_layers_, self.residual_layers_)
            routed = np.array(sorted({int(v) for layers in layer_sets for v in layers}), np.intp)
            columns = np.searchsorted(routed, self.residual_layers_)
            if len(columns) and (np.diff(columns) == 1).all():  # a view of the nodes, no copy
                columns = slice(int(columns[0]), int(columns[-1]) + 1)
            plan = (self.tree_, routed, columns)
            self._plan = plan
        return plan[1:]

    def _sparse(self):
        if self.sparse_output == "auto":
            return sum(width for *_, width in self._blocks) >= _SPARSE_FROM
        return bool(self.sparse_output)

    def get_feature_names_out(self, input_features=None):
        """Column names: each names its layer, node and pyramid cell (or step, or channel).

        ``layer<l>_node<k>_part<c>of<p>`` (occupancy), ``layer<l>_node<a>_to_node<b>``
        (transitions), ``layer<l>_node<k>_<channel>`` (residuals),
        ``layer<l>_node<k>_var_<channel>`` (their second order), ``mean_<channel>``
        (``mean_<channel>_part<c>of<p>`` over a part of the clip) and ``rms_<channel>``
        (moments).

        Parameters
        ----------
        input_features : array-like of str, default=None
            Input channel names (for the residual columns).

        Returns
        -------
        feature_names_out : ndarray of str
        """
        check_is_fitted(self)
        return feature_names(
            self._blocks,
            self.residual_layers_,
            self.tree_.n_nodes,
            channel_names_in(self, input_features),
            second_order=bool(self._residual_variances),
            moments=self.moments,
            moment_pyramid=self._moment_pyramid,
        )


def _array_blocks(z):
    """``StackedClips.blocks`` of an array: its consecutive blocks of ``rows`` rows."""
    return lambda rows: ((start, z[start : start + rows]) for start in range(0, len(z), rows))
