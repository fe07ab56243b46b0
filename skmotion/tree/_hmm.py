"""MotionTreeHMM: recognise, decode and predict motion clips with a motion tree and its graphs.

This module holds the estimator's parameters and ``fit`` (the tree, the graphs,
the temperature); its other methods come from mixins, one module per concern:
``_hmm_recognition`` (decoding, ``predict``, ``predict_proba``, ...),
``_hmm_features`` (``transform``, ``fit_transform``), ``_hmm_over_time``
(``decode``, ``predict_next``, ``predict_proba_windows``, ``plan``) and
``_hmm_live`` (``partial_fit``, ``stream``, ``sample``).
"""

from numbers import Integral, Real

import numpy as np
from sklearn.base import BaseEstimator, ClassifierMixin
from sklearn.utils.multiclass import check_classification_targets
from sklearn.utils.validation import column_or_1d

from skmotion.base import ClipFeatureMixin, MotionTags
from skmotion.tree._calibration import fit_temperature, held_out_folds, per_frame
from skmotion.tree._decode import NODE_PRIORS
from skmotion.tree._gaussian import COVARIANCE_TYPES
from skmotion.tree._hmm_features import ClassScoreFeaturesMixin
from skmotion.tree._hmm_live import LiveDatabaseMixin
from skmotion.tree._hmm_over_time import OverTimeMixin
from skmotion.tree._hmm_recognition import RecognitionMixin
from skmotion.tree._motion_tree import MotionTree
from skmotion.tree._split import SPLIT_CRITERIA
from skmotion.tree._transitions import TransitionGraphs
from skmotion.utils._clips import check_clips, stack_clips
from skmotion.utils._labels import check_label_types
from skmotion.utils._progress import say
from skmotion.utils._sklearn_compat import Interval, StrOptions, _fit_context

__all__ = ["MotionTreeHMM"]


