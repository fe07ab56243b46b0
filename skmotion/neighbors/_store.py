"""A growable store of per-clip arrays: appending costs amortised O(new rows)."""

import numpy as np

__all__ = ["GrowableStore"]


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
    >>> from skmotion.neighbors._store import GrowableStore
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
