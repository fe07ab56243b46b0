"""MotionTreeHMM: recognise, decode and predict motion clips with a motion tree and its graphs.

The estimator, whole: ``fit`` (the tree, the graphs, the temperature), the
class-score features (``transform``, ``fit_transform``), recognition
(``predict``, ``predict_proba``, ``score_samples``, ``novelty_score``, ...),
the answers over time (``decode``, ``predict_next``, ``predict_proba_windows``,
``plan``) and the live database (``partial_fit``, ``stream``, ``sample``). The
work on arrays is in free functions: the decoder (``tree/_decoder``), the
scores' calibration and features (``_calibration``), the graphs' counts
(``_transitions``), one ``partial_fit`` step (``tree/_growth``), the streams
(``tree/_online``) and sampling (``_synthesis``).
"""

from numbers import Integral, Real

import numpy as np
from sklearn.base import BaseEstimator, ClassifierMixin
from sklearn.utils import Bunch
from sklearn.utils.validation import check_is_fitted

from skmotion.base import ClipFeatureMixin, MotionTags
from skmotion.tree._build import TREE_CONSTRAINTS, TreeParams
from skmotion.tree._build._standardise import column_mean_std, standardise_in_place
from skmotion.tree._calibration import (
    class_score_features,
    class_score_names,
    class_totals,
    fit_temperature,
    held_out_folds,
    layer_class_scores,
    log_softmax_rows,
    mixture_novelty,
    next_node_probabilities,
    per_frame,
)
from skmotion.tree._decoder import NODE_PRIORS, decode_clips
from skmotion.tree._growth import (
    Graphs,
    LiveDatabase,
    check_growth_params,
    grow,
    regraph,
    union_classes,
)
from skmotion.tree._magnitude import SCORE_LIMIT, check_magnitude
from skmotion.tree._motion_tree import MotionTree
from skmotion.tree._online import MotionStream, OnlineMotionStream
from skmotion.tree._transitions import count_database_graphs
from skmotion.utils._clips import check_clips, stack_clips
from skmotion.utils._labels import check_clip_labels, check_label_types
from skmotion.utils._progress import progress, say
from skmotion.utils._sklearn_compat import Interval, StrOptions, _fit_context
from skmotion.utils._validation import check_int

__all__ = ["MotionTreeHMM"]

_TREE = TreeParams()  # the build's defaults are the tree's measured ones


