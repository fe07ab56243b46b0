"""Where does this motion occur in long takes: ranked occurrences of a query clip.

Two distances between the query and a stretch of a take:

- ``"znorm"``: the z-normalised Euclidean distance of every window of the
  query's length (Mueen et al., MASS, 2017), per channel, averaged over the
  channels, as stumpy's ``match`` defines it for several dimensions. The
  sliding dot products are FFT correlations computed block by block
  (overlap-save: many short transforms instead of one of the take's length,
  which keeps the work in cache); the windows' means and spreads come from a
  compiled sliding pass (``_occurrence_loops.pyx``) that is exact for
  constant windows;
- ``"dtw"``: subsequence dynamic time warping (Mueller 2007): the whole query
  is warped onto a stretch of the take that may start and end anywhere, with
  the squared Euclidean cost between frames; the distance is the square root
  of the accumulated cost, as tslearn's ``dtw_subsequence_path`` gives it.

Occurrences are chosen greedily: the smallest distance first, then, as
stumpy's ``match`` does, no window starting within ``exclusion`` frames of a
chosen one in the same take (``"znorm"``), or no path overlapping a chosen
one (``"dtw"``), and so on.
"""

from concurrent.futures import ThreadPoolExecutor
from numbers import Integral, Real

import numpy as np
import pandas as pd
from joblib import effective_n_jobs
from numpy.lib.stride_tricks import as_strided
from scipy import fft

from skmotion.neighbors import _occurrence_loops as _loops
from skmotion.utils._sklearn_compat import Interval, StrOptions, validate_params

__all__ = ["find_occurrences"]

#: Shortest FFT block of the sliding dot products: long enough that the hop
#: (the block less the query) wastes little, short enough to stay in cache.
MIN_BLOCK = 2048


def _as_frames(values, what):
    """A float64 C-contiguous ``(n_frames, n_channels)`` array; NaN or inf is an error."""
    array = np.asarray(values, dtype=np.float64)
    if array.ndim == 1:
        array = array[:, None]
    if array.ndim != 2:
        raise ValueError(f"{what} must be (n_frames, n_channels); got shape {array.shape}")
    bad = ~np.isfinite(array)
    if bad.any():
        frame, channel = np.argwhere(bad)[0]
        raise ValueError(f"{what} has a non-finite value at frame {frame}, channel {channel}")
    return np.ascontiguousarray(array)


