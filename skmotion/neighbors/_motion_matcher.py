"""Frame search for motion matching: which frame of which take best continues this pose and path.

The feature of a frame is the one game engines search (Clavet, "Motion
Matching and The Road to Next-Gen Animation", GDC 2016; Holden, Kanoun,
Perepichka and Popa, "Learned Motion Matching", SIGGRAPH 2020): the positions
and velocities of a few points in the body frame (the same frame as
:class:`~skmotion.preprocessing.VirtualMarkerTransform`, computed by its
compiled loop), and where the body will be and face after a few future
times, on the floor, seen from the body frame now. Each group is divided by
its mean standard deviation over the database and multiplied by its weight,
so a weight says how much the group counts whatever its units.

The search backends were chosen by measurement (benchmarks/bench_matching.py,
docs/motion-matching.md): on 10^6 frames of 30-dimensional features sklearn's
k-d tree answers one exact query 45-58 times faster than faiss's compiled brute
force, and faiss's HNSW graph (Malkov and Yashunin, 2018) answers
approximately at recall@1 0.99 where hnswlib's graph of the same degree and
construction beam reached 0.92; brute force stays available for checking.
Of the graphs measured on 2 x 10^5 frames, degree 32 reached recall@1 0.99
at the least CPU time per query: a lower degree needs a wider beam, a
higher one visits more neighbours per step; a PCA to 8-12 dimensions with
an exact re-ranking of 8-16 candidates stayed below 0.98, and faiss's
half-precision or 8-bit storage was both slower and less exact; on 10^6
frames faiss's inverted lists (1,024 of them) needed more time than the
graph for the same recall. The graph is stored in cluster order
(:func:`~skmotion.neighbors._hnsw.hnsw_index`), which on 10^6 frames cut a
query's cost by a quarter at the same answers.
"""

import math
from numbers import Integral, Real

import numpy as np
from sklearn.base import BaseEstimator
from sklearn.neighbors import BallTree, KDTree
from sklearn.utils.validation import check_is_fitted

from skmotion.base import VersionedStateMixin
from skmotion.io import Motion
from skmotion.kinematics import get_layout
from skmotion.kinematics._layouts import layout_plan
from skmotion.neighbors._hnsw import HnswSearch, faiss_module, hnsw_index
from skmotion.planning._ik import plan_axes
from skmotion.preprocessing._marker_presets import marker_preset
from skmotion.preprocessing._position_frame import position_frame_features
from skmotion.utils._sklearn_compat import Interval, StrOptions

__all__ = ["MotionMatcher", "floor_frames"]

#: The facing pairs and the root, by shared marker name.
_ROLES = {"root": ("pelvis",), "lefts": ("left_hip", "left_shoulder")}
_ROLES["rights"] = tuple(name.replace("left", "right") for name in _ROLES["lefts"])
#: HNSW search beam by default: recall@1 >= 0.99 on 10^6 frames of walks (the benchmark).
EF_DEFAULT = 24


def floor_frames(points, *, root, lefts, rights, up="y"):
    """Where the body frame is on the floor and where it faces, per frame.

    Parameters
    ----------
    points : ndarray of shape (n_frames, n_points, 3)
        World positions.
    root, lefts, rights : sequence of int
        The root points (averaged) and the facing pairs, as for
        :func:`~skmotion.preprocessing.position_frame_features`.
    up : {"x", "y", "z"}, default="y"

    Returns
    -------
    origin : ndarray of shape (n_frames, 2)
        The root below on the floor, in the planner's floor axes
        (:func:`~skmotion.planning.plan_axes`).
    yaw : ndarray of shape (n_frames,)
        The facing direction, counter-clockwise from the floor's ``x`` axis.

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.neighbors import floor_frames
    >>> # Y up: the floor's x is world z, its y world x; left hip at +x faces +z.
    >>> p = np.array([[[0.0, 1.0, 2.0], [0.1, 1.0, 2.0], [-0.1, 1.0, 2.0]]])
    >>> origin, yaw = floor_frames(p, root=[0], lefts=[1], rights=[2])
    >>> origin.tolist(), yaw.round(6).tolist()
    ([[2.0, 0.0]], [0.0])
    """
    plan = points @ plan_axes(up)
    origin = plan[:, list(root), :2].mean(axis=1)
    lateral = sum(plan[:, left, :2] - plan[:, right, :2] for left, right in zip(lefts, rights))
    # forward = lateral x up on the floor: (l_y, -l_x).
    return origin, np.arctan2(-lateral[:, 0], lateral[:, 1])