class MotionTreeHMM(ClipFeatureMixin, ClassifierMixin, BaseEstimator):
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
    max_depth : int, default=12
        The deepest layer of the tree (the root is layer 0); None for no limit
        (the paper's choice). Decoding costs one pass per layer. Deep trees
        recognise people never seen in training best: on MSRC-12 (grouped
        cross-validation over the training people) depth 6, 8, 10 and 12
        reached 0.66, 0.79, 0.83 and 0.84, and 0.85 at depth 12 with
        ``min_samples_leaf=8`` (the user guide's "The measured defaults").
    min_samples_split : int, default=2
        A node with fewer frames is not split.
    min_samples_leaf : int, default=8
        A split is only made when both sides keep this many frames (the
        paper's databases use 16).
    split : {"two_means", "median", "min_error"}, default="two_means"
        How a node's projections on its first principal axis are cut: 1-D
        2-means, the median (balanced trees), or Kittler-Illingworth
        minimum-error thresholding (the paper's, which cuts off small tails
        and grows deep, unbalanced trees). The defaults of ``split`` and
        ``score_layers`` were the most accurate candidates on every
        development data set, those of ``max_depth`` and ``min_samples_leaf``
        by far the most accurate on people never seen in training (MSRC-12),
        at a small cost on JapaneseVowels and CMU windows (the user guide's
        tables); :data:`PAPER_SETTINGS` gives the paper's.
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
        **TREE_CONSTRAINTS,
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
        max_depth=_TREE.max_depth,
        min_samples_split=_TREE.min_samples_split,
        min_samples_leaf=_TREE.min_samples_leaf,
        split=_TREE.split,
        covariance_type=_TREE.covariance_type,
        reg_covar=_TREE.reg_covar,
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
        check_magnitude(clips, self)
        y = check_clip_labels(check_label_types(y), len(clips))
        self.classes_, y_index = np.unique(y, return_inverse=True)
        frames, offsets = stack_clips(clips)
        self.center_ = np.zeros(frames.shape[1])
        self.scale_ = np.ones(frames.shape[1])
        if self.standardize:
            # the mean and spread, then the standardisation, over the stacked copy itself
            self.center_, spread = column_mean_std(frames)
            self.scale_ = np.where(spread > 0, spread, 1.0)
            standardise_in_place(frames, self.center_, self.scale_)
        say(self.verbose, f"MotionTreeHMM: building the tree over {len(frames):,} frames")
        tree = MotionTree.from_params(frames, TreeParams.of(self), copy=False)
        say(self.verbose, f"MotionTreeHMM: {tree.n_layers} layers; counting the transition graphs")
        labels = list(tree.iter_apply(frames))
        self._set_tree(tree)
        self._set_graphs(self._count_graphs(tree, labels, offsets, y_index, self.classes_))
        folds = held_out_folds(y_index, groups, self.calibration_cv)
        self.temperature_, log_prob = 1.0, None
        if folds is not None:
            totals, log_prob = self._held_out_scores(clips, labels, offsets, y_index, folds)
            self.temperature_ = fit_temperature(per_frame(totals, np.diff(offsets)), y_index)
        return clips, log_prob

    def _set_tree(self, tree):
        """``tree_`` and what follows from it: the layers classified at, the layer sizes."""
        self.tree_ = tree
        self.layer_ = tree.check_layer(-1 if self.layer is None else self.layer)
        n_scored = (
            self.layer_ if self.score_layers == "all" else min(self.score_layers, self.layer_)
        )
        self.score_layers_ = (
            np.arange(self.layer_ - n_scored + 1, self.layer_ + 1)
            if self.layer_
            else np.zeros(1, int)
        )
        self.n_layers_ = tree.n_layers
        self.n_nodes_ = tree.n_nodes

    def _count_graphs(self, tree, labels, offsets, y_index, classes):
        """The database's :class:`~skmotion.tree._growth._step.Graphs` from routed frames."""
        global_graph, graphs, graph_classes = count_database_graphs(
            tree,
            labels,
            offsets,
            y_index,
            n_classes=len(classes),
            per_clip=self.graph == "clip",
            smoothing=self.smoothing,
        )
        return Graphs(global_graph, graphs, graph_classes, classes)

    def _set_graphs(self, graphs):
        """The graphs' fitted attributes, and the node weights of ``novelty_score``."""
        self.global_graph_, self.graphs_ = graphs.global_graph, graphs.graphs
        self.graph_classes_, self.classes_ = graphs.graph_classes, graphs.classes
        visits = self.global_graph_.visits(self.layer_)[0]
        with np.errstate(divide="ignore"):
            self.log_node_weights_ = np.log(visits / visits.sum())

    @_fit_context(prefer_skip_nested_validation=True)
    def fit_transform(self, X, y, groups=None):
        """Fit, and return the training clips' class-score features, out of fold.

        A training clip's transition graphs include its own transitions, so its
        ``transform`` scores are optimistic (its class looks surer than it will
        on new clips) and a model stacked on them learns to trust them too much.
        As sklearn's ``StackingClassifier`` does with ``cross_val_predict``, each
        row here comes from the internal cross-validation's graphs counted
        without the clip's fold (the folds of ``calibration_cv`` and ``groups``;
        the tree, built without labels, is shared). So ``fit_transform(X, y)``
        differs from ``fit(X, y).transform(X)``; ``transform`` of new clips uses
        the graphs of all training clips. When no folds can be made
        (``calibration_cv=None``, a class of one clip) the rows are in-sample.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_channels)
        y : array-like of shape (n_clips,)
        groups : array-like of shape (n_clips,), default=None
            See ``fit``.

        Returns
        -------
        features : ndarray of shape (n_clips, n_scored_layers * n_classes) or DataFrame
            See ``transform``.
        """
        clips, log_prob = self._fit(X, y, groups)
        if log_prob is None:
            log_prob = self._layer_log_probs(clips)
        return self._wrap_table(class_score_features(log_prob, [len(c) for c in clips]), clips)

    def _held_out_scores(self, clips, labels, offsets, y_index, folds):
        """Scores of every clip by graphs counted without its fold (calibration and stacking).

        The tree is shared (it is built without labels); each fold recounts the
        graphs from its training clips only and scores its held-out clips.
        Returns the class totals ``(n_clips, n_classes)`` (as ``_class_log_probs``)
        and the per-layer scores ``(n_clips, n_classes, n_scored)``.
        """
        lengths = np.diff(offsets)
        totals = np.empty((len(clips), len(self.classes_)))
        layers = np.empty((len(clips), len(self.classes_), len(self.score_layers_)))
        for train, held_out in progress(
            folds, verbose=self.verbose, desc="MotionTreeHMM: calibration folds"
        ):
            keep = np.repeat(np.isin(np.arange(len(lengths)), train), lengths)
            sub_offsets = np.r_[0, np.cumsum(lengths[train])]
            guide, graphs, graph_classes, _ = self._count_graphs(
                self.tree_,
                [lab[keep] for lab in labels],
                sub_offsets,
                y_index[train],
                self.classes_,
            )
            scores = self._graph_scores(
                [clips[i] for i in held_out], exact=False, graphs=graphs, guide=guide
            )
            totals[held_out] = class_totals(
                scores, graph_classes, len(self.classes_), self.graph == "clip"
            )
            layers[held_out] = layer_class_scores(
                scores, graph_classes, len(self.classes_), self.graph == "clip"
            )
        return totals, layers

    def transform(self, X):
        """Per-layer class scores: the supervised view of the tree, features for a linear model.

        For each scored layer ``l`` (``score_layers_``) and class ``c``:
        ``log softmax_c(log P_l(clip | c) / n_frames)``, where ``P_l(clip | c)``
        is the clip's generation probability under class ``c``'s graph at layer
        ``l`` (the summed probability of its ``n_paths`` best node sequences, the
        factor of that layer in ``score_samples``). Dividing by the clip's
        length makes clips of any length comparable; the softmax over classes
        within each layer makes each layer's block a log posterior under a
        uniform class prior (at temperature 1). With ``graph="clip"``, a class's
        score at a layer is that of its best training clip at that layer. Use
        it to stack: ``make_pipeline(MotionTreeHMM(), LogisticRegression())``
        learns how much to trust each layer; ``fit_transform`` gives out-of-fold
        rows for the training clips.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_channels)

        Returns
        -------
        features : ndarray of shape (n_clips, n_scored_layers * n_classes)
            Layer-major: all classes of the first scored layer, then the next
            (``get_feature_names_out``); a DataFrame after
            ``set_output(transform="pandas")``.

        Examples
        --------
        >>> from sklearn.linear_model import LogisticRegression
        >>> from sklearn.pipeline import make_pipeline
        >>> from skmotion.datasets import make_motions
        >>> from skmotion.tree import MotionTreeHMM
        >>> data = make_motions(n_clips_per_class=4, classes=["walk", "jump"], random_state=0)
        >>> X = [clip[:, 6:] for clip in data.clips]
        >>> model = MotionTreeHMM(max_depth=3).fit(X, data.target)
        >>> model.transform(X).shape, list(model.get_feature_names_out()[:2])
        ((8, 6), ['layer1_class_0', 'layer1_class_1'])
        >>> stacked = make_pipeline(MotionTreeHMM(max_depth=3), LogisticRegression())
        >>> stacked.fit(X, data.target).score(X, data.target)
        1.0
        """
        check_is_fitted(self)
        clips = check_clips(X, estimator=self)
        features = class_score_features(self._layer_log_probs(clips), [len(c) for c in clips])
        return self._wrap_table(features, clips)

    def get_feature_names_out(self, input_features=None):
        """Column names of ``transform``: ``layer<l>_class_<label>``, layer-major.

        Parameters
        ----------
        input_features : array-like of str, default=None
            Ignored (the columns do not follow the input channels); accepted
            for sklearn's API.

        Returns
        -------
        feature_names_out : ndarray of str
        """
        check_is_fitted(self)
        return class_score_names(self.score_layers_, self.classes_)

    def _decode(
        self,
        clips,
        graphs,
        layer,
        n_graphs,
        *,
        score_layers=1,
        exact=True,
        prune=False,
        paths=True,
        guide=None,
    ):
        """Beam-decode every clip under every graph: paths and scores per clip (``decode_clips``).

        Without ``exact``, and when the normaliser of ``Ps`` is the same for
        every graph (``node_prior="layer"``), scores skip it: rankings are equal.
        With ``prune``, graphs that cannot score a clip best get ``-inf`` (for ``predict``).
        ``guide`` replaces the global graph in the shared search (calibration folds).
        """
        normalise = exact or self.node_prior != "layer"
        # One beam search per clip on the global graph, shared by all graphs. Under
        # node_prior="graph" a graph may have no candidate left in the shared beam,
        # so each graph then searches on its own (and nothing is pruned: pruning
        # compares the graphs of a clip within its shared search).
        guide = self.global_graph_ if guide is None else guide
        guide = guide if self.node_prior == "layer" else None
        frames, offsets = stack_clips(clips)
        return decode_clips(
            self.tree_,
            graphs,
            (frames - self.center_) / self.scale_,
            offsets,
            n_graphs=n_graphs,
            layer=layer,
            n_paths=self.n_paths,
            node_prior=self.node_prior,
            score_layers=score_layers,
            guide=guide,
            normalise=normalise,
            prune=prune and guide is not None,
            return_paths=paths,
            n_jobs=self.n_jobs,
        )

    def _graph_scores(self, clips, exact=True, prune=False, graphs=None, guide=None):
        """The decoder's K-best log scores ``(n_clips, n_graphs, n_scored, n_paths)``.

        Without ``exact``, up to a constant per clip and layer (enough to rank
        classes). With ``prune``, ``-inf`` for graphs that provably do not score
        best. ``graphs`` and ``guide`` replace the fitted ones (calibration folds).
        """
        graphs = self.graphs_ if graphs is None else graphs
        _, scores = self._decode(
            clips,
            graphs,
            self.layer_,
            graphs.n_graphs,
            score_layers=len(self.score_layers_),
            exact=exact,
            prune=prune,
            paths=False,
            guide=guide,
        )
        return scores

    def _class_log_probs(self, clips, exact=True, prune=False):
        """Log generation probability of each clip under each class, ``(n_clips, n_classes)``.

        The product over the scored layers. Without ``exact``, up to a constant
        per clip (enough to rank classes). With ``prune``, ``-inf`` for classes
        that provably do not score best.
        """
        scores = self._graph_scores(clips, exact=exact, prune=prune)
        return class_totals(scores, self.graph_classes_, len(self.classes_), self.graph == "clip")

    def _layer_log_probs(self, clips):
        """Per-layer class log generation probabilities ``(n_clips, n_classes, n_scored)``."""
        return layer_class_scores(
            self._graph_scores(clips, exact=False),
            self.graph_classes_,
            len(self.classes_),
            self.graph == "clip",
        )

    def score_samples(self, X):
        """Log generation probability of each clip under each class.

        With ``graph="clip"`` a class's value is that of its best training clip.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_channels)

        Returns
        -------
        log_prob : ndarray of shape (n_clips, n_classes)
            ``log`` of the summed probability of the ``n_paths`` best node
            sequences at ``layer_`` (summed over ``score_layers_`` when there
            are several); columns follow ``classes_``.

        Raises
        ------
        ValueError
            A value more than 1e5 training spreads from the training mean
            (naming its clip and channel): there the log-probability is
            rounding noise. :meth:`predict_proba` and :meth:`novelty_score`
            still answer for such clips.
        """
        check_is_fitted(self)
        clips = check_clips(X, estimator=self)
        check_magnitude(
            clips,
            self,
            center=self.center_,
            scale=self.scale_,
            limit=SCORE_LIMIT,
            why=f"scores values up to {SCORE_LIMIT:g} training spreads from the training mean "
            "(past them a log-probability is rounding noise)",
        )
        return self._class_log_probs(clips)

    def decision_function(self, X):
        """Per-frame log generation probability of each clip under each class, over the temperature.

        ``log P(clip | class) / (n_frames * temperature_)``, up to a constant per
        clip: the softmax of a row is ``predict_proba``; its argmax is
        ``predict`` (which prunes, with the same labels).

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_channels)

        Returns
        -------
        scores : ndarray of shape (n_clips, n_classes) or (n_clips,)
            Columns follow ``classes_``; with two classes, as sklearn expects,
            one column: the second class's score minus the first's.
        """
        scores = self._scores(X)
        if len(self.classes_) == 2:
            with np.errstate(invalid="ignore"):
                return scores[:, 1] - scores[:, 0]
        return scores

    def _scores(self, X):
        check_is_fitted(self)
        clips = check_clips(X, estimator=self)
        log_prob = self._class_log_probs(clips, exact=False)
        return per_frame(log_prob, [len(c) for c in clips]) / self.temperature_

    def predict_log_proba(self, X):
        """Log class probabilities: a softmax of ``decision_function`` (see ``predict_proba``).

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_channels)

        Returns
        -------
        log_proba : ndarray of shape (n_clips, n_classes)
        """
        return log_softmax_rows(self._scores(X))

    def predict_proba(self, X):
        """Class probabilities from per-frame generation probabilities and a fitted temperature.

        ``softmax(log P(clip | class) / (n_frames * temperature_))``: dividing by
        the clip's length keeps a long clip from making every answer certain
        (the plain normalised generation probabilities are near 0 or 1 for
        nearly every clip, the wrong ones included); ``temperature_`` is fitted
        by log loss on held-out folds in ``fit`` (``calibration_cv``). Rows are
        finite and sum to 1 for any finite input: a clip that no class can
        generate (scores ``-inf`` or NaN, e.g. frames far beyond the data's
        range) gets equal probabilities. ``novelty_score`` says how unlike the
        training data a clip is, which these probabilities do not.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_channels)

        Returns
        -------
        proba : ndarray of shape (n_clips, n_classes)
        """
        return np.exp(self.predict_log_proba(X))

    def novelty_score(self, X):
        """Mean log density of each clip's frames under the tree's nodes: lower is more novel.

        The nodes of ``layer_`` as a Gaussian mixture, each weighted by its share
        of the training frames, in standardised units (``center_``,
        ``scale_``): ``mean_i log sum_k w_k N(x_i | k)``. Unlike the generation
        probabilities, whose ``Ps(k | x)`` is normalised per frame (so a frame far
        from every node still picks one with certainty), this density falls as
        a clip moves away from the training frames. Threshold it, e.g., at a low
        quantile of the training clips' scores to flag clips to reject.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_channels)

        Returns
        -------
        score : ndarray of shape (n_clips,)
            Higher for clips like the training data (sklearn's ``score_samples``
            convention for novelty); ``-inf`` when a frame is so far that its
            density underflows.
        """
        check_is_fitted(self)
        clips = check_clips(X, estimator=self)
        frames, offsets = stack_clips(clips)
        frames = (frames - self.center_) / self.scale_
        return mixture_novelty(self.tree_, self.layer_, frames, offsets, self.log_node_weights_)

    def predict(self, X):
        """The class whose graph generates each clip with the highest probability.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_channels)

        Returns
        -------
        labels : ndarray of shape (n_clips,)
        """
        check_is_fitted(self)
        # Classes whose best sequence is too far below another's are left out of the
        # K-best pass: they cannot win (see beam_decode's prune), so labels are unchanged.
        log_prob = self._class_log_probs(check_clips(X, estimator=self), exact=False, prune=True)
        return self.classes_[np.argmax(log_prob, axis=1)]

    def predict_proba_windows(self, X, width, step=1):
        """Class probabilities of sliding windows: the time profiles of the paper's Figures 10-12.

        Each window's row is ``predict_proba`` of the window as a clip.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_channels)
        width : int
            Frames per window. A clip shorter than ``width`` gives one window,
            the whole clip.
        step : int, default=1
            Frames between the starts of consecutive windows.

        Returns
        -------
        profiles : list of ndarray of shape (n_windows_i, n_classes)
            For clip ``i``, the windows start at frames
            ``0, step, 2 step, ...`` up to ``max(n_frames_i - width, 0)``.
        """
        check_is_fitted(self)
        clips = check_clips(X, estimator=self)
        width, step = check_int("width", width), check_int("step", step)
        starts = [np.arange(0, max(len(c) - width, 0) + 1, step) for c in clips]
        windows = [c[s : s + width] for c, st in zip(clips, starts) for s in st]
        log_prob = self._class_log_probs(windows, exact=False)
        scores = per_frame(log_prob, [len(w) for w in windows]) / self.temperature_
        proba = np.exp(log_softmax_rows(scores))
        return np.split(proba, np.cumsum([len(s) for s in starts])[:-1])

    def _resolve_layer(self, layer):
        return self.layer_ if layer is None else self.tree_.check_layer(layer)

    def decode(self, X, layer=None):
        """The most likely node sequence of each clip on the global graph, and its log probability.

        State estimation, in hmmlearn's convention (``logprob, path``), one
        entry per clip.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_channels)
        layer : int, default=None
            The layer to decode at; ``layer_`` by default.

        Returns
        -------
        logprob : ndarray of shape (n_clips,)
            ``log P(N | X)`` of each clip's sequence ``N``: the log node
            posteriors ``log Ps(n_t | x_t)`` and the global graph's log
            transition probabilities along it (the units of ``score_samples``,
            which sums ``n_paths`` sequences under each class graph).
        paths : list of ndarray of shape (n_frames_i,)
            Layer indices of the nodes (see ``tree_.node_ids(layer)``).

        Examples
        --------
        >>> from skmotion.datasets import make_motions
        >>> from skmotion.tree import MotionTreeHMM
        >>> data = make_motions(n_clips_per_class=4, classes=["walk", "jump"], random_state=0)
        >>> X = [clip[:, 6:] for clip in data.clips]
        >>> model = MotionTreeHMM(max_depth=4).fit(X, data.target)
        >>> logprob, paths = model.decode(X[:2])
        >>> logprob.shape, len(paths[0]) == len(X[0]), bool((logprob <= 0).all())
        ((2,), True, True)
        """
        check_is_fitted(self)
        clips = check_clips(X, estimator=self)
        paths, scores = self._decode(clips, self.global_graph_, self._resolve_layer(layer), 1)
        return scores[:, 0, -1, 0], [p[0, 0] for p in paths]

    def predict_next(self, X, n_steps=1, *, n_best=3, layer=None):
        """The most likely nodes ``n_steps`` frames after each clip ends (prediction).

        The current node's probability comes from the ``n_paths`` best sequences
        on the global graph (their normalised probabilities, by last node); it is
        carried ``n_steps`` transitions forward on the global graph.

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_channels)
        n_steps : int, default=1
            How many frames ahead.
        n_best : int, default=3
            How many nodes to return per clip (at most the layer's node count).
        layer : int, default=None
            The layer to predict at; ``layer_`` by default.

        Returns
        -------
        prediction : Bunch
            nodes : ndarray of shape (n_clips, n_best)
                Layer indices of the most likely nodes, most likely first.
            probabilities : ndarray of shape (n_clips, n_best)
                Their probabilities (the confidence of the prediction).
            means : ndarray of shape (n_clips, n_best, n_channels)
                Their mean frames: the predicted states.
            layer : int
        """
        check_is_fitted(self)
        clips = check_clips(X, estimator=self)
        n_steps, n_best = check_int("n_steps", n_steps), check_int("n_best", n_best)
        layer = self._resolve_layer(layer)
        paths, scores = self._decode(clips, self.global_graph_, layer, 1, exact=False)
        future = next_node_probabilities(paths, scores, self.global_graph_, layer, n_steps)
        n_best = min(n_best, self.tree_.n_nodes[layer])
        nodes = np.argsort(-future, axis=1, kind="stable")[:, :n_best]
        return Bunch(
            nodes=nodes,
            probabilities=np.take_along_axis(future, nodes, axis=1),
            means=self.tree_.means(layer)[nodes] * self.scale_ + self.center_,
            layer=layer,
        )

    def plan(self, start, goal, *, frame_rate, **options):
        """Plan a motion on the global graph that takes the root from ``start`` to ``goal``.

        A* over (node, root pose on the floor) finds the most probable node
        path whose root ends near the goal, using only transitions seen in the
        data (Yamane, Yamaguchi and Nakamura, section V-C). The model must have been fit on
        virtual-marker clips (:class:`~skmotion.preprocessing.VirtualMarkerTransform`).
        The planner is :func:`skmotion.planning.plan_from_database`, which
        checks the parameters; see the user guide (``docs/planning.md``).

        Parameters
        ----------
        start : tuple of (float, float, float)
            The root's ``(x, y, heading)`` on the floor at the first frame.
        goal : tuple of (float, float)
            The goal position on the floor, metres.
        frame_rate : float
            Frames per second of the training clips.
        **options
            ``body_size``, ``transformer``, ``layer``, ``max_frames``,
            ``tolerance``, ``start_node``, ``heuristic_weight``, ``cell``,
            ``heading_bins``, ``max_expansions``: see
            :func:`~skmotion.planning.plan_from_database`.

        Returns
        -------
        plan : MotionPlan

        Raises
        ------
        UnreachableGoalError
            (a ``ValueError``) when no motion of the database reaches the goal.

        Examples
        --------
        >>> from skmotion.datasets import make_walks
        >>> from skmotion.io import as_motions
        >>> from skmotion.preprocessing import VirtualMarkerTransform
        >>> from skmotion.tree import MotionTreeHMM
        >>> walks = make_walks(2, directions=["forward", "left"], random_state=0)
        >>> motions = as_motions(walks.clips, walks.skeletons, walks.frame_rate)
        >>> X = VirtualMarkerTransform().fit_transform(motions)
        >>> model = MotionTreeHMM(max_depth=5, split="median").fit(X, walks.target)
        >>> plan = model.plan((0, 0, 0), (2.0, 1.0), frame_rate=30, body_size=1.6, tolerance=0.15)
        >>> plan.reached < 0.15, bool((plan.seen_counts > 0).all())
        (True, True)
        """
        from skmotion.planning import plan_from_database

        return plan_from_database(self, start, goal, frame_rate=frame_rate, **options)

    def partial_fit(
        self, X, y, classes=None, *, split_growth=2.0, rebuild_growth=2.0, rebuild_tol=None
    ):
        """Add clips (of known or new classes) to the database without rebuilding it.

        The first call builds the database as ``fit`` does and keeps what later
        calls need: every node's exact moments and the clips. Later calls
        route the new frames down the existing splits: node counts, means and
        covariances are merged exactly (pairwise moment updates; the ``"full"``
        Ledoit-Wolf estimate too, from the fourth moment), and the new clips'
        transitions are added to the graphs; leaves split and grown subtrees
        are built again by the build's rule (``split_growth``,
        ``rebuild_growth``, ``rebuild_tol``). The standardisation, the
        absolute ``reg_covar`` and ``temperature_`` are those of the last
        whole build (the first call, or a rebuild of the root). See the user
        guide (``docs/live-database.md``).

        Parameters
        ----------
        X : list of ndarray of shape (n_frames_i, n_channels)
            New clips.
        y : array-like of shape (n_clips,)
            Their labels; a label not in ``classes_`` adds a class.
        classes : array-like, default=None
            Classes to add even when no clip of them is given yet (they get
            empty graphs).
        split_growth : float or None, default=2.0
            A leaf is split by the build's rule (``split``,
            ``min_samples_leaf``, ``min_samples_split``, ``max_depth``),
            recursively, when it reaches ``min_samples_split`` frames (the
            build splits every node that large) or its frame count has grown
            this many times since it was built (or last tried). None never
            splits leaves.
        rebuild_growth : float or None, default=2.0
            A split node whose frame count has grown this many times since its
            subtree was built has the subtree built again from its frames (its
            split was chosen on part of them). At the root this rebuilds the
            whole database as ``fit`` would from all clips so far (the
            standardisation and ``temperature_`` included): with a doubling,
            the tree is always built on at least half the clips, for about
            twice the cost of one ``fit`` over the whole growth. None never
            does; with ``split_growth=None`` too, node statistics equal those
            of the first batch's tree routed with all frames, whatever the
            order and batching of the clips.
        rebuild_tol : float or None, default=None
            A split node whose mean has moved more than this many of its
            standard deviations (``sqrt(trace(cov) / n_channels)``, taken when
            the split was made) has its subtree rebuilt from its frames. None
            never rebuilds.

        Returns
        -------
        self : MotionTreeHMM

        Notes
        -----
        A model fitted with ``fit`` keeps no frames: ``partial_fit`` then
        recovers the moments of ``"diag"`` and ``"spherical"`` nodes from their
        estimates (exact up to rounding) and only merges new frames in; a
        ``"full"`` model cannot be updated (its estimate hides the fourth
        moment) and raises. Start a growing database with ``partial_fit``.

        Examples
        --------
        >>> from skmotion.datasets import make_motions
        >>> from skmotion.tree import MotionTreeHMM
        >>> data = make_motions(n_clips_per_class=4, classes=["walk", "jump"], random_state=0)
        >>> X = [clip[:, 6:] for clip in data.clips]
        >>> model = MotionTreeHMM(max_depth=4, min_samples_leaf=16)
        >>> model = model.partial_fit(X[:2], data.target[:2])
        >>> for clip, label in zip(X[2:], data.target[2:]):
        ...     model = model.partial_fit([clip], [label])
        >>> int(model.tree_.count[0]) == sum(len(c) for c in X), model.score(X, data.target)
        (True, 1.0)
        """
        growth = check_growth_params(split_growth, rebuild_tol, rebuild_growth)
        if classes is not None and np.ndim(classes) != 1:
            raise ValueError(f"classes must be a 1-D array-like of labels; got {classes!r}.")
        if not hasattr(self, "tree_"):
            clips = check_clips(X, estimator=self, reset=True)
            return self._build_live(clips, list(check_clip_labels(y, len(clips))), classes)
        clips = check_clips(X, estimator=self)
        y = check_clip_labels(y, len(clips))
        classes = union_classes(self.classes_, y, classes)
        live = getattr(self, "_live", None)
        if live is None or live.tree is not self.tree_:  # fit since: start from its tree
            live = self._live = LiveDatabase.from_tree(self.tree_, self.center_, self.scale_)
        if live.root_due(sum(len(c) for c in clips), rebuild_growth):
            # the whole database has grown rebuild_growth times: built again, as fit
            # builds it from all clips so far (standardisation and temperature included)
            return self._build_live(live.clips + clips, live.labels + list(y), classes)
        tree, graphs = grow(
            live,
            Graphs(self.global_graph_, self.graphs_, self.graph_classes_, self.classes_),
            clips,
            y,
            classes,
            per_clip=self.graph == "clip",
            smoothing=self.smoothing,
            build_params=TreeParams.of(self),
            growth=growth,
        )
        self._set_tree(tree)
        self._set_graphs(graphs)
        return self

    def _build_live(self, clips, labels, classes):
        """``fit`` on ``clips``, keeping them and the moments for later ``partial_fit`` calls."""
        # the clips kept are arrays: keep the channel names fit saw
        names = getattr(self, "feature_names_in_", None)
        self.fit(clips, labels)
        if names is not None:
            self.feature_names_in_ = names
        self._live = LiveDatabase.from_clips(self.tree_, clips, labels, self.center_, self.scale_)
        if classes is not None and len(np.setdiff1d(classes, self.classes_)):
            graphs = Graphs(self.global_graph_, self.graphs_, self.graph_classes_, self.classes_)
            new = union_classes(self.classes_, classes)
            kind = {"per_clip": self.graph == "clip", "smoothing": self.smoothing}
            self._set_graphs(regraph(self.tree_, graphs, new, **kind))
        return self

    def stream(self, *, layer=None, lag=0, window=None, n_best=3, mode="online", beam=None):
        """An online decoder: recognition and state estimation as frames arrive.

        ``stream.update(frames)`` takes one frame or a chunk and returns the
        current node (and its ancestors at every layer above), the node
        ``lag`` frames back, the class posterior and decision, and the most
        likely next nodes. Two modes:

        - ``"online"`` (default): a causal top-down beam kept between calls.
          Each frame's candidates are the children of its kept nodes, scored
          by forward max-product recursions on the global graph (the state)
          and on each class graph (a running log-likelihood per class); a
          frame costs the same whatever came before (about 15
          microseconds of CPU per single-frame update for 32 markers), and the
          state is ``O(beam x layers)`` numbers. Its
          answers are not the batch ones: the batch beam keeps the nodes with
          the best forward + backward scores over the whole clip, which no
          causal decoder can know. Measured on four data sets, the final
          label equals ``predict``'s on 98.9-100% of clips and the node equals
          ``decode``'s on 82-98% of frames (93-98% with ``lag=5``).
        - ``"exact"``: the batch answers (``decode``, ``predict_proba``,
          ``predict_next``) of the frames seen so far, or of the last
          ``window``, exactly, by decoding them again at each update: about
          a millisecond or more per update.

        The default is ``"online"`` because a live stream must have a bounded
        cost per frame (the exact mode without a window grows with the
        stream). See :class:`~skmotion.tree._online._causal.OnlineMotionStream`,
        :class:`~skmotion.tree._online._exact.MotionStream` and the user guide
        (``docs/live-database.md``).

        Parameters
        ----------
        layer : int, default=None
            The layer to estimate the state at; ``layer_`` by default.
        lag : int, default=0
            Also report the node this many frames back (fixed-lag smoothing).
        window : int, default=None
            ``mode="exact"`` only: decode only the last ``window`` frames at
            each update (bounded cost per update), or all frames so far (None).
        n_best : int, default=3
            Predicted next nodes per update (``mode="online"`` also takes 0).
        mode : {"online", "exact"}, default="online"
            ``"exact"``: the batch answers of the frames so far, decoded again
            at each update (:class:`~skmotion.tree._online._exact.MotionStream`).
            ``"online"``: a causal top-down beam kept between calls, a bounded
            cost per frame (forward scores only, so its answers may differ
            from the batch ones; :class:`~skmotion.tree._online._causal.OnlineMotionStream`).
        beam : int, default=None
            ``mode="online"`` only: nodes kept per frame and layer (the
            model's ``n_paths`` by default).

        Returns
        -------
        stream : MotionStream or OnlineMotionStream

        Examples
        --------
        >>> import numpy as np
        >>> from skmotion.datasets import make_motions
        >>> from skmotion.tree import MotionTreeHMM
        >>> data = make_motions(n_clips_per_class=4, classes=["walk", "jump"], random_state=0)
        >>> X = [clip[:, 6:] for clip in data.clips]
        >>> model = MotionTreeHMM(max_depth=4).fit(X, data.target)
        >>> stream = model.stream(lag=5)
        >>> for frame in X[0]:
        ...     state = stream.update(frame)
        >>> bool(state.label == model.predict(X[:1])[0])
        True
        >>> exact = model.stream(mode="exact")
        >>> state = exact.update(X[0])        # a chunk: here the whole clip
        >>> bool((exact.path() == model.decode(X[:1])[1][0]).all())
        True
        """
        check_is_fitted(self)
        if mode == "online":
            if window is not None:
                raise ValueError("window is for mode='exact'; the online stream is causal.")
            return OnlineMotionStream(self, layer=layer, lag=lag, beam=beam, n_best=n_best)
        if mode != "exact":
            raise ValueError(f"mode must be 'exact' or 'online'; got {mode!r}.")
        if beam is not None:
            raise ValueError("beam is for mode='online'; the exact stream uses n_paths.")
        return MotionStream(self, layer=layer, lag=lag, window=window, n_best=n_best)

    def sample(
        self,
        n_frames,
        *,
        y=None,
        random_state=None,
        layer=None,
        smoothness=1.0,
        transformer=None,
        frame_rate=None,
    ):
        """Generate a motion: a node sequence from a transition graph, frames from its nodes.

        The first node is drawn by the graph's visit frequencies and each next
        one by its transition probabilities (those used to recognise);
        frames are the nodes' Gaussians, the means and the noise smoothed over
        ``smoothness`` frames so that node changes do not jump (see
        :mod:`skmotion.tree._synthesis`).

        Parameters
        ----------
        n_frames : int
        y : label, default=None
            Sample from this class's graph (with ``graph="clip"``, from one of
            its clips' graphs, at random); the global graph by default.
        random_state : int, RandomState instance or None, default=None
        layer : int, default=None
            The layer whose nodes generate the frames; ``layer_`` by default.
        smoothness : float, default=1.0
            Standard deviation, in frames, of the smoothing kernel (0: none).
        transformer : VirtualMarkerTransform, default=None
            The fitted transform, with a skeleton, that made the training
            clips (virtual markers): the sampled markers are turned into joint
            angles by the planning module's inverse kinematics, in the body
            frame (the root stays in place).
        frame_rate : float, default=None
            Frames per second of the motion (needed with ``transformer``).

        Returns
        -------
        sample : Bunch
            frames : ndarray of shape (n_frames, n_features_in_)
            nodes : ndarray of int of shape (n_frames,)
                Layer indices of the sampled nodes.
            layer : int
            motion : Motion or None
                The joint angles, for ``write_bvh`` (with ``transformer``).
            ik_rms : ndarray of shape (n_frames,) or None
                RMS marker error of the inverse kinematics, data units.

        Examples
        --------
        >>> from skmotion.datasets import make_motions
        >>> from skmotion.tree import MotionTreeHMM
        >>> data = make_motions(n_clips_per_class=4, classes=["walk", "jump"], random_state=0)
        >>> X = [clip[:, 6:] for clip in data.clips]
        >>> model = MotionTreeHMM(max_depth=4).fit(X, data.target)
        >>> clip = model.sample(60, y=model.classes_[0], random_state=0)
        >>> clip.frames.shape == (60, X[0].shape[1])
        True
        >>> bool(model.predict([clip.frames])[0] == model.classes_[0])
        True
        """
        from skmotion.tree._synthesis import sample_model

        check_is_fitted(self)
        return sample_model(
            self,
            n_frames,
            y=y,
            random_state=random_state,
            layer=layer,
            smoothness=smoothness,
            transformer=transformer,
            frame_rate=frame_rate,
        )