class MotionTreeHMM(
    RecognitionMixin,
    ClassScoreFeaturesMixin,
    OverTimeMixin,
    LiveDatabaseMixin,
    ClipFeatureMixin,
    ClassifierMixin,
    BaseEstimator,
):
    """Recognise motion clips with a binary tree of frame clusters and node transition graphs.

    Yamane, Yamaguchi and Nakamura's motion database: ``fit`` builds a
    :class:`MotionTree` over all frames of all clips and counts, at every layer,
    the transitions between the nodes of consecutive frames: one global graph
    and one graph per class (or per clip). A clip's *generation probability*
    under a graph sums the ``n_paths`` best node sequences found by the
    top-down beam Viterbi (:func:`beam_decode`); ``predict`` picks the class
    whose graph generates the clip with the highest probability, and
    ``transform`` gives those probabilities per scored layer, per frame and
    normalised over the classes, as features for a model stacked on it.

    Parameters
    ----------
    max_depth : int, default=8
        The deepest layer of the tree (the root is layer 0); None for no limit
        (the paper's choice). Decoding costs one pass per layer.
    min_samples_split : int, default=2
        A node with fewer frames is not split.
    min_samples_leaf : int, default=4
        A split is only made when both sides keep this many frames (the
        paper's databases use 16).
    split : {"two_means", "median", "min_error"}, default="two_means"
        How a node's projections on its first principal axis are cut: 1-D
        2-means, the median (balanced trees), or Kittler-Illingworth
        minimum-error thresholding (the paper's, which cuts off small tails
        and grows deep, unbalanced trees). The defaults of ``split``,
        ``max_depth``, ``min_samples_leaf`` and ``score_layers`` were the most
        accurate candidates on every development data set (the user guide's
        table); :data:`PAPER_SETTINGS` gives the paper's.
    covariance_type : {"diag", "full", "spherical"}, default="diag"
        The covariance estimator of each node; ``"full"`` is Ledoit-Wolf shrunk.
    reg_covar : float, default=1e-6
        Added to every variance, as a fraction of the mean variance of all frames.
    graph : {"class", "clip"}, default="class"
        Classify by one transition graph per class, or by one graph per
        training clip (a clip is given the label of the training clip whose
        graph generates it best, as in the paper).
    node_prior : {"layer", "graph"}, default="layer"
        Where the uniform prior ``P(k)`` of ``Ps(k | x)`` is spread: over all
        nodes of the layer, or over the nodes the graph's clips visit (the
        paper's choice for clip graphs). With ``"graph"``, ``Ps`` is normalised
        within each graph, so a graph whose clips visit few nodes explains any
        frame with probability near 1 and classification rests on transitions
        alone; on the built-in synthetic data (subject-wise CV) that gave 0-14%
        accuracy with minimum-error splits against 95-100% for ``"layer"``,
        where how well a graph's nodes fit the frames counts too. See the user
        guide.
    smoothing : float, default=1.0
        Pseudo-transitions added to every row of every transition graph, spread
        evenly over the layer's nodes (Lidstone smoothing); see
        :class:`TransitionGraphs`.
    n_paths : int, default=3
        The beam: nodes kept per frame at each layer of the top-down search,
        and the number of best sequences summed into the generation probability.
    layer : int, default=None
        The layer to classify at (negative counts from the bottom); None for
        the bottom layer. Upper layers are faster and coarser.
    score_layers : int or "all", default="all"
        How many layers, ending at ``layer``, classify together: a clip's score
        under a graph is the product of its generation probabilities at each
        of them (a product of experts over the tree's resolutions; the paper
        classifies at one layer). Coarse layers are robust and fine ones
        precise; together they vary less with the tree's depth. At most layers
        1 to ``layer`` are used (``"all"``: every one of them), so a grid over
        ``max_depth`` can share one value. The scored layers are searched on
        the way down anyway: each one adds a pass over its candidates per
        graph, not another search.
    standardize : bool, default=True
        Scale every channel to zero mean and unit variance (statistics of the
        training frames; a constant channel is only centred) before building
        the tree, whose principal axes otherwise follow the channels with the
        largest units. Node means reported by ``predict_next`` are in the
        input's units either way.
    calibration_cv : int or None, default=3
        Folds of the internal cross-validation that fits the temperature of
        ``predict_proba`` and gives ``fit_transform``'s out-of-fold rows
        (stratified, each class's clips cut in the order given into contiguous
        blocks, so overlapping windows of one take stay mostly in one fold; at
        most the smallest class's clip count; by group when ``fit`` gets
        ``groups``). The tree is built once on all frames (it sees no labels);
        each fold recounts the graphs without its held-out clips and scores
        them. None, or a smallest class of one clip, keeps ``temperature_ = 1``.
        Labels (``predict``) never depend on it.
    verbose : int, default=0
        0 is silent; 1 or more reports the stages of ``fit`` (tree, graphs,
        calibration folds) on standard error.
    n_jobs : int, default=None
        Jobs over groups of clips (and their graphs) when decoding; None means
        1 unless in a ``joblib.parallel_config`` context. Results do not
        depend on it.

    Attributes
    ----------
    tree_ : MotionTree
        The tree over all training frames.
    global_graph_ : TransitionGraphs
        The global transition graph (one graph of all clips), for ``decode``
        and ``predict_next``.
    graphs_ : TransitionGraphs
        The graphs used to classify: one per class, or one per training clip.
    graph_classes_ : ndarray of shape (n_graphs,)
        Index in ``classes_`` of each graph of ``graphs_``.
    classes_ : ndarray of shape (n_classes,)
        The class labels.
    layer_ : int
        The (non-negative) layer used for classification.
    score_layers_ : ndarray of int
        The layers whose generation probabilities are multiplied to classify
        (``[0]`` for a tree of one layer).
    center_, scale_ : ndarray of shape (n_features_in_,)
        The standardisation (zeros and ones when ``standardize=False``).
    n_layers_ : int
        Number of layers of the tree.
    n_nodes_ : ndarray of shape (n_layers_,)
        Number of nodes in each layer.
    temperature_ : float
        Divides the per-frame log generation probabilities before the softmax
        of ``predict_proba`` (fitted by log loss on held-out folds).
    log_node_weights_ : ndarray of shape (n_nodes_[layer_],)
        Log share of the training frames in each node of ``layer_``: the
        mixing weights of ``novelty_score``'s density.
    n_features_in_ : int
        Number of channels.
    feature_names_in_ : ndarray of str
        Channel names, when fit saw a DataFrame with string columns.

    See Also
    --------
    MotionTree : the tree data structure.
    MotionTreeEncoder : the same tree as a vocabulary of poses, features for a linear model.
    TransitionGraphs : the node transition graphs.

    Notes
    -----
    ``Ps(k | x) = Po(x | k) / sum_j Po(x | j)`` with ``j`` over the nodes of the
    prior; everything is computed in log space, so clips of any length give
    finite scores. Building costs O(N log N) for N frames when the tree is
    about ``log N`` deep.

    With ``node_prior="layer"`` the beams are searched once per clip on the
    global graph, and each class's (or clip's) graph runs its K-best passes at
    the scored layers on the candidates that leaves; this shared beam gave the
    same accuracy as one search per graph in our measurements, for a fraction
    of the work. The normaliser of ``Ps`` is then the same for every graph, so
    ``predict``, ``predict_proba`` and ``decode`` skip it; ``score_samples``
    computes it (every node's density on every frame). Decoding a clip of M
    frames costs ``O(M n_paths^2)`` per layer. See the user guide
    (``docs/motion-database.md``) for the measurements behind these choices.

    References
    ----------
    K. Yamane, Y. Yamaguchi and Y. Nakamura, "Human motion database with a
    binary tree and node transition graphs", Autonomous Robots 30(1), 2011.

    Examples
    --------
    >>> from skmotion.datasets import make_motions
    >>> from skmotion.tree import MotionTreeHMM
    >>> data = make_motions(n_clips_per_class=4, classes=["walk", "jump"], random_state=0)
    >>> X = [clip[:, 6:] for clip in data.clips]   # joint angles, without the root
    >>> model = MotionTreeHMM(max_depth=4).fit(X, data.target)
    >>> model.n_layers_, model.score(X, data.target)
    (5, 1.0)
    """

    _parameter_constraints = {
        "max_depth": [Interval(Integral, 0, None, closed="left"), None],
        "min_samples_split": [Interval(Integral, 2, None, closed="left")],
        "min_samples_leaf": [Interval(Integral, 1, None, closed="left")],
        "split": [StrOptions(set(SPLIT_CRITERIA))],
        "covariance_type": [StrOptions(set(COVARIANCE_TYPES))],
        "reg_covar": [Interval(Real, 0, None, closed="neither")],
        "graph": [StrOptions({"class", "clip"})],
        "node_prior": [StrOptions(set(NODE_PRIORS))],
        "smoothing": [Interval(Real, 0, None, closed="neither")],
        "n_paths": [Interval(Integral, 1, None, closed="left")],
        "layer": [Interval(Integral, None, None, closed="neither"), None],
        "score_layers": [Interval(Integral, 1, None, closed="left"), StrOptions({"all"})],
        "standardize": ["boolean"],
        "calibration_cv": [Interval(Integral, 2, None, closed="left"), None],
        "verbose": ["verbose"],
        "n_jobs": [Integral, None],
    }

    def __init__(
        self,
        *,
        max_depth=8,
        min_samples_split=2,
        min_samples_leaf=4,
        split="two_means",
        covariance_type="diag",
        reg_covar=1e-6,
        graph="class",
        node_prior="layer",
        smoothing=1.0,
        n_paths=3,
        layer=None,
        score_layers="all",
        standardize=True,
        calibration_cv=3,
        verbose=0,
        n_jobs=None,
    ):
        self.max_depth = max_depth
        self.min_samples_split = min_samples_split
        self.min_samples_leaf = min_samples_leaf
        self.split = split
        self.covariance_type = covariance_type
        self.reg_covar = reg_covar
        self.graph = graph
        self.node_prior = node_prior
        self.smoothing = smoothing
        self.n_paths = n_paths
        self.layer = layer
        self.score_layers = score_layers
        self.standardize = standardize
        self.calibration_cv = calibration_cv
        self.verbose = verbose
        self.n_jobs = n_jobs

    _motion_tags = MotionTags(output_kind="table")  # transform: per-layer class scores

    @_fit_context(prefer_skip_nested_validation=True)
    def fit(self, X, y, groups=None):
        """Build the tree, count the transition graphs and fit the temperature.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_channels)
            Training clips (or a 3-D array, or a ``(clip, frame)`` DataFrame).
        y : array-like of shape (n_clips,)
            One label per clip (any hashable type, strings included).
        groups : array-like of shape (n_clips,), default=None
            Group of each clip (subject, take, recording): the folds of the
            internal cross-validation (``calibration_cv``) then never split a
            group. Without it the folds are contiguous blocks of each class's
            clips in the order given. Labels do not depend on it.

        Returns
        -------
        self : MotionTreeHMM
            The fitted model.
        """
        self._fit(X, y, groups)
        return self

    def _fit(self, X, y, groups):
        """``fit``; returns the validated clips and their held-out per-layer class scores."""
        clips = check_clips(X, estimator=self, reset=True)
        y = column_or_1d(np.asarray(check_label_types(y)), warn=True)
        if len(y) != len(clips):
            raise ValueError(
                f"y has {len(y)} labels but X holds {len(clips)} clips; give one label per clip."
            )
        check_classification_targets(y)
        self.classes_, y_index = np.unique(y, return_inverse=True)
        frames, offsets = stack_clips(clips)
        self.center_ = np.zeros(frames.shape[1])
        self.scale_ = np.ones(frames.shape[1])
        if self.standardize:
            self.center_ = frames.mean(axis=0)
            spread = frames.std(axis=0)
            self.scale_ = np.where(spread > 0, spread, 1.0)
            frames = (frames - self.center_) / self.scale_
        say(self.verbose, f"MotionTreeHMM: building the tree over {len(frames):,} frames")
        tree = MotionTree.build(
            frames,
            max_depth=self.max_depth,
            min_samples_split=self.min_samples_split,
            min_samples_leaf=self.min_samples_leaf,
            split=self.split,
            covariance_type=self.covariance_type,
            reg_covar=self.reg_covar,
        )
        self.layer_ = tree.check_layer(-1 if self.layer is None else self.layer)
        n_scored = (
            self.layer_ if self.score_layers == "all" else min(self.score_layers, self.layer_)
        )
        self.score_layers_ = (
            np.arange(self.layer_ - n_scored + 1, self.layer_ + 1)
            if self.layer_
            else np.zeros(1, int)
        )
        say(self.verbose, f"MotionTreeHMM: {tree.n_layers} layers; counting the transition graphs")
        labels = list(tree.iter_apply(frames))
        self.global_graph_, self.graphs_, self.graph_classes_ = self._count_graphs(
            tree, labels, offsets, y_index
        )
        self.tree_ = tree
        self.n_layers_ = tree.n_layers
        self.n_nodes_ = tree.n_nodes
        self._set_node_weights()
        folds = held_out_folds(y_index, groups, self.calibration_cv)
        self.temperature_, log_prob = 1.0, None
        if folds is not None:
            totals, log_prob = self._held_out_scores(clips, labels, offsets, y_index, folds)
            self.temperature_ = fit_temperature(per_frame(totals, np.diff(offsets)), y_index)
        return clips, log_prob

    def _set_node_weights(self):
        """``log_node_weights_``: each node's share of the frames at ``layer_`` (novelty_score)."""
        visits = self.global_graph_.visits(self.layer_)[0]
        with np.errstate(divide="ignore"):
            self.log_node_weights_ = np.log(visits / visits.sum())

    def _count_graphs(self, tree, labels, offsets, y_index):
        """The global graph, the classifying graphs and the class of each, from routed frames."""
        n_clips = len(offsets) - 1
        global_graph = TransitionGraphs.count(
            labels,
            tree.n_nodes,
            offsets=offsets,
            graph_of_clip=np.zeros(n_clips, dtype=np.intp),
            n_graphs=1,
            smoothing=self.smoothing,
        )
        if self.graph == "class":
            graph_of_clip, graph_classes = y_index, np.arange(len(self.classes_))
        else:
            graph_of_clip, graph_classes = np.arange(n_clips), y_index
        graphs = TransitionGraphs.count(
            labels,
            tree.n_nodes,
            offsets=offsets,
            graph_of_clip=graph_of_clip,
            n_graphs=len(graph_classes),
            smoothing=self.smoothing,
        )
        return global_graph, graphs, graph_classes
