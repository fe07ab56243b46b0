# cython: language_level=3, boundscheck=False, wraparound=False, initializedcheck=False, cdivision=True
"""The online stream's answers after an update (:class:`OnlineState`), filled in C and read lazily.

The kernel (:class:`~skmotion.tree._online._kernel.OnlineKernel`) writes a state's C
buffers directly (their fields are declared in ``_state.pxd``); the
arrays are made on first access. A state pickles through
:func:`_from_values` (pickles made before the ``_online`` sub-package name it
``skmotion.tree._online._from_values``, which the package re-exports).
"""

from collections.abc import Mapping

import numpy as np

from libc.stdlib cimport free, malloc
from libc.string cimport memcpy

KEYS = ("frame", "node", "nodes", "lagged_node", "proba", "label", "next_nodes", "next_proba")


cdef object _doubles(const double* source, Py_ssize_t n):
    """A new float64 array holding a copy of ``source[:n]``."""
    out = np.empty(n)
    cdef double[::1] view = out
    if n:
        memcpy(&view[0], source, n * sizeof(double))
    return out


cdef class OnlineState:
    """The stream's answers after an update; attributes, or keys as in a ``Bunch``.

    A single-frame update must cost a few microseconds, and building a
    ``Bunch`` of three new arrays costs more than the frame's compiled work:
    the kernel writes the answers into the state's own C buffers, and the
    arrays and ``label`` are made on first access and kept. They are the
    answers at the update that returned the state: later updates do not
    change it.

    Attributes
    ----------
    frame : int
        Index of the last frame seen.
    node : int
        The current node at the stream's layer.
    nodes : ndarray of int
        Its ancestors at layers ``0 .. layer`` (the node last).
    lagged_node : int
        The node ``lag`` frames back (-1 before ``lag + 1`` frames).
    proba : ndarray of shape (n_classes,)
        The class posterior.
    label : object
        The decision (an entry of the model's ``classes_``).
    next_nodes, next_proba : ndarray of shape (n_best,)
        The most likely nodes one frame ahead and their probabilities.
    """

    def __cinit__(self):
        self.proba_buf = NULL
        self.next_buf = NULL

    def __dealloc__(self):
        free(self.proba_buf)
        free(self.next_buf)

    cdef int allocate(self, Py_ssize_t n_classes, Py_ssize_t n_best) except -1:
        self.n_classes = n_classes
        self.n_best = n_best
        self.proba_buf = <double*> malloc((n_classes + n_best + 1) * sizeof(double))
        self.next_buf = <Py_ssize_t*> malloc((n_best + 1) * sizeof(Py_ssize_t))
        if self.proba_buf == NULL or self.next_buf == NULL:
            raise MemoryError()
        return 0

    @property
    def proba(self):
        if self._proba is None:
            self._proba = _doubles(self.proba_buf, self.n_classes)
        return self._proba

    @property
    def next_proba(self):
        if self._next_proba is None:
            self._next_proba = _doubles(self.proba_buf + self.n_classes, self.n_best)
        return self._next_proba

    @property
    def next_nodes(self):
        cdef Py_ssize_t[::1] view
        if self._next_nodes is None:
            self._next_nodes = np.empty(self.n_best, dtype=np.intp)
            view = self._next_nodes
            if self.n_best:
                memcpy(&view[0], self.next_buf, self.n_best * sizeof(Py_ssize_t))
        return self._next_nodes

    @property
    def label(self):
        if self._label is None:
            self._label = self.classes[self.label_index]
        return self._label

    @property
    def nodes(self):
        if self._nodes is None:
            self._nodes = self.ancestors[self.node].copy()
        return self._nodes

    # -- the mapping of a Bunch ------------------------------------------------------

    def keys(self):
        return KEYS

    def values(self):
        return [getattr(self, key) for key in KEYS]

    def items(self):
        return [(key, getattr(self, key)) for key in KEYS]

    def get(self, key, default=None):
        return getattr(self, key) if key in KEYS else default

    def __getitem__(self, key):
        if key not in KEYS:
            raise KeyError(key)
        return getattr(self, key)

    def __contains__(self, key):
        return key in KEYS

    def __iter__(self):
        return iter(KEYS)

    def __len__(self):
        return len(KEYS)

    def __repr__(self):
        return f"OnlineState(frame={self.frame}, node={self.node}, label={self.label!r})"

    def __reduce__(self):
        return (_from_values, (dict(self.items()),))


def _from_values(values):
    """An OnlineState holding given answers (unpickling)."""
    cdef OnlineState out = OnlineState.__new__(OnlineState)
    out.frame, out.node, out.lagged_node = values["frame"], values["node"], values["lagged_node"]
    out._nodes, out._proba, out._label = values["nodes"], values["proba"], values["label"]
    out._next_nodes, out._next_proba = values["next_nodes"], values["next_proba"]
    out.n_classes, out.n_best = len(out._proba), len(out._next_nodes)
    return out


Mapping.register(OnlineState)
