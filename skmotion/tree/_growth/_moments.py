"""Exactly mergeable moments of tree nodes: counts, means, scatters and the fourth moment.

A node's Gaussian is a function of its frames' moments about their mean, and
two sets of frames merge without revisiting them: Chan, Golub and LeVeque's
pairwise update of the mean and scatter, with the third and fourth moments
carried as in Pebay's formulas. With ``n = na + nb``, ``e = mb - ma`` and each
part's moments about its own mean:

- mean: ``ma + e nb / n``;
- scatter ``S = sum (x - m)(x - m)^T``: ``Sa + Sb + e e^T na nb / n``;
- ``t3 = sum |x - m|^2 (x - m)`` and ``s4 = sum |x - m|^4``: each part's are
  moved to the merged mean (a shift by ``u`` turns ``t3`` into
  ``t3 - s2 u - 2 S u - n |u|^2 u`` and ``s4`` into
  ``s4 - 4 u.t3 + 2 |u|^2 s2 + 4 u^T S u + n |u|^4``, ``s2`` the trace of
  ``S``) and added.

``"diag"`` and ``"spherical"`` estimates need the scatter's diagonal or trace
only. The ``"full"`` (Ledoit-Wolf) estimate reads the whole scatter and
``s4``: its shrinkage depends on every frame, yet it is a function of these
sums, so it is updated exactly too (``O(d^2)`` per node and merge).
"""

import numpy as np

__all__ = ["Moments"]


class Moments:
    """The moments of several sets of frames (one per node), for one covariance estimator.

    Parameters
    ----------
    count : ndarray of shape (n_sets,)
    mean : ndarray of shape (n_sets, n_channels)
    scatter : ndarray
        ``(n_sets, d, d)`` for ``"full"``, the diagonals ``(n_sets, d)`` for
        ``"diag"``, the traces ``(n_sets,)`` for ``"spherical"``.
    kind : {"diag", "full", "spherical"}
    t3 : ndarray of shape (n_sets, n_channels), default=None
        ``sum |x - m|^2 (x - m)`` (``"full"`` only).
    s4 : ndarray of shape (n_sets,), default=None
        ``sum |x - m|^4`` (``"full"`` only).

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.tree._growth._moments import Moments
    >>> rng = np.random.default_rng(0)
    >>> a, b = rng.normal(size=(5, 3)), rng.normal(size=(7, 3))
    >>> merged = Moments.of(a, [0], "full").merged(Moments.of(b, [0], "full"))
    >>> whole = Moments.of(np.r_[a, b], [0], "full")
    >>> bool(np.allclose(merged.scatter, whole.scatter) and np.allclose(merged.s4, whole.s4))
    True
    """

    def __init__(self, count, mean, scatter, kind, t3=None, s4=None):
        self.count = np.asarray(count, dtype=np.int64)
        self.mean = np.asarray(mean, dtype=np.float64)
        self.scatter = np.asarray(scatter, dtype=np.float64)
        self.kind = kind
        self.t3 = t3
        self.s4 = s4

    def __len__(self):
        return len(self.count)

    @classmethod
    def of(cls, frames, starts, kind):
        """The moments of consecutive blocks of frames.

        Parameters
        ----------
        frames : ndarray of shape (n_frames, n_channels)
        starts : array-like of int
            Block ``i`` is ``frames[starts[i]:starts[i + 1]]`` (the last runs
            to the end); blocks are non-empty.
        kind : {"diag", "full", "spherical"}
        """
        X = np.asarray(frames, dtype=np.float64)
        starts = np.asarray(starts, dtype=np.intp)
        count = np.diff(np.append(starts, len(X)))
        mean = np.add.reduceat(X, starts, axis=0) / count[:, None]
        centred = X - np.repeat(mean, count, axis=0)
        sq = centred * centred
        if kind == "diag":
            return cls(count, mean, np.add.reduceat(sq, starts, axis=0), kind)
        norms = sq.sum(axis=1)
        if kind == "spherical":
            return cls(count, mean, np.add.reduceat(norms, starts), kind)
        stops = np.append(starts[1:], len(X))
        scatter = np.stack([centred[a:b].T @ centred[a:b] for a, b in zip(starts, stops)])
        t3 = np.add.reduceat(norms[:, None] * centred, starts, axis=0)
        return cls(count, mean, scatter, kind, t3, np.add.reduceat(norms * norms, starts))

    @classmethod
    def from_estimates(cls, count, mean, covariance, kind, reg):
        """Moments recovered from ``"diag"`` or ``"spherical"`` estimates (exact up to rounding).

        ``covariance - reg`` is the scatter's diagonal (mean diagonal) over the
        count. A ``"full"`` estimate hides its shrinkage and fourth moment, so
        it cannot be inverted.
        """
        if kind == "full":
            raise ValueError(
                "the moments of 'full' (Ledoit-Wolf) nodes cannot be recovered from their "
                "covariances; start the database with partial_fit to update it"
            )
        count = np.asarray(count, dtype=np.int64)
        scatter = (np.asarray(covariance, dtype=np.float64) - reg) * (
            count[:, None] if kind == "diag" else count * np.shape(mean)[1]
        )
        return cls(count, mean, scatter, kind)

    def take(self, index):
        """The moments of the chosen sets."""

        def pick(a):
            return None if a is None else a[index]

        return Moments(
            self.count[index],
            self.mean[index],
            self.scatter[index],
            self.kind,
            pick(self.t3),
            pick(self.s4),
        )

    def put(self, index, other):
        """Replace the moments of the chosen sets by ``other``'s, in place."""
        self.count[index] = other.count
        self.mean[index] = other.mean
        self.scatter[index] = other.scatter
        if self.kind == "full":
            self.t3[index] = other.t3
            self.s4[index] = other.s4

    def append(self, other):
        """Both sets of sets, one after the other (a new object)."""

        def cat(a, b):
            return None if a is None else np.concatenate([a, b])

        return Moments(
            cat(self.count, other.count),
            cat(self.mean, other.mean),
            cat(self.scatter, other.scatter),
            self.kind,
            cat(self.t3, other.t3),
            cat(self.s4, other.s4),
        )

    def merged(self, other):
        """Set by set, the moments of the frames of both (a new object)."""
        na, nb = self.count.astype(np.float64), other.count.astype(np.float64)
        n = na + nb
        e = other.mean - self.mean
        frac = np.divide(nb, n, out=np.zeros_like(n), where=n > 0)
        mean = self.mean + e * frac[:, None]
        weight = na * frac
        if self.kind == "diag":
            scatter = self.scatter + other.scatter + e * e * weight[:, None]
            return Moments(self.count + other.count, mean, scatter, self.kind)
        if self.kind == "spherical":
            scatter = self.scatter + other.scatter + np.einsum("kd,kd->k", e, e) * weight
            return Moments(self.count + other.count, mean, scatter, self.kind)
        scatter = (
            self.scatter + other.scatter + np.einsum("kd,ke->kde", e, e) * weight[:, None, None]
        )
        t3a, s4a = _shifted(self, mean - self.mean)
        t3b, s4b = _shifted(other, mean - other.mean)
        return Moments(self.count + other.count, mean, scatter, "full", t3a + t3b, s4a + s4b)

    def covariances(self, reg):
        """Every set's covariance by its estimator, as :func:`estimate_covariance` gives it."""
        n = self.count.astype(np.float64)
        d = self.mean.shape[1]
        if self.kind == "diag":
            return self.scatter / n[:, None] + reg
        if self.kind == "spherical":
            return self.scatter / (n * d) + reg
        return np.stack([_ledoit_wolf(s, c, s4, reg) for s, c, s4 in zip(self.scatter, n, self.s4)])


