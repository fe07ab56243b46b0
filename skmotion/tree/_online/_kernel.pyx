# cython: language_level=3, boundscheck=False, wraparound=False, initializedcheck=False, cdivision=True
"""Compiled per-frame update of the causal top-down beam (see :mod:`skmotion.tree._online._causal`).

One call of :meth:`OnlineKernel.advance` takes a chunk of standardised frames
and, frame after frame, layer after layer (``1 .. n_layers``), with no Python
between:

1. the frame's candidates at layer ``l`` are the children of its kept nodes at
   ``l - 1`` (the root at layer 0; a leaf copied down has one child, itself,
   whose log density is carried down, not recomputed);
2. their Gaussian log densities ``log Po(x | k)`` (the loops of ``_emission.h``);
3. the forward max-product step on the global graph (column 0 of the layer's
   transition table) from the previous frame's candidates at the same layer:
   ``delta_t(j) = max_i delta_{t-1}(i) + (log p(i -> j) + e_t(j))``; the
   ``beam`` best candidates (ties to the lower slot) are the frame's kept nodes;
4. at the scored layers, the same step under every class (or clip) graph
   (columns ``1 .. n_graphs``), over the same candidates, keeping the
   ``n_paths`` best sequences into each candidate (a list Viterbi): each
   graph's ``n_paths`` best sequences, whose probabilities the classifier sums;
5. at the stream's layer, the candidates and back-pointers go to a ring of
   ``lag + 1`` frames, for the fixed-lag answer.

Every step subtracts its layer's best score from the layer's scores and adds it
to the layer's offset (so scores stay near 0 on an endless stream; the
differences, hence every decision, are those of the plain sums up to rounding).
The state lives in numpy arrays owned by the caller (they pickle); this object
holds only pointers to them and to the model's tables.

A single float64 frame can go through :meth:`OnlineKernel.step`, which checks
its buffer in C (no Python between the call and the frame's work); the answers
come back as an :class:`~skmotion.tree._online._state.OnlineState`, filled in C
and read lazily.

The kernel's C fields are one struct (``Kernel``, in ``_structs.pxd``):
the per-frame work (steps 1 to 5) is in :mod:`skmotion.tree._online._step` and
the answers in :mod:`skmotion.tree._online._answers`, functions of that struct
(calls within a module, which the compiler inlines); this module holds the
class, its setup and its Python entry points.
"""

from cpython.buffer cimport PyBUF_C_CONTIGUOUS, PyBUF_FORMAT, PyBuffer_Release, PyObject_GetBuffer
from libc.stdlib cimport free, malloc

from skmotion.tree._online._answers cimport _next, _posterior
from skmotion.tree._online._state cimport OnlineState as State  # the C type, its fields
from skmotion.tree._online._step cimport _frame
from skmotion.tree._online._structs cimport Kernel, Layer, intp


