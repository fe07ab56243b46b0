"""What the interval index reads of its input: clips or a table, their spectra, how many levels.

:func:`input_kind` (clips or feature vectors), :func:`index_spectra` (the
singular vectors and values the features and psi need), and the number of
levels the data allows (:func:`clip_level_limit`, :func:`resolve_levels`).
"""

import numpy as np
import pandas as pd
import scipy.sparse as sp

from skmotion.decomposition._clip_svd import clip_spectra
from skmotion.decomposition._svd_projection import N_VECTORS, max_svd_components

__all__ = ["clip_level_limit", "index_spectra", "input_kind", "resolve_levels"]


def input_kind(X):
    """``"table"`` for a 2-D table of feature vectors, else ``"clips"``.

    Clips are a list or tuple of 2-D arrays, a 3-D array or a ``(clip, frame)``
    DataFrame; anything else (a 2-D array, a list of 1-D rows, a plain
    DataFrame) is a table. Objects that are neither go to ``check_clips``, whose
    TypeError names what was given.

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.neighbors._index_features import input_kind
    >>> input_kind(np.zeros((4, 3))), input_kind([np.zeros((5, 3))]), input_kind(None)
    ('table', 'clips', 'clips')
    """
    if isinstance(X, (list, tuple)):
        # All rows 1-D: a list with one 1-D clip among 2-D ones is a clip collection
        # with a bad clip, which check_clips names.
        table = len(X) > 0 and all(np.ndim(x) == 1 for x in X)
    elif isinstance(X, np.ndarray):
        table = X.ndim != 3
    elif isinstance(X, pd.DataFrame):
        table = not isinstance(X.index, pd.MultiIndex)
    else:
        table = sp.issparse(X) or hasattr(X, "__array__")
    return "table" if table else "clips"


def index_spectra(clips, weighting, k, *, n_jobs=None):
    """The spectra the index needs: enough vectors for psi (``k``) and the features.

    Only the leading pairs are needed unless ``"first_two"`` weighs by all the
    singular values: then every eigenvalue is computed (``method="exact"``).
    """
    n_vectors = max(min(k, clips.n_channels), N_VECTORS[weighting])
    method = "iterative" if weighting == "first" else "exact"
    return clip_spectra(clips, n_vectors, method=method, n_jobs=n_jobs)


def clip_level_limit(clips, weighting):
    """``(limit, what)``: the most levels (feature components) these training clips allow."""
    limit = max_svd_components(len(clips), clips.n_channels, weighting)
    what = (
        f"SVD feature components the clips allow (at most the {len(clips)} training clips and "
        f"the composite vector's {N_VECTORS[weighting]} x {clips.n_channels} channels)"
    )
    return limit, what


def resolve_levels(n_levels, from_features, limit, what, default):
    """The number of levels: asked for (``n_levels`` or ``features.n_components``) or the default.

    The default is capped at ``limit``; an explicit value above it, or two
    explicit values that disagree, is an error saying how to fix it.

    Examples
    --------
    >>> from skmotion.neighbors._index_features import resolve_levels
    >>> resolve_levels(None, None, 6, "components", 7), resolve_levels(None, 3, 6, "c", 7)
    (6, 3)
    """
    if n_levels is not None and from_features not in (None, n_levels):
        raise ValueError(
            f"n_levels={n_levels} and features.n_components={from_features} disagree: "
            "the tree has one level per feature component. Set one of them (or both equal)."
        )
    asked = n_levels if n_levels is not None else from_features
    if asked is None:
        return min(default, limit)
    if asked > limit:
        raise ValueError(
            f"n_levels={asked} is more than the {limit} {what}: the tree has one level "
            f"per feature component. Pass n_levels={limit} or fewer, or n_levels=None "
            f"for min({default}, {limit})."
        )
    return int(asked)