def _trajectory(origin, yaw, offsets):
    """Future floor positions and facings in the body frame now, ``(n, 4 len(offsets))``.

    Frames whose future runs past the take use its last frame.
    """
    n = len(origin)
    later = np.minimum(np.arange(n)[:, None] + np.asarray(offsets)[None, :], n - 1)
    c, s = np.cos(yaw)[:, None], np.sin(yaw)[:, None]
    delta = origin[later] - origin[:, None, :]
    ahead = delta[..., 0] * c + delta[..., 1] * s
    aside = -delta[..., 0] * s + delta[..., 1] * c
    turn = yaw[later] - yaw[:, None]
    return np.concatenate([ahead, aside, np.cos(turn), np.sin(turn)], axis=1)


class MotionMatcher(VersionedStateMixin, BaseEstimator):
    """Index every frame of long takes by its motion-matching feature; find the nearest frames.

    Parameters
    ----------
    layout : str, Layout or None, default=None
        None: the takes are :class:`~skmotion.io.Motion` objects with a
        skeleton, whose standard markers (:func:`marker_preset`) give the
        points. A layout name (``"kinect_v1"``, ...) or
        :class:`~skmotion.kinematics.Layout`: the takes are position arrays of
        shape ``(n_frames, 3 n_joints)`` (joint-major) or ``(n_frames,
        n_joints, 3)``, in metres.
    points : sequence of str, default=("pelvis", "left_ankle", "right_ankle")
        Shared marker names (:data:`~skmotion.kinematics.MARKER_NAMES`) whose
        body-frame positions and velocities enter the feature.
    future : sequence of float, default=(0.33, 0.67, 1.0)
        Seconds ahead at which the trajectory is sampled.
    frame_rate : float, default=None
        Frames per second of position takes (Motions carry their own).
    pose_weight, velocity_weight, trajectory_weight : float, default=1.0
        Weights of the groups (after each is divided by its spread).
    algorithm : {"auto", "kd_tree", "ball_tree", "brute", "hnsw"}, default="auto"
        ``"auto"`` is the exact ``"kd_tree"``; ``"hnsw"`` is approximate:
        faiss's HNSW graph (the ``ann`` extra, ``faiss-cpu``) of degree 32,
        built on one thread so that it is the same graph every time.
    leaf_size : int, default=40
        Leaf size of the trees.
    ef : int, default=24
        HNSW search beam: larger is slower and more often exact.

    Attributes
    ----------
    features_ : ndarray of shape (n_indexed, n_features)
        The weighted, normalised features of the indexed frames: every frame
        whose whole future lies in its take.
    take_ : ndarray of shape (n_indexed,)
    frame_ : ndarray of shape (n_indexed,)
        Take and frame of each indexed row.
    origin_, yaw_ : list of ndarray
        Per take, its body frame on the floor per frame (:func:`floor_frames`).
    mean_, scale_ : ndarray of shape (n_features,)
        ``features_ = (raw - mean_) / scale_``.
    groups_ : dict of str to slice
        Columns of ``"pose"``, ``"velocity"`` and ``"trajectory"``.
    future_frames_ : ndarray of int
    frame_rate_ : float

    Examples
    --------
    >>> from skmotion.datasets import make_walks
    >>> from skmotion.io import as_motions
    >>> from skmotion.neighbors import MotionMatcher
    >>> data = make_walks(2, random_state=0)
    >>> takes = as_motions(data.clips, data.skeletons, data.frame_rate)
    >>> matcher = MotionMatcher().fit(takes)
    >>> take, frame, distance = matcher.kneighbors(matcher.features_[[40]], n_neighbors=1)
    >>> (int(take[0, 0]), int(frame[0, 0])) == (matcher.take_[40], matcher.frame_[40])
    True
    """

    _parameter_constraints = {
        "layout": [str, object, None],
        "points": [list, tuple],
        "future": [list, tuple],
        "frame_rate": [Interval(Real, 0, None, closed="neither"), None],
        "pose_weight": [Interval(Real, 0, None, closed="left")],
        "velocity_weight": [Interval(Real, 0, None, closed="left")],
        "trajectory_weight": [Interval(Real, 0, None, closed="left")],
        "algorithm": [StrOptions({"auto", "kd_tree", "ball_tree", "brute", "hnsw"})],
        "leaf_size": [Interval(Integral, 1, None, closed="left")],
        "ef": [Interval(Integral, 1, None, closed="left")],
    }

    def __init__(
        self,
        *,
        layout=None,
        points=("pelvis", "left_ankle", "right_ankle"),
        future=(0.33, 0.67, 1.0),
        frame_rate=None,
        pose_weight=1.0,
        velocity_weight=1.0,
        trajectory_weight=1.0,
        algorithm="auto",
        leaf_size=40,
        ef=EF_DEFAULT,
    ):
        self.layout = layout
        self.points = points
        self.future = future
        self.frame_rate = frame_rate
        self.pose_weight = pose_weight
        self.velocity_weight = velocity_weight
        self.trajectory_weight = trajectory_weight
        self.algorithm = algorithm
        self.leaf_size = leaf_size
        self.ef = ef

    def _take_points(self, take, i):
        """World points (metres), the role indices, the up axis and the frame rate of a take."""
        if self.layout is None:
            if not isinstance(take, Motion) or take.skeleton is None:
                raise TypeError(
                    f"take {i}: without a layout, takes must be Motions with a skeleton; "
                    f"got {type(take).__name__}"
                )
            markers = marker_preset(take.skeleton)
            names = list(markers.names)
            unit = take.skeleton.meters_per_unit or 1.0
            world = markers.positions(take.skeleton, take.channels) * unit
            roles = {k: [names.index(n) for n in v] for k, v in _ROLES.items()}
            outputs = [names.index(n) for n in self.points]
            return world, roles, outputs, take.skeleton.up_axis, take.frame_rate
        layout = get_layout(self.layout)
        plan = layout_plan(layout, markers=list(self.points))
        world = np.asarray(take, dtype=float).reshape(len(take), layout.n_joints, 3)
        if self.frame_rate is None:
            raise ValueError("position takes need frame_rate= (frames per second)")
        roles = {k: list(plan[k]) for k in ("root", "lefts", "rights")}
        return world, roles, list(plan["outputs"]), layout.up, float(self.frame_rate)

    def _raw_features(self, takes):
        """Per take: unscaled features of every frame, its floor origin and yaw; the frame rate."""
        out, rate = [], None
        for i, take in enumerate(takes):
            world, roles, outputs, up, take_rate = self._take_points(take, i)
            if rate is not None and take_rate != rate:
                raise ValueError(f"take {i} runs at {take_rate} frames/s, take 0 at {rate}")
            rate = take_rate
            if len(world) < 2:
                raise ValueError(f"take {i} has {len(world)} frame(s); at least 2 are needed")
            local = position_frame_features(
                world, **roles, up=up, frame_rate=rate, outputs=outputs
            ).reshape(len(world), len(outputs), 6)
            origin, yaw = floor_frames(world, **roles, up=up)
            future = np.maximum(1, np.round(np.asarray(self.future) * rate).astype(int))
            trajectory = _trajectory(origin, yaw, future)
            flat = [local[..., :3].reshape(len(world), -1), local[..., 3:].reshape(len(world), -1)]
            out.append((np.hstack([*flat, trajectory]), origin, yaw))
        return out, rate, future

    def fit(self, X, y=None):
        """Index every frame of the takes whose whole future lies in the take.

        Parameters
        ----------
        X : list of Motion or of array-like
            The takes (see ``layout``).
        y : None
            Ignored.

        Returns
        -------
        self : MotionMatcher
        """
        self._validate_params()
        takes = list(X)
        if not takes:
            raise ValueError("no takes to index: the collection is empty")
        raw, self.frame_rate_, self.future_frames_ = self._raw_features(takes)
        horizon = int(self.future_frames_.max())
        keep = [np.arange(max(len(f) - horizon, 0)) for f, _, _ in raw]
        if not sum(len(k) for k in keep):
            raise ValueError(f"no take is longer than the trajectory's horizon ({horizon} frames)")
        stacked = np.concatenate([f[k] for (f, _, _), k in zip(raw, keep)])
        n_points = len(self.points)
        bounds = np.cumsum([0, 3 * n_points, 3 * n_points, stacked.shape[1] - 6 * n_points])
        self.groups_ = {
            g: slice(int(a), int(b))
            for g, a, b in zip(("pose", "velocity", "trajectory"), bounds[:-1], bounds[1:])
        }
        weights = {"pose": self.pose_weight, "velocity": self.velocity_weight}
        weights["trajectory"] = self.trajectory_weight
        self.mean_ = stacked.mean(axis=0)
        self.scale_ = np.empty(stacked.shape[1])
        for group, cols in self.groups_.items():
            spread = float(stacked[:, cols].std(axis=0).mean()) or 1.0
            # A zero weight drops the group: an infinite divisor makes its columns 0.
            self.scale_[cols] = spread / weights[group] if weights[group] > 0 else np.inf
        self.features_ = np.ascontiguousarray((stacked - self.mean_) / self.scale_)
        self.take_ = np.concatenate([np.full(len(k), i) for i, k in enumerate(keep)])
        self.frame_ = np.concatenate(keep)
        self.origin_ = [o for _, o, _ in raw]
        self.yaw_ = [w for _, _, w in raw]
        self._build()
        return self

    def _build(self):
        # A refit with another algorithm must not keep searching an earlier graph.
        self.__dict__.pop("_graph", None)
        self.__dict__.pop("_graph_order", None)
        algorithm = "kd_tree" if self.algorithm == "auto" else self.algorithm
        data = self.features_
        if algorithm == "kd_tree":
            self.index_ = KDTree(data, leaf_size=self.leaf_size)
        elif algorithm == "ball_tree":
            self.index_ = BallTree(data, leaf_size=self.leaf_size)
        elif algorithm == "hnsw":
            self._set_graph(*hnsw_index(data))
        else:
            self.index_ = None
            self.squared_norms_ = np.einsum("ij,ij->i", data, data)

    def _set_graph(self, index, order):
        """Keep an HNSW graph as the index, with its searches (not pickled: rebuilt on load).

        Graph row ``r`` is row ``order[r]`` of ``features_`` (:func:`hnsw_index`).
        """
        self.index_, self._graph_order = index, order
        self._graph = HnswSearch(index, self.take_[order], self.frame_[order])

    def frame_features(self, X):
        """The weighted, normalised feature of every frame of new takes.

        Frames whose future runs past their take use its last frame.

        Parameters
        ----------
        X : list of Motion or of array-like

        Returns
        -------
        features : list of ndarray of shape (n_frames_i, n_features)
        """
        check_is_fitted(self)
        raw, _, _ = self._raw_features(list(X))
        return [(f - self.mean_) / self.scale_ for f, _, _ in raw]

    def kneighbors(self, X, n_neighbors=1):
        """The nearest indexed frames of feature vectors: take, frame and distance.

        Parameters
        ----------
        X : array-like of shape (n_queries, n_features)
            Features as in ``features_`` (from :meth:`frame_features`, or a row of
            ``features_`` with the trajectory replaced by a desired one).
        n_neighbors : int, default=1

        Returns
        -------
        take, frame : ndarray of int of shape (n_queries, n_neighbors)
        distance : ndarray of shape (n_queries, n_neighbors)
            Euclidean, nearest first.
        """
        graph = self.__dict__.get("_graph")
        if graph is not None:
            # One row, the motion-matching case: the graph answers it without the
            # checks below (a NaN or inf makes its answer None, and they name it).
            found = graph.one(X, n_neighbors, self.ef)
            if found is not None:
                return found
        if "features_" not in vars(self):
            # check_is_fitted's scan of the attributes costs as much as an approximate query.
            check_is_fitted(self)
        X = np.asarray(X, dtype=float)
        if X.ndim == 1:
            X = X[None]
        if X.ndim != 2 or X.shape[1] != self.features_.shape[1]:
            raise ValueError(
                f"X has shape {X.shape}; the index needs (n_queries, {self.features_.shape[1]})"
            )
        # One dot product is finite when every value is (and not too large): the
        # row-wise check, many times the cost of the rest of the wrapper, runs only
        # when it is not.
        flat = X.reshape(-1)
        with np.errstate(over="ignore", invalid="ignore"):
            square = flat @ flat
        if not math.isfinite(square):
            finite = np.isfinite(X).all(axis=1)
            if not finite.all():
                raise ValueError(f"query {int(np.flatnonzero(~finite)[0])} holds NaN or inf")
        k = min(int(n_neighbors), len(self.features_))
        if graph is not None:
            return graph.batch(X, k, self.ef)
        index = self.index_
        if index is not None:
            distance, index = index.query(X, k=k)
        else:
            distance, index = _brute_force(self.features_, self.squared_norms_, X, k)
        return self.take_[index], self.frame_[index], distance

    def __getstate__(self):
        state = super().__getstate__()
        if state.pop("_graph", None) is not None:
            # faiss indexes do not pickle: their own serialisation, as bytes.
            state["index_"] = ("faiss", faiss_module().serialize_index(state["index_"]).tobytes())
        return state

    def __setstate__(self, state):
        index = state.get("index_")
        graph = isinstance(index, tuple) and index[0] == "faiss"
        if graph:
            state = dict(state, index_=None)
        super().__setstate__(state)
        if graph:
            buffer = np.frombuffer(index[1], dtype=np.uint8)
            index = faiss_module().deserialize_index(buffer)
            # Pickled before the graph had a storage order: its rows are in their own.
            order = self.__dict__.get("_graph_order")
            self._set_graph(index, np.arange(index.ntotal) if order is None else order)

    def __sklearn_tags__(self):
        tags = super().__sklearn_tags__()
        tags.requires_fit = True
        return tags


def _brute_force(data, squared_norms, X, k):
    """Exact k nearest rows by one matrix product: ``|x|^2 - 2 x.q + |q|^2``."""
    squared = squared_norms[None, :] - 2.0 * (X @ data.T) + np.einsum("ij,ij->i", X, X)[:, None]
    part = np.argpartition(squared, k - 1, axis=1)[:, :k] if k < data.shape[0] else None
    if part is None:
        part = np.broadcast_to(np.arange(data.shape[0]), squared.shape)
    order = np.take_along_axis(squared, part, axis=1).argsort(axis=1)
    index = np.take_along_axis(part, order, axis=1)
    distance = np.sqrt(np.maximum(np.take_along_axis(squared, index, axis=1), 0.0))
    return distance, index
