"""Motion synthesis from a motion database: node sequences from a graph, frames from the nodes.

A node sequence is a Markov chain on one transition graph at one layer: the
first node is drawn by the graph's visit frequencies, each next node by the
graph's (smoothed) transition probabilities. Frames follow the nodes'
Gaussians. Drawn independently, frames would jitter and jump at every node
change; instead the piecewise-constant path of node means is smoothed by a
Gaussian kernel of ``smoothness`` frames, and the noise (drawn from each frame's
node covariance) is smoothed by the same kernel and rescaled so that, within a
long stay in one node, each frame still has the node's covariance.
"""

import numpy as np
from scipy.ndimage import gaussian_filter1d

__all__ = ["sample_frames", "sample_nodes"]


def sample_nodes(graphs, layer, graph, n_frames, rng):
    """A node sequence (layer indices) drawn from one graph's chain.

    The smoothed probability ``(t(m, n) + s / K) / (T_m + s)`` is drawn as a
    mixture: with probability ``T_m / (T_m + s)`` a transition seen from ``m``
    (in proportion to its count), else a node uniformly. The chain is sequential:
    one short step per frame.

    Parameters
    ----------
    graphs : TransitionGraphs
    layer, graph : int
    n_frames : int
    rng : numpy.random.Generator

    Returns
    -------
    nodes : ndarray of int of shape (n_frames,)
    """
    k = graphs.n_nodes(layer)
    visits = graphs.visits(layer)[graph].astype(np.float64)
    start = visits / visits.sum() if visits.sum() > 0 else np.full(k, 1.0 / k)
    counts = graphs.counts(layer, graph).tocsr()
    indptr, indices = counts.indptr, counts.indices
    cumulative = np.cumsum(counts.data)  # searched within each row's span
    totals = graphs.row_totals(layer)[graph]
    seen = totals / (totals + graphs.smoothing)
    nodes = np.empty(n_frames, dtype=np.intp)
    nodes[0] = rng.choice(k, p=start)
    u_mix, u_pick = rng.random(n_frames), rng.random(n_frames)
    uniform = rng.integers(0, k, size=n_frames)
    for t in range(1, n_frames):
        m = nodes[t - 1]
        if u_mix[t] >= seen[m]:
            nodes[t] = uniform[t]
            continue
        lo, hi = indptr[m], indptr[m + 1]
        before = cumulative[lo - 1] if lo else 0
        target = before + u_pick[t] * totals[m]
        pos = lo + np.searchsorted(cumulative[lo:hi], target, side="right")
        nodes[t] = indices[min(pos, hi - 1)]
    return nodes


def _noise_factors(tree, ids):
    """Per tree node in ``ids``, a matrix (or vector) ``A`` with ``A A^T`` its covariance."""
    cov = tree.covariance[ids]
    if tree.covariance_type == "full":
        return np.linalg.cholesky(cov)
    return np.sqrt(cov)


def sample_frames(tree, layer, nodes, rng, smoothness=1.0):
    """Frames (in the tree's units) for a node sequence: smoothed means plus smoothed node noise.

    Parameters
    ----------
    tree : MotionTree
    layer : int
    nodes : ndarray of int of shape (n_frames,)
        Layer indices.
    rng : numpy.random.Generator
    smoothness : float, default=1.0
        Standard deviation, in frames, of the Gaussian kernel smoothing the
        means and the noise; 0 for none (independent draws, steps at node changes).

    Returns
    -------
    frames : ndarray of shape (n_frames, n_channels)
    """
    ids = tree.layers[layer][nodes]
    used, inverse = np.unique(ids, return_inverse=True)
    factors = _noise_factors(tree, used)
    z = rng.standard_normal((len(nodes), tree.n_channels))
    if tree.covariance_type == "full":
        noise = np.einsum("fij,fj->fi", factors[inverse], z)
    elif tree.covariance_type == "diag":
        noise = factors[inverse] * z
    else:
        noise = factors[inverse][:, None] * z
    means = tree.mean[ids]
    if smoothness <= 0:
        return means + noise
    impulse = np.zeros(8 * int(np.ceil(smoothness)) + 1)
    impulse[len(impulse) // 2] = 1.0
    gain = np.sqrt(np.sum(gaussian_filter1d(impulse, smoothness) ** 2))
    smooth_means = gaussian_filter1d(means, smoothness, axis=0, mode="nearest")
    return smooth_means + gaussian_filter1d(noise, smoothness, axis=0, mode="nearest") / gain


def _graph_of(est, y, rng):
    """(graphs, graph index) to sample from: the global graph, or one of class ``y``."""
    if y is None:
        return est.global_graph_, 0
    match = np.flatnonzero(est.classes_ == y)
    if not len(match):
        raise ValueError(f"y={y!r} is not a class of the model; classes_ is {list(est.classes_)}.")
    graphs = np.flatnonzero(est.graph_classes_ == match[0])
    if not est.graphs_.visits(0)[graphs].sum():
        raise ValueError(f"class {y!r} has no clip yet (added by classes=): nothing to sample.")
    # a clip graph of the class, chosen at random (graph="class": the one graph)
    return est.graphs_, int(rng.choice(graphs))


def _to_motion(est, frames, transformer, frame_rate):
    """Joint angles by the planning module's IK, as a Motion (body frame, the root in place)."""
    from skmotion.io import Motion
    from skmotion.planning import SkeletonModel

    if est.n_features_in_ % 6 or len(transformer.marker_names_) * 6 != est.n_features_in_:
        raise ValueError(
            f"transformer gives {6 * len(transformer.marker_names_)} channels, the model has "
            f"{est.n_features_in_}: joint angles need the virtual-marker clips it was fit on."
        )
    if transformer.skeleton is None:
        raise ValueError("transformer has no skeleton: there are no joint angles to solve for.")
    if frame_rate is None or not frame_rate > 0:
        raise ValueError(
            f"frame_rate must be a positive number with a transformer; got {frame_rate!r}."
        )
    model = SkeletonModel.from_transformer(transformer)
    channels, rms = model.solve(frames.reshape(len(frames), -1, 6)[..., :3])
    return Motion(model.skeleton, channels, frame_rate=float(frame_rate)), rms


def sample_model(est, n_frames, *, y, random_state, layer, smoothness, transformer, frame_rate):
    """See :meth:`MotionTreeHMM.sample`."""
    from numbers import Integral, Real

    from sklearn.utils import Bunch, check_random_state

    if not isinstance(n_frames, Integral) or isinstance(n_frames, bool) or n_frames < 1:
        raise ValueError(f"n_frames must be an int >= 1; got {n_frames!r}.")
    if not isinstance(smoothness, Real) or not smoothness >= 0:
        raise ValueError(f"smoothness must be a number >= 0; got {smoothness!r}.")
    rng = np.random.default_rng(check_random_state(random_state).randint(2**31))
    layer = est.layer_ if layer is None else est.tree_.check_layer(layer)
    graphs, graph = _graph_of(est, y, rng)
    nodes = sample_nodes(graphs, layer, graph, int(n_frames), rng)
    frames = sample_frames(est.tree_, layer, nodes, rng, float(smoothness))
    frames = frames * est.scale_ + est.center_
    out = Bunch(frames=frames, nodes=nodes, layer=layer, motion=None, ik_rms=None)
    if transformer is not None:
        out.motion, out.ik_rms = _to_motion(est, frames, transformer, frame_rate)
    return out