def sliding_dots(query, series, block=None, workers=None):
    """``out[i] = sum_j query[j] * series[i + j]`` for every window, by block FFTs.

    Parameters
    ----------
    query : ndarray of shape (m,)
    series : ndarray of shape (n,), ``n >= m``
    block : int, default=None
        FFT length (a power of two at least ``2 m``); by default
        ``max(MIN_BLOCK, 32 m)`` rounded up to a power of two.
    workers : int, default=None
        Threads of the FFTs (scipy.fft's ``workers``).

    Returns
    -------
    dots : ndarray of shape (n - m + 1,)
    """
    m, n = len(query), len(series)
    if block is None:
        block = 1 << int(np.ceil(np.log2(max(MIN_BLOCK, 32 * m))))
    hop = block - m + 1
    n_windows = n - m + 1
    n_blocks = -(-n_windows // hop)
    padded = np.zeros(n_blocks * hop + m - 1)
    padded[:n] = series
    # Block b holds frames b * hop ... b * hop + block - 1; its first hop
    # circular correlations do not wrap around.
    blocks = as_strided(padded, (n_blocks, block), (hop * 8, 8), writeable=False)
    spectrum = fft.rfft(blocks, axis=1, workers=workers)
    spectrum *= np.conj(fft.rfft(query, block))
    dots = fft.irfft(spectrum, block, axis=1, workers=workers)[:, :hop]
    return dots.reshape(-1)[:n_windows]


def _znorm_profile(query, take, n_threads):
    """Mean over channels of the z-normalised distance of each window to the query.

    With several threads, each handles whole channels: the FFTs and the
    compiled pass release the GIL, and a channel's work is independent.
    """
    m, n_channels = query.shape
    # Channel-major, each channel shifted to mean 0 in one pass: shifting changes
    # no z-normalised distance but shrinks the FFT's rounding, which grows with the
    # values' size; a contiguous channel is what the FFT and the compiled pass read.
    channels = np.ascontiguousarray(take.T)
    channels -= channels.mean(axis=1, keepdims=True)

    def add_channels(which):
        total = np.zeros(len(take) - m + 1)
        for c in which:
            q = query[:, c]
            constant = bool(np.all(q == q[0]))
            dots = total if constant else sliding_dots((q - q.mean()) / q.std(), channels[c])
            _loops.add_znorm_distance(channels[c], dots, m, constant, total)
        return total

    n_threads = min(n_threads, n_channels)
    if n_threads <= 1:
        return add_channels(range(n_channels)) / n_channels
    with ThreadPoolExecutor(n_threads) as pool:
        parts = list(pool.map(add_channels, np.array_split(np.arange(n_channels), n_threads)))
    return sum(parts) / n_channels


def _dtw_profile(query, take):
    """Subsequence DTW distance of the best path ending at each take frame, and its start."""
    cost, start = _loops.subsequence_dtw(query, take)
    return np.sqrt(cost), start


def _greedy(profiles, starts, n_occurrences, exclusion):
    """Indices into the concatenated profiles, smallest first, each excluding its neighbours.

    With ``exclusion`` (z-normalised windows), the indices within ``exclusion``
    of a chosen one in the same take; without (DTW), every path that overlaps
    the chosen one (those ending at or after its start and starting at or
    before its end).
    """
    bounds = np.concatenate([[0], np.cumsum([len(p) for p in profiles])]).astype(np.intp)
    distance = np.concatenate(profiles) if profiles else np.empty(0)
    start = np.concatenate(starts) if starts else np.empty(0, dtype=np.intp)
    chosen = []
    limit = len(distance) if n_occurrences is None else n_occurrences
    while len(chosen) < limit and len(distance):
        i = int(np.argmin(distance))
        if not np.isfinite(distance[i]):
            break
        chosen.append(i)
        t = int(np.searchsorted(bounds, i, side="right")) - 1
        if exclusion is not None:
            distance[max(bounds[t], i - exclusion) : min(bounds[t + 1], i + exclusion + 1)] = np.inf
        else:
            first = bounds[t] + start[i]
            later = distance[first : bounds[t + 1]]
            later[start[first : bounds[t + 1]] <= i - bounds[t]] = np.inf
    return chosen, bounds


@validate_params(
    {
        "query": ["array-like"],
        "takes": [list, tuple],
        "metric": [StrOptions({"znorm", "dtw"})],
        "n_occurrences": [Interval(Integral, 1, None, closed="left"), None],
        "exclusion": [Interval(Integral, 0, None, closed="left"), None],
        "max_distance": [Interval(Real, 0, None, closed="both")],
        "n_jobs": [Integral, None],
    },
    prefer_skip_nested_validation=True,
)
def find_occurrences(
    query,
    takes,
    *,
    metric="znorm",
    n_occurrences=10,
    exclusion=None,
    max_distance=np.inf,
    n_jobs=None,
):
    """Ranked occurrences of a query clip in long takes: ``(take, start, end, distance)``.

    Parameters
    ----------
    query : array-like of shape (m, n_channels)
        The motion to look for: per frame, the same features as the takes
        (marker positions in the body frame, say, from
        :class:`~skmotion.preprocessing.VirtualMarkerTransform`).
    takes : list of array-like of shape (n_frames_i, n_channels)
        The recordings to search. A take shorter than the query (for
        ``"znorm"``) holds no window and contributes no occurrence.
    metric : {"znorm", "dtw"}, default="znorm"
        ``"znorm"``: windows of ``m`` frames, each channel z-normalised, the
        distances averaged over the channels (stumpy's ``match``; a constant
        channel is at 0 from a constant window and ``sqrt(m)`` from any
        other). ``"dtw"``: subsequence DTW on the raw features, any length.
    n_occurrences : int or None, default=10
        How many occurrences to return (None: all that ``max_distance`` lets through).
    exclusion : int, default=None
        ``"znorm"``: frames around a chosen occurrence's start where no other
        starts; by default ``ceil(m / 4)``, as stumpy. Not used by ``"dtw"``,
        whose occurrences never overlap.
    max_distance : float, default=inf
        Occurrences farther than this are not returned.
    n_jobs : int, default=None
        Threads (``"znorm"``), each handling whole channels; None is one, -1
        all cores.

    Returns
    -------
    occurrences : pandas.DataFrame
        Columns ``take``, ``start``, ``end`` (the frames ``start:end`` of
        that take) and ``distance``, smallest distance first. Read the first
        column as ``occurrences["take"]``: ``occurrences.take`` is pandas'
        own method.

    Raises
    ------
    ValueError
        When the query or a take holds NaN or inf (the message names the take,
        frame and channel) or the channels differ.

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.neighbors import find_occurrences
    >>> t = np.linspace(0, 20 * np.pi, 2000)
    >>> take = np.column_stack([np.sin(t), np.cos(2 * t)])
    >>> query = 3.0 * take[500:560] + 1.0         # z-normalisation ignores scale and offset
    >>> found = find_occurrences(query, [take], n_occurrences=3)
    >>> found.loc[0, ["take", "start", "end"]].tolist(), bool(found.distance[0] < 1e-6)
    ([0, 500, 560], True)
    >>> find_occurrences(take[500:560], [take], metric="dtw", n_occurrences=1).end.tolist()
    [560]
    """
    query = _as_frames(query, "the query")
    m, n_channels = query.shape
    if m < 2 and metric == "znorm":
        raise ValueError("a z-normalised query needs 2 frames or more")
    arrays = []
    for i, take in enumerate(takes):
        array = _as_frames(take, f"take {i}")
        if array.shape[1] != n_channels:
            raise ValueError(f"take {i} has {array.shape[1]} channels and the query {n_channels}")
        arrays.append(array)
    n_threads = effective_n_jobs(n_jobs)
    if metric == "znorm":
        exclusion = int(np.ceil(m / 4)) if exclusion is None else exclusion
    else:
        exclusion = None
    profiles, starts = [], []
    for take in arrays:
        if metric == "znorm":
            profile = _znorm_profile(query, take, n_threads) if len(take) >= m else np.empty(0)
            start = np.arange(len(profile))
        else:
            profile, start = _dtw_profile(query, take)
        # Farther than max_distance is never chosen (and never excludes another).
        profiles.append(np.where(profile <= max_distance, profile, np.inf))
        starts.append(start)
    chosen, bounds = _greedy(profiles, starts, n_occurrences, exclusion)
    rows = []
    for index in chosen:
        t = int(np.searchsorted(bounds, index, side="right")) - 1
        local = index - int(bounds[t])
        start = int(starts[t][local])
        end = start + m if metric == "znorm" else local + 1
        rows.append((t, start, end, float(profiles[t][local])))
    return pd.DataFrame(rows, columns=["take", "start", "end", "distance"]).astype(
        {"take": np.intp, "start": np.intp, "end": np.intp, "distance": float}
    )
