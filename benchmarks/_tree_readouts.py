"""Readouts of a motion tree measured in bench_tree.py's defaults study but not kept in skmotion.

Each is a transformer over a fitted :class:`MotionTreeEncoder` (same tree, same
routing), so its row in the study differs from the encoder's rows by the
readout alone:

- ``"soft"``: residuals with soft assignment of frames to a layer's nodes (the
  posterior of the nodes as diagonal Gaussians weighted by their share of the
  training frames, log-likelihoods divided by ``temperature``) instead of each
  frame counting for its own node only;
- ``"fisher"``: residuals with their second order (per node and channel, the
  mean of ``(z - mean) ** 2 / variance - 1`` over the clip's frames in the node:
  a Fisher vector's variance terms), each block power- and unit-normalised;
- ``"pyramid"``: the residuals over the halves and thirds of the clip as well;
- ``"ensemble"``: ``n_trees`` encoders, the first on all training frames, the
  others on bootstrap samples of them, columns concatenated (each tree's
  divided by ``sqrt(n_trees)``), as sklearn's ``RandomTreesEmbedding`` does with
  random trees;
- ``"meansquare"``: the encoder's residuals and moments, with the mean square
  minus 1 in place of the root mean square minus 1 (the first form of the
  moments, measured before the square root was taken);
- ``"graph"``: occupancy histograms of every layer smoothed over the layer's
  node transition graph (training frames' steps, rows normalised):
  ``h ((1 - a) I + a P)``, ``a = 0.5``, then square-rooted.
"""

import numpy as np
import scipy.sparse as sp
from sklearn.base import BaseEstimator, TransformerMixin

from skmotion.tree import MotionTreeEncoder
from skmotion.tree._encoding._histograms import _signed_power_unit_norm
from skmotion.utils._clips import stack_clips


def _clip_average(offsets, parts=1):
    """(clip x cell) x frame matrix of 1 / frames in the cell: a product averages each cell."""
    lengths = np.diff(offsets)
    clip = np.repeat(np.arange(len(lengths)), lengths)
    cell = (np.arange(offsets[-1]) - offsets[clip]) * parts // lengths[clip]
    key = clip * parts + cell
    size = np.bincount(key, minlength=len(lengths) * parts)
    return sp.csr_matrix(
        (1.0 / size[key], (key, np.arange(offsets[-1]))), shape=(len(lengths) * parts, len(key))
    )