def _shifted(m, u):
    """``t3`` and ``s4`` of moments ``m`` taken about ``m.mean + u`` instead of ``m.mean``."""
    s2 = np.trace(m.scatter, axis1=1, axis2=2)
    su = np.einsum("kde,ke->kd", m.scatter, u)
    uu = np.einsum("kd,kd->k", u, u)
    n = m.count.astype(np.float64)
    t3 = m.t3 - s2[:, None] * u - 2.0 * su - (n * uu)[:, None] * u
    s4 = (
        m.s4
        - 4.0 * np.einsum("kd,kd->k", u, m.t3)
        + 2.0 * uu * s2
        + 4.0 * np.einsum("kd,kd->k", u, su)
        + n * uu * uu
    )
    return t3, s4


def _ledoit_wolf(scatter, n, s4, reg):
    """``estimate_covariance(scatter, n, "full", reg, sq_norms)`` from two sums of ``sq_norms``.

    Those are ``sum |x - m|^2`` (the scatter's trace) and ``sum |x - m|^4``
    (``s4``); the arithmetic is that of :func:`ledoit_wolf_shrinkage`.
    """
    d = len(scatter)
    s2 = float(np.trace(scatter))
    trace = s2 / n
    mu = trace / d
    frob = np.sum(scatter * scatter) / (n * n)
    beta = (s4 / n - frob) / (d * n)
    delta = (frob - 2.0 * mu * trace + d * mu * mu) / d
    beta = min(beta, delta)
    shrink = 1.0 if delta <= 0 else float(beta / delta)
    covariance = ((1.0 - shrink) / n) * scatter
    covariance[np.diag_indices_from(covariance)] += shrink * s2 / (n * d) + reg
    return covariance