cdef class OnlineKernel:
    """The per-frame update loop over one model's tables and one stream's state arrays.

    Parameters
    ----------
    gauss : dict
        The tree's Gaussians as the compiled decoders read them (means, prec,
        shifts, const, full, lr_*).
    layers : list
        Entry ``l - 1`` for layer ``l``: ``(children, ids, pair_start,
        pair_dst, pair_log, unseen_log, allowed, log_norm, scored)``.
    state : dict
        The stream's arrays (see :class:`~skmotion.tree._online._causal.OnlineMotionStream`).
    beam, n_graphs, n_paths, stream_layer, ring : int
    """

    cdef object _keep              # the arrays the pointers point into
    cdef Kernel k                  # the C state the compiled loops read (_structs.pxd)
    # the answers (set by `answers`): what `result` and the single-frame `step` need
    cdef object _answers     # (model, tree, classes, ancestors, arrays kept alive)
    cdef const intp* class_of_graph
    cdef const double* center
    cdef const double* scale
    cdef intp n_classes, n_best, lag
    cdef bint fast

    def __cinit__(self):
        self.k._layers = NULL
        self.k._n_made = 0
        self.k.new_delta = NULL
        self.k.new_alpha = NULL
        self.k.new_emit = NULL
        self.k.new_cand = NULL
        self.k.parent_slot = NULL
        self.k.back = NULL
        self.k.union_slot = NULL
        self.k.y = NULL
        self.k.x = NULL
        self.fast = False

    def __init__(self, dict gauss, list layers, dict state, intp beam, intp n_graphs, intp n_paths,
                 intp stream_layer, intp ring):
        keep = [gauss, layers, state]
        self._keep = keep
        self.k.n_layers = len(layers)
        self.k.beam = beam
        self.k.slots = 2 * beam
        self.k.n_graphs = n_graphs
        self.k.n_paths = n_paths
        self.k.stream_layer = stream_layer
        self.k.ring = ring
        self._set_gaussians(gauss)
        self.k._layers = <Layer*> malloc(max(self.k.n_layers, 1) * sizeof(Layer))
        if self.k._layers == NULL:
            raise MemoryError()
        cdef intp l
        for l in range(self.k.n_layers):
            self.k._layers[l].moves = NULL
            self.k._layers[l].move_src = NULL
            self.k._layers[l].move_dst = NULL
        self.k._n_made = 0
        for l in range(self.k.n_layers):
            self.k._layers[l] = self._layer(layers[l])
            self.k._n_made = l + 1
        self._set_state(state)
        cdef intp s = self.k.slots, g = max(n_graphs, 1)
        self.k.new_delta = <double*> malloc(s * sizeof(double))
        self.k.new_alpha = <double*> malloc(s * g * n_paths * sizeof(double))
        self.k.new_emit = <double*> malloc(s * sizeof(double))
        self.k.new_cand = <intp*> malloc(s * sizeof(intp))
        self.k.parent_slot = <intp*> malloc(s * sizeof(intp))
        self.k.back = <intp*> malloc(s * sizeof(intp))
        self.k.y = <double*> malloc(4 * max(self.k.d, 1) * sizeof(double))
        self.k.x = <double*> malloc(max(self.k.d, 1) * sizeof(double))
        cdef intp n_nodes = self.k._layers[stream_layer - 1].k if stream_layer else 1, i
        self.k.union_slot = <intp*> malloc(n_nodes * sizeof(intp))
        if self.k.union_slot == NULL:
            raise MemoryError()
        for i in range(n_nodes):
            self.k.union_slot[i] = -1
        if (self.k.new_delta == NULL or self.k.new_alpha == NULL or self.k.new_emit == NULL
                or self.k.new_cand == NULL or self.k.parent_slot == NULL or self.k.back == NULL
                or self.k.y == NULL or self.k.x == NULL):
            raise MemoryError()

    def __dealloc__(self):
        cdef intp l
        if self.k._layers != NULL:
            for l in range(self.k._n_made):
                free(self.k._layers[l].moves)
                free(self.k._layers[l].move_src)
                free(self.k._layers[l].move_dst)
        free(self.k._layers)
        free(self.k.new_delta)
        free(self.k.new_alpha)
        free(self.k.new_emit)
        free(self.k.new_cand)
        free(self.k.parent_slot)
        free(self.k.back)
        free(self.k.union_slot)
        free(self.k.y)
        free(self.k.x)

    cdef void _set_gaussians(self, dict gauss):
        cdef const double[:, ::1] means = gauss["means"]
        cdef const double[::1] prec = gauss["prec"]
        cdef const double[:, ::1] shifts = gauss["shifts"]
        cdef const double[::1] const_ = gauss["const"]
        cdef const intp[::1] lr_start = gauss["lr_start"]
        cdef const intp[::1] lr_rank = gauss["lr_rank"]
        cdef const double[:, ::1] lr_vectors = gauss["lr_vectors"]
        cdef const double[::1] lr_weights = gauss["lr_weights"]
        cdef const double[::1] lr_inv_floor = gauss["lr_inv_floor"]
        self.k.means = &means[0, 0]
        self.k.prec = &prec[0]
        self.k.shifts = &shifts[0, 0]
        self.k.const_ = &const_[0]
        self.k.lr_start = &lr_start[0]
        self.k.lr_rank = &lr_rank[0]
        self.k.lr_vectors = &lr_vectors[0, 0] if lr_vectors.shape[0] else NULL
        self.k.lr_weights = &lr_weights[0] if lr_weights.shape[0] else NULL
        self.k.lr_inv_floor = &lr_inv_floor[0]
        self.k.d = means.shape[1]
        self.k.full = gauss["full"]

    cdef Layer _layer(self, tuple spec):
        cdef Layer out
        cdef const intp[:, ::1] children = spec[0]
        cdef const intp[::1] ids = spec[1]
        cdef const intp[::1] pair_start = spec[2]
        cdef const intp[::1] pair_dst = spec[3]
        cdef const double[:, ::1] pair_log = spec[4]
        cdef const double[:, ::1] unseen_log = spec[5]
        cdef const unsigned char[:, ::1] allowed = spec[6]
        cdef double[::1] log_norm = spec[7]
        out.children = &children[0, 0]
        out.ids = &ids[0]
        out.table.pair_start = &pair_start[0]
        out.table.pair_dst = &pair_dst[0] if pair_dst.shape[0] else NULL
        out.table.pair_log = &pair_log[0, 0] if pair_log.shape[0] else NULL
        out.table.unseen_log = &unseen_log[0, 0]
        out.table.n_cols = unseen_log.shape[1]
        out.allowed = &allowed[0, 0] if allowed.shape[0] else NULL
        out.log_norm = &log_norm[0] if log_norm.shape[0] else NULL
        out.k = ids.shape[0]
        out.scored = spec[8]
        out.moves = <double*> malloc(self.k.slots * self.k.slots * out.table.n_cols * sizeof(double))
        out.move_src = <intp*> malloc(self.k.slots * sizeof(intp))
        out.move_dst = <intp*> malloc(self.k.slots * sizeof(intp))
        out.n_src = -1
        out.n_dst = -1
        if out.moves == NULL or out.move_src == NULL or out.move_dst == NULL:
            raise MemoryError()
        return out

    cdef void _set_state(self, dict state):
        cdef intp[:, ::1] cand = state["cand"]
        cdef intp[::1] n_cand = state["n_cand"]
        cdef intp[:, ::1] kept = state["kept"]
        cdef intp[::1] n_kept = state["n_kept"]
        cdef double[:, ::1] emit = state["emit"]
        cdef double[:, ::1] delta = state["delta"]
        cdef double[:, :, :, ::1] alpha = state["alpha"]
        cdef double[::1] delta_off = state["delta_off"]
        cdef double[::1] alpha_off = state["alpha_off"]
        cdef intp[:, ::1] ring_cand = state["ring_cand"]
        cdef intp[:, ::1] ring_back = state["ring_back"]
        cdef intp[::1] counter = state["n_frames"]
        self.k.cand = &cand[0, 0]
        self.k.n_cand = &n_cand[0]
        self.k.kept = &kept[0, 0]
        self.k.n_kept = &n_kept[0]
        self.k.emit = &emit[0, 0]
        self.k.delta = &delta[0, 0]
        self.k.alpha = &alpha[0, 0, 0, 0]
        self.k.delta_off = &delta_off[0]
        self.k.alpha_off = &alpha_off[0]
        self.k.ring_cand = &ring_cand[0, 0]
        self.k.ring_back = &ring_back[0, 0]
        self.k.counter = &counter[0]

    def advance(self, const double[:, ::1] frames, const double[::1] center, const double[::1] scale):
        """Take a chunk of raw frames ``(n, d)``, standardised here; the state arrays are updated in place.

        Returns -1, or the flat index of the first value that is not finite
        (then nothing is taken: the check runs over the whole chunk first).
        """
        cdef intp i, a, n = frames.shape[0], d = self.k.d
        cdef double* x = self.k.x
        for i in range(n):
            for a in range(d):
                if not (frames[i, a] - frames[i, a] == 0.0):  # NaN or infinite
                    return i * d + a
        with nogil:
            for i in range(n):
                for a in range(d):
                    x[a] = (frames[i, a] - center[a]) / scale[a]
                _frame(&self.k, x, self.k.counter[0])
                self.k.counter[0] += 1
        return -1

    def answers(self, model, tree, classes, const intp[::1] class_of_graph, ancestors, intp n_best,
                intp lag, const double[::1] center, const double[::1] scale, bint fast):
        """What :meth:`result` reports and :meth:`step` checks: set once per stream.

        ``fast``: single frames may take :meth:`step` (False under
        ``node_prior="graph"``, whose normalisers are computed in numpy).
        """
        self._answers = (model, tree, classes, ancestors, class_of_graph, center, scale)
        self.class_of_graph = &class_of_graph[0]
        self.center = &center[0]
        self.scale = &scale[0]
        self.n_classes = len(classes)
        self.n_best = n_best
        self.lag = lag
        self.fast = fast

    def step(self, frame):
        """One raw frame, the common case, with no Python between: the answers, or None.

        The frame is taken when it is a C-contiguous float64 buffer of ``d``
        finite values and the model has not been fit again; otherwise nothing
        changes and None is returned (the caller's general path converts,
        checks and explains).
        """
        cdef Py_buffer view
        cdef intp a, d = self.k.d
        cdef const double* f
        cdef bint ok
        if not self.fast or self._answers[0].tree_ is not self._answers[1]:
            return None
        try:
            PyObject_GetBuffer(frame, &view, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT)
        except (BufferError, TypeError, ValueError):
            return None
        ok = view.ndim == 1 and view.shape[0] == d and view.format[0] == b"d" and view.format[1] == 0
        if ok:
            f = <const double*> view.buf
            for a in range(d):
                if not (f[a] - f[a] == 0.0):  # NaN or infinite
                    ok = False
                    break
                self.k.x[a] = (f[a] - self.center[a]) / self.scale[a]
        PyBuffer_Release(&view)
        if not ok:
            return None
        with nogil:
            _frame(&self.k, self.k.x, self.k.counter[0])
            self.k.counter[0] += 1
        return self.result()

    cpdef State result(self):
        """The answers now (after at least one frame).

        ``proba``: the class posterior, each class's value being its best
        graph's running log-likelihood (summed over the scored layers).
        ``next_nodes``/``next_proba``: the kept nodes of the stream layer
        weighted by their forward scores, carried one transition forward on
        the global graph; ties go to the lower node.
        """
        cdef State out = State.__new__(State)
        cdef intp L = self.k.stream_layer
        out.allocate(self.n_classes, self.n_best)
        out.frame = self.k.counter[0] - 1
        out.classes = self._answers[2]
        out.ancestors = self._answers[3]
        if L:
            out.node = self.k.cand[L * self.k.slots + self.k.kept[L * self.k.beam]]
            out.lagged_node = self.lagged(self.lag)
        else:
            out.node = 0
            out.lagged_node = 0 if self.k.counter[0] > self.lag else -1
        out.label_index = _posterior(&self.k, self.class_of_graph, out.proba_buf, self.n_classes)
        if self.n_best:
            if L:
                _next(&self.k, out.next_buf, out.proba_buf + self.n_classes, self.n_best)
            else:
                out.next_buf[0] = 0
                out.proba_buf[self.n_classes] = 1.0
        return out

    cpdef intp lagged(self, intp lag):
        """The stream layer's node ``lag`` frames back on the best sequence's backtrace, or -1."""
        cdef intp t = self.k.counter[0] - 1, slot, i
        if t < lag or self.k.n_kept[self.k.stream_layer] == 0:
            return -1
        slot = self.k.kept[self.k.stream_layer * self.k.beam]
        for i in range(lag):
            slot = self.k.ring_back[((t - i) % self.k.ring) * self.k.slots + slot]
        return self.k.ring_cand[((t - lag) % self.k.ring) * self.k.slots + slot]