class TreeReadout(TransformerMixin, BaseEstimator):
    """A candidate readout of a MotionTreeEncoder's tree (see the module docstring)."""

    def __init__(
        self,
        readout="soft",
        residual_layers=(1, 3),
        moments=0,
        temperature=1.0,
        pyramid=(1, 2, 3),
        n_trees=5,
        random_state=0,
    ):
        self.readout = readout
        self.residual_layers = residual_layers
        self.moments = moments
        self.temperature = temperature
        self.pyramid = pyramid
        self.n_trees = n_trees
        self.random_state = random_state

    def fit(self, X, y=None):
        frames, offsets = stack_clips(X)
        if self.readout == "ensemble":
            rng = np.random.default_rng(self.random_state)
            first = MotionTreeEncoder(residual_layers=self.residual_layers, moments=self.moments)
            self.encoders_ = [first.fit(X)]
            for _ in range(self.n_trees - 1):
                sample = frames[rng.integers(0, len(frames), len(frames))]
                encoder = MotionTreeEncoder(residual_layers=self.residual_layers, moments=0)
                self.encoders_.append(encoder.fit([sample]))
            return self
        if self.readout == "meansquare":
            self.encoder_ = MotionTreeEncoder(residual_layers=self.residual_layers, moments=2)
            self.encoder_.fit(X)
            return self
        graph = self.readout == "graph"
        self.encoder_ = MotionTreeEncoder(
            layers="all" if graph else (),
            residual_layers=() if graph else self.residual_layers,
            moments=self.moments,
            sparse_output=False,
        ).fit(X)
        encoder = self.encoder_
        z = (frames - encoder.center_) / encoder.scale_
        layers = encoder.layers_ if graph else encoder.residual_layers_
        nodes = encoder._router.route(frames, layers)
        self.nodes_ = []  # per layer: means, variances, log weights or transition matrix
        for j, layer in enumerate(layers):
            k = encoder.tree_.n_nodes[layer]
            node = nodes[:, j]
            if graph:
                same = np.diff(np.repeat(np.arange(len(offsets) - 1), np.diff(offsets))) == 0
                steps = np.zeros((k, k))
                np.add.at(steps, (node[:-1][same], node[1:][same]), 1.0)
                rows = steps.sum(axis=1, keepdims=True)
                self.nodes_.append(np.where(rows > 0, steps / np.where(rows > 0, rows, 1), 0))
                continue
            count = np.bincount(node, minlength=k)
            mean = encoder.tree_.means(layer)
            var = np.ones_like(mean)
            for n in range(k):  # k <= 8 nodes: a loop over nodes, not frames
                if count[n] > 1:
                    var[n] = np.maximum(((z[node == n] - mean[n]) ** 2).mean(axis=0), 1e-3)
            self.nodes_.append((mean, var, np.log(np.maximum(count, 1) / len(node))))
        return self

    def transform(self, X):
        if self.readout == "meansquare":
            features = self.encoder_.transform(X)
            rms = features[:, -self.encoder_.n_features_in_ :]
            features[:, -self.encoder_.n_features_in_ :] = (rms + 1.0) ** 2 - 1.0
            return features
        if self.readout == "ensemble":
            blocks = [e.transform(X) for e in self.encoders_]
            return np.hstack(blocks) / np.sqrt(len(blocks))
        frames, offsets = stack_clips(X)
        encoder = self.encoder_
        if self.readout == "graph":
            blocks = self._graph(frames, offsets)
        else:
            blocks = self._residuals(frames, offsets)
        if self.moments:
            blocks.append(encoder.transform(X)[:, -self.moments * frames.shape[1] :])
        return np.hstack(blocks)

    def _residuals(self, frames, offsets):
        encoder = self.encoder_
        z = (frames - encoder.center_) / encoder.scale_
        nodes = encoder._router.route(frames, encoder.residual_layers_)
        blocks = []
        for j, (mean, var, log_weight) in enumerate(self.nodes_):
            k = len(mean)
            if self.readout == "soft":
                loglik = -0.5 * (((z[:, None, :] - mean) ** 2) / var).sum(-1)
                loglik = (loglik - 0.5 * np.log(var).sum(axis=1) + log_weight) / self.temperature
                q = np.exp(loglik - loglik.max(axis=1, keepdims=True))
                q /= q.sum(axis=1, keepdims=True)
            else:
                q = np.zeros((len(z), k))
                q[np.arange(len(z)), nodes[:, j]] = 1.0
            diff = z[:, None, :] - mean  # frames x nodes x channels
            levels = self.pyramid if self.readout == "pyramid" else (1,)
            for parts in levels:
                average = _clip_average(offsets, parts)
                first = average @ (q[:, :, None] * diff).reshape(len(z), -1)
                terms = [first]
                if self.readout == "fisher":
                    second = (q[:, :, None] * (diff**2 / var - 1)).reshape(len(z), -1)
                    terms.append(average @ second)
                for term in terms:
                    term = term.reshape(len(offsets) - 1, -1)
                    blocks.append(_signed_power_unit_norm(term, 0.5))
        return blocks

    def _graph(self, frames, offsets):
        encoder = self.encoder_
        nodes = encoder._router.route(frames, encoder.layers_)
        average = _clip_average(offsets)
        blocks = []
        for j, steps in enumerate(self.nodes_):
            k = len(steps)
            onehot = sp.csr_matrix(
                (np.ones(len(frames)), (np.arange(len(frames)), nodes[:, j])),
                shape=(len(frames), k),
            )
            share = np.asarray((average @ onehot).todense())
            blocks.append(np.sqrt(share @ (0.5 * np.eye(k) + 0.5 * steps)))
        return blocks
