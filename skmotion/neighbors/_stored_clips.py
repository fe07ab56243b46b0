"""The clips an IntervalIndexNeighbors holds, and the ranking of a leaf's queries against them.

:class:`StoredClips` (the object the index holds in ``_stored``): each stored
clip's tree features, label and ranking data (psi signatures or feature
vectors), appended at amortised O(new rows) cost by :class:`GrowableStore`, and
the distances of queries to them.
"""

import numpy as np

from skmotion.neighbors._leaf_kernels import euclidean_block
from skmotion.neighbors._ranking import psi_distance_block, smallest_k

__all__ = ["GrowableStore", "StoredClips"]


class GrowableStore:
    """Several arrays with one row per item, appended to together.

    Each array is kept in a buffer that doubles when full, so inserting clips
    one at a time does not copy everything stored each time; reading gives
    views of the filled rows.

    Parameters
    ----------
    names : sequence of str
        One name per stored array.

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.neighbors._stored_clips import GrowableStore
    >>> store = GrowableStore(["x", "label"])
    >>> store.append(x=np.zeros((2, 3)), label=np.array([4, 5]))
    >>> store.append(x=np.ones((1, 3)), label=np.array([6]))
    >>> len(store), store["label"].tolist(), store["x"].shape
    (3, [4, 5, 6], (3, 3))
    """

    def __init__(self, names):
        self.names = tuple(names)
        self._buffers = dict.fromkeys(self.names)
        self._n = 0

    def __len__(self):
        return self._n

    def __getitem__(self, name):
        """The filled rows of one array (a view)."""
        buffer = self._buffers[name]
        return None if buffer is None else buffer[: self._n]

    def append(self, **arrays):
        """Append rows to every array (all of them, with the same number of rows)."""
        if set(arrays) != set(self.names):
            raise ValueError(f"append needs exactly the arrays {list(self.names)}.")
        sizes = {len(a) for a in arrays.values()}
        if len(sizes) != 1:
            raise ValueError("append needs the same number of rows in every array.")
        (size,) = sizes
        need = self._n + size
        for name, new in arrays.items():
            new = np.asarray(new)
            buffer = self._buffers[name]
            if buffer is None or need > len(buffer):
                grown = np.empty(
                    (max(need, 2 * (0 if buffer is None else len(buffer))),) + new.shape[1:],
                    dtype=new.dtype,
                )
                if buffer is not None:
                    grown[: self._n] = buffer[: self._n]
                buffer = self._buffers[name] = grown
            buffer[self._n : need] = new
        self._n = need

    def nbytes(self):
        """Memory of the filled rows."""
        return sum(self[name].nbytes for name in self.names if self[name] is not None)


class StoredClips(GrowableStore):
    """The stored clips' arrays, and distances of queries to them.

    Parameters
    ----------
    metric : {"psi", "euclidean"}
        How queries are ranked: psi on the clips' signatures (``weights``,
        ``vectors``), or Euclidean distances between feature vectors (``table``).

    Examples
    --------
    >>> import numpy as np
    >>> from skmotion.neighbors._stored_clips import StoredClips
    >>> stored = StoredClips("euclidean")
    >>> table = np.array([[0.0, 0.0], [3.0, 4.0]])
    >>> stored.append_clips(np.zeros((2, 1)), table, [0, 1], ["a", "b"])
    >>> stored.distances(np.array([[0.0, 0.0]]), np.array([0]), np.array([0, 1])).tolist()
    [[0.0, 5.0]]
    """

    def __init__(self, metric):
        ranking = ("weights", "vectors") if metric == "psi" else ("table",)
        super().__init__(("tree", "encoded", "labels") + ranking)

    @classmethod
    def adopt(cls, store):
        """The StoredClips of a :class:`GrowableStore` (pickles made before this class)."""
        stored = cls.__new__(cls)
        stored.__dict__.update(store.__dict__)
        return stored

    def append_clips(self, tree_features, ranking, encoded, labels):
        """Append clips' tree features, ranking data and labels (encoded and as given)."""
        ranking = ranking if isinstance(ranking, tuple) else (ranking,)
        parts = dict(zip(self.names[3:], ranking))
        self.append(tree=tree_features, encoded=encoded, labels=labels, **parts)

    @property
    def ranking(self):
        """Signatures (weights, vectors) for psi, or the feature vectors."""
        if "table" in self.names:
            return self["table"]
        return self["weights"], self["vectors"]

    def distances(self, ranking, rows, columns):
        """Distances of queries ``rows`` (of their ranking data) to stored clips ``columns``."""
        if "table" in self.names:
            rows, columns = (np.ascontiguousarray(i, dtype=np.intp) for i in (rows, columns))
            return euclidean_block(np.ascontiguousarray(ranking), self.ranking, rows, columns)
        return psi_distance_block(ranking, self.ranking, rows, columns)

    def rank_leaf(self, columns, rows, ranking, self_ids, n_neighbors):
        """The nearest ``n_neighbors`` of queries ``rows`` among a leaf's clips ``columns``.

        A leaf with too few clips (besides the query itself when it is stored,
        ``self_ids``) is ranked against every stored clip. Returns (distances, ids).
        """
        n_usable = len(columns) - (1 if self_ids is not None else 0)
        if n_usable < n_neighbors:
            columns = np.arange(len(self))
        distances = self.distances(ranking, rows, columns)
        if self_ids is not None:
            distances[columns[None, :] == self_ids[rows][:, None]] = np.inf
        chosen, nearest = smallest_k(distances, n_neighbors)
        return nearest, columns[chosen]
