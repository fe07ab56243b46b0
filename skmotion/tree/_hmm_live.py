"""MotionTreeHMM as a live database: clips added, frames streamed, motions sampled.

Short delegates, with their documentation, to the modules that do the work:
``partial_fit`` to ``_partial_fit``, ``stream`` to ``_online_stream`` and
``_stream``, ``sample`` to ``_synthesis``.
"""

from sklearn.utils.validation import check_is_fitted

__all__ = ["LiveDatabaseMixin"]


class LiveDatabaseMixin:
    """``partial_fit``, ``stream`` and ``sample``, mixed into :class:`MotionTreeHMM`.

    ``partial_fit`` refreshes the node weights with the model's ``_set_node_weights``.
    """

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
        from skmotion.tree._partial_fit import partial_fit

        partial_fit(self, X, y, classes, split_growth, rebuild_growth, rebuild_tol)
        self._set_node_weights()  # the nodes and their frame counts have changed
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
        stream). See :class:`~skmotion.tree._online_stream.OnlineMotionStream`,
        :class:`~skmotion.tree._stream.MotionStream` and the user guide
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
            at each update (:class:`~skmotion.tree._stream.MotionStream`).
            ``"online"``: a causal top-down beam kept between calls, a bounded
            cost per frame (forward scores only, so its answers may differ
            from the batch ones; :class:`~skmotion.tree._online_stream.OnlineMotionStream`).
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
        >>> bool((exact.path() == model.decode(X[:1])[0]).all())
        True
        """
        check_is_fitted(self)
        if mode == "online":
            from skmotion.tree._online_stream import OnlineMotionStream

            if window is not None:
                raise ValueError("window is for mode='exact'; the online stream is causal.")
            return OnlineMotionStream(self, layer=layer, lag=lag, beam=beam, n_best=n_best)
        if mode != "exact":
            raise ValueError(f"mode must be 'exact' or 'online'; got {mode!r}.")
        if beam is not None:
            raise ValueError("beam is for mode='online'; the exact stream uses n_paths.")
        from skmotion.tree._stream import MotionStream

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
