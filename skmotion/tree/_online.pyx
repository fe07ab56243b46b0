# cython: language_level=3, boundscheck=False, wraparound=False, initializedcheck=False, cdivision=True
"""Compiled per-frame update of the causal top-down beam (see :mod:`skmotion.tree._online_stream`).

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
come back as an :class:`OnlineState`, filled in C and read lazily.
"""

from collections.abc import Mapping

import numpy as np

from cpython.buffer cimport PyBUF_C_CONTIGUOUS, PyBUF_FORMAT, PyBuffer_Release, PyObject_GetBuffer
from libc.math cimport INFINITY, exp, log1p
from libc.stdlib cimport free, malloc
from libc.string cimport memcpy

from skmotion.tree._emission cimport skm_diag_run, skm_full_run, skm_lowrank_run
from skmotion.tree._pairs cimport pair_moves

ctypedef Py_ssize_t intp


cdef struct Table:
    const intp* pair_start      # (K + 1,): transitions seen from node m are pairs pair_start[m]:pair_start[m + 1]
    const intp* pair_dst        # their destinations, sorted within m
    const double* pair_log      # (n_pairs, n_cols) log probabilities in every graph (column 0: global)
    const double* unseen_log    # (K, n_cols) a never-seen transition from each node
    intp n_cols


cdef struct Layer:
    const intp* children        # (K_{l-1}, 2) layer indices here of the layer above's children; -1 for none
    const intp* ids             # (K_l,) tree node ids
    const unsigned char* allowed  # (n_graphs, K_l) nodes each scored graph may visit, or NULL for all
    const double* log_norm      # (n_graphs,) this frame's log normaliser per graph (scored layers), or NULL
    Table table
    intp k
    bint scored
    # the moves between the last two candidate lists (a node holds for many frames, so the
    # lists repeat): (n_src, n_dst, n_cols) values, looked up again only when a list changes
    double* moves
    intp* move_src
    intp* move_dst
    intp n_src
    intp n_dst


cdef inline const double* _moves(const Table* t, intp src, intp dst) noexcept nogil:
    """``log p(src -> dst)`` in every column of the table, ``n_cols`` contiguous values."""
    return pair_moves(t.pair_start, t.pair_dst, t.pair_log, t.unseen_log, t.n_cols, src, dst)


cdef inline void _push(double v, double* out, intp P) noexcept nogil:
    """Put ``v`` into ``out[:P]``, the largest values so far in decreasing order, if it beats the last.

    Pushing every value of a list into ``out`` filled with -inf leaves its ``P``
    largest values, largest first (equal values are all kept; -inf and NaN never enter).
    """
    cdef intp r = P - 1
    while r > 0 and v > out[r - 1]:
        out[r] = out[r - 1]
        r -= 1
    out[r] = v


KEYS = ("frame", "node", "nodes", "lagged_node", "proba", "label", "next_nodes", "next_proba")


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

    cdef readonly Py_ssize_t frame, node, lagged_node
    cdef Py_ssize_t label_index, n_classes, n_best
    cdef double* proba_buf        # (n_classes,) then (n_best,): proba, next_proba
    cdef Py_ssize_t* next_buf     # (n_best,) next nodes
    cdef object classes, ancestors
    cdef object _proba, _next_nodes, _next_proba, _label, _nodes

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
        cdef double[::1] view
        if self._proba is None:
            self._proba = np.empty(self.n_classes)
            view = self._proba
            if self.n_classes:
                memcpy(&view[0], self.proba_buf, self.n_classes * sizeof(double))
        return self._proba

    @property
    def next_proba(self):
        cdef double[::1] view
        if self._next_proba is None:
            self._next_proba = np.empty(self.n_best)
            view = self._next_proba
            if self.n_best:
                memcpy(&view[0], self.proba_buf + self.n_classes, self.n_best * sizeof(double))
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
        The stream's arrays (see :class:`~skmotion.tree._online_stream.OnlineMotionStream`).
    beam, n_graphs, n_paths, stream_layer, ring : int
    """

    cdef object _keep              # the arrays the pointers point into
    cdef Layer* _layers
    cdef intp n_layers, beam, slots, n_graphs, n_paths, stream_layer, ring, d, _n_made
    # Gaussians
    cdef const double* means
    cdef const double* prec
    cdef const double* shifts
    cdef const double* const_
    cdef const intp* lr_start
    cdef const intp* lr_rank
    cdef const double* lr_vectors
    cdef const double* lr_weights
    cdef const double* lr_inv_floor
    cdef bint full
    # state (owned by the caller)
    cdef intp* cand          # (n_layers + 1, slots) candidates of the last frame at each layer, -1 for none
    cdef intp* n_cand        # (n_layers + 1,)
    cdef intp* kept          # (n_layers + 1, beam) slots of the kept candidates, best first
    cdef intp* n_kept        # (n_layers + 1,)
    cdef double* emit        # (n_layers + 1, slots) their log densities
    cdef double* delta       # (n_layers + 1, slots) global forward scores (minus the offset)
    cdef double* alpha       # (n_layers + 1, slots, n_graphs, n_paths) per-graph list scores (minus the offset)
    cdef double* delta_off   # (n_layers + 1,)
    cdef double* alpha_off   # (n_layers + 1,)
    cdef intp* ring_cand     # (ring, slots) the stream layer's candidates of the last `ring` frames
    cdef intp* ring_back     # (ring, slots) their back-pointers (slot at the frame before)
    cdef intp* counter       # (1,) frames seen
    # scratch
    cdef double* new_delta
    cdef double* new_alpha
    cdef double* new_emit
    cdef intp* new_cand
    cdef intp* parent_slot
    cdef intp* back
    cdef intp* union_slot    # (K at the stream layer,) a node's entry in the next-node union, -1 for none
    cdef double* y
    cdef double* x           # (d,) a standardised frame
    # the answers (set by `answers`): what `result` and the single-frame `step` need
    cdef object _answers     # (model, tree, classes, ancestors, arrays kept alive)
    cdef const intp* class_of_graph
    cdef const double* center
    cdef const double* scale
    cdef intp n_classes, n_best, lag
    cdef bint fast

    def __cinit__(self):
        self._layers = NULL
        self._n_made = 0
        self.new_delta = NULL
        self.new_alpha = NULL
        self.new_emit = NULL
        self.new_cand = NULL
        self.parent_slot = NULL
        self.back = NULL
        self.union_slot = NULL
        self.y = NULL
        self.x = NULL
        self.fast = False

    def __init__(self, dict gauss, list layers, dict state, intp beam, intp n_graphs, intp n_paths,
                 intp stream_layer, intp ring):
        keep = [gauss, layers, state]
        self._keep = keep
        self.n_layers = len(layers)
        self.beam = beam
        self.slots = 2 * beam
        self.n_graphs = n_graphs
        self.n_paths = n_paths
        self.stream_layer = stream_layer
        self.ring = ring
        self._set_gaussians(gauss)
        self._layers = <Layer*> malloc(max(self.n_layers, 1) * sizeof(Layer))
        if self._layers == NULL:
            raise MemoryError()
        cdef intp l
        for l in range(self.n_layers):
            self._layers[l].moves = NULL
            self._layers[l].move_src = NULL
            self._layers[l].move_dst = NULL
        self._n_made = 0
        for l in range(self.n_layers):
            self._layers[l] = self._layer(layers[l])
            self._n_made = l + 1
        self._set_state(state)
        cdef intp s = self.slots, g = max(n_graphs, 1)
        self.new_delta = <double*> malloc(s * sizeof(double))
        self.new_alpha = <double*> malloc(s * g * n_paths * sizeof(double))
        self.new_emit = <double*> malloc(s * sizeof(double))
        self.new_cand = <intp*> malloc(s * sizeof(intp))
        self.parent_slot = <intp*> malloc(s * sizeof(intp))
        self.back = <intp*> malloc(s * sizeof(intp))
        self.y = <double*> malloc(4 * max(self.d, 1) * sizeof(double))
        self.x = <double*> malloc(max(self.d, 1) * sizeof(double))
        cdef intp k = self._layers[stream_layer - 1].k if stream_layer else 1, i
        self.union_slot = <intp*> malloc(k * sizeof(intp))
        if self.union_slot == NULL:
            raise MemoryError()
        for i in range(k):
            self.union_slot[i] = -1
        if (self.new_delta == NULL or self.new_alpha == NULL or self.new_emit == NULL or self.new_cand == NULL
                or self.parent_slot == NULL or self.back == NULL or self.y == NULL or self.x == NULL):
            raise MemoryError()

    def __dealloc__(self):
        cdef intp l
        if self._layers != NULL:
            for l in range(self._n_made):
                free(self._layers[l].moves)
                free(self._layers[l].move_src)
                free(self._layers[l].move_dst)
        free(self._layers)
        free(self.new_delta)
        free(self.new_alpha)
        free(self.new_emit)
        free(self.new_cand)
        free(self.parent_slot)
        free(self.back)
        free(self.union_slot)
        free(self.y)
        free(self.x)

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
        self.means = &means[0, 0]
        self.prec = &prec[0]
        self.shifts = &shifts[0, 0]
        self.const_ = &const_[0]
        self.lr_start = &lr_start[0]
        self.lr_rank = &lr_rank[0]
        self.lr_vectors = &lr_vectors[0, 0] if lr_vectors.shape[0] else NULL
        self.lr_weights = &lr_weights[0] if lr_weights.shape[0] else NULL
        self.lr_inv_floor = &lr_inv_floor[0]
        self.d = means.shape[1]
        self.full = gauss["full"]

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
        out.moves = <double*> malloc(self.slots * self.slots * out.table.n_cols * sizeof(double))
        out.move_src = <intp*> malloc(self.slots * sizeof(intp))
        out.move_dst = <intp*> malloc(self.slots * sizeof(intp))
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
        self.cand = &cand[0, 0]
        self.n_cand = &n_cand[0]
        self.kept = &kept[0, 0]
        self.n_kept = &n_kept[0]
        self.emit = &emit[0, 0]
        self.delta = &delta[0, 0]
        self.alpha = &alpha[0, 0, 0, 0]
        self.delta_off = &delta_off[0]
        self.alpha_off = &alpha_off[0]
        self.ring_cand = &ring_cand[0, 0]
        self.ring_back = &ring_back[0, 0]
        self.counter = &counter[0]

    cdef double _density(self, const double* x, intp node) noexcept nogil:
        """``log Po(x | node)`` of tree node ``node``."""
        cdef double out
        cdef intp row
        if self.full:
            row = self.lr_start[node]
            if row >= 0:
                skm_lowrank_run(x, 1, self.d, self.means + node * self.d, self.lr_vectors + row * self.d,
                                self.lr_weights + row, self.lr_rank[node], self.lr_inv_floor[node],
                                self.const_[node], &out, 1, self.y)
            else:
                skm_full_run(x, 1, self.d, self.prec + node * self.d * self.d, self.shifts + node * self.d,
                             self.const_[node], &out, 1, self.y)
        else:
            skm_diag_run(x, 1, self.d, self.means + node * self.d, self.prec + node * self.d, self.const_[node],
                         &out, 1)
        return out

    cdef intp _candidates(self, intp l, const double* x) noexcept nogil:
        """Layer ``l``'s candidates of this frame (children of the kept nodes above) and their densities."""
        cdef const Layer* lay = &self._layers[l - 1]
        cdef intp w, side, slot, child, n = 0, parent_id
        cdef intp above = l - 1
        for w in range(self.n_kept[above]):
            slot = self.kept[above * self.beam + w]
            parent_id = -1 if above == 0 else self._layers[above - 1].ids[self.cand[above * self.slots + slot]]
            for side in range(2):
                child = lay.children[self.cand[above * self.slots + slot] * 2 + side]
                if child < 0:
                    continue
                self.new_cand[n] = child
                if lay.ids[child] == parent_id:  # a leaf copied down: the same Gaussian
                    self.new_emit[n] = self.emit[above * self.slots + slot]
                else:
                    self.new_emit[n] = self._density(x, lay.ids[child])
                n += 1
        return n

    cdef const double* _move_table(self, intp l, intp n) noexcept nogil:
        """``log p(i -> j)`` in every column, ``(n_prev, n, n_cols)``, from the previous frame's candidates."""
        cdef Layer* lay = &self._layers[l - 1]
        cdef intp i, j, c, n_prev = self.n_cand[l], cols = lay.table.n_cols
        cdef const intp* prev = self.cand + l * self.slots
        cdef const double* move
        if lay.n_src == n_prev and lay.n_dst == n:
            for i in range(n_prev):
                if lay.move_src[i] != prev[i]:
                    break
            else:
                for j in range(n):
                    if lay.move_dst[j] != self.new_cand[j]:
                        break
                else:
                    return lay.moves
        for i in range(n_prev):
            lay.move_src[i] = prev[i]
            for j in range(n):
                move = _moves(&lay.table, prev[i], self.new_cand[j])
                for c in range(cols):
                    lay.moves[(i * n + j) * cols + c] = move[c]
        for j in range(n):
            lay.move_dst[j] = self.new_cand[j]
        lay.n_src = n_prev
        lay.n_dst = n
        return lay.moves

    cdef void _forward(self, intp l, intp n, bint first) noexcept nogil:
        """The global graph's max-product step at layer ``l`` over its ``n`` new candidates."""
        cdef const Layer* lay = &self._layers[l - 1]
        cdef intp i, j, arg, n_prev = self.n_cand[l]
        cdef double best, v
        cdef const double* prev_delta = self.delta + l * self.slots
        cdef const double* moves = NULL
        cdef intp cols = lay.table.n_cols
        if not first:
            moves = self._move_table(l, n)
        for j in range(n):
            if first:
                self.new_delta[j] = self.new_emit[j]
                self.back[j] = -1
                continue
            best = -INFINITY
            arg = -1
            for i in range(n_prev):
                v = prev_delta[i] + (moves[(i * n + j) * cols] + self.new_emit[j])
                if v > best:
                    best = v
                    arg = i
            self.new_delta[j] = best
            self.back[j] = arg

    cdef void _keep_best(self, intp l, intp n) noexcept nogil:
        """The ``beam`` best new candidates by forward score, best first (ties to the lower slot)."""
        cdef intp r, j, arg, m = 0
        cdef double best
        cdef double* scratch = self.delta + l * self.slots  # overwritten next, by the new scores
        for j in range(n):
            scratch[j] = self.new_delta[j]
        for r in range(min(self.beam, n)):
            arg = -1
            best = -INFINITY
            for j in range(n):
                if scratch[j] > best:
                    best = scratch[j]
                    arg = j
            if arg < 0:
                break
            scratch[arg] = -INFINITY
            self.kept[l * self.beam + m] = arg
            m += 1
        self.n_kept[l] = m

    cdef void _classes(self, intp l, intp n, bint first) noexcept nogil:
        """Every graph's list step at a scored layer: the ``n_paths`` best sequences into each new candidate.

        Entry ``(j, g, r)``: the rank-``r`` sequence under graph ``g`` ending in
        candidate ``j`` (decreasing in ``r``; -inf when there are fewer).
        """
        cdef const Layer* lay = &self._layers[l - 1]
        cdef intp i, j, g, r, G = self.n_graphs, P = self.n_paths, n_prev = self.n_cand[l]
        cdef intp size = n * G * P
        cdef double e, move, v, top = -INFINITY
        cdef const double* prev_alpha = self.alpha + l * self.slots * G * P
        cdef const double* prev
        cdef const double* moves = NULL
        cdef intp cols = lay.table.n_cols
        cdef double* out
        if not first:
            moves = self._move_table(l, n)  # made by the global step just before: a cache hit
        for j in range(n):
            for g in range(G):
                out = self.new_alpha + (j * G + g) * P
                for r in range(P):
                    out[r] = -INFINITY
                if lay.allowed != NULL and not lay.allowed[g * lay.k + self.new_cand[j]]:
                    continue
                e = self.new_emit[j]
                if lay.log_norm != NULL:
                    e = e - lay.log_norm[g]
                if first:
                    out[0] = e
                else:
                    # each previous candidate's list is in decreasing order: once an entry
                    # misses the best P so far, the rest of its list does too
                    for i in range(n_prev):
                        move = moves[(i * n + j) * cols + 1 + g] + e
                        prev = prev_alpha + (i * G + g) * P
                        for r in range(P):
                            v = prev[r] + move
                            if not (v > out[P - 1]):
                                break
                            _push(v, out, P)
                if out[0] > top:
                    top = out[0]
        if top == -INFINITY:
            top = 0.0
        for j in range(size):
            self.alpha[l * self.slots * G * P + j] = self.new_alpha[j] - top
        self.alpha_off[l] += top

    cdef void _frame(self, const double* x, intp t) noexcept nogil:
        """One frame through every layer."""
        cdef intp l, n, j, r, s = self.slots
        cdef bint first = t == 0
        cdef double top
        cdef intp* row
        for l in range(1, self.n_layers + 1):
            n = self._candidates(l, x)
            self._forward(l, n, first)
            if self._layers[l - 1].scored and self.n_graphs:
                self._classes(l, n, first)
            self._keep_best(l, n)
            top = self.new_delta[self.kept[l * self.beam]] if self.n_kept[l] else 0.0
            for j in range(n):
                self.delta[l * s + j] = self.new_delta[j] - top
                self.emit[l * s + j] = self.new_emit[j]
                self.cand[l * s + j] = self.new_cand[j]
            self.delta_off[l] += top
            self.n_cand[l] = n
            if l == self.stream_layer:
                row = self.ring_cand + (t % self.ring) * s
                for j in range(s):
                    row[j] = self.new_cand[j] if j < n else -1
                    self.ring_back[(t % self.ring) * s + j] = self.back[j] if j < n else -1

    def advance(self, const double[:, ::1] frames, const double[::1] center, const double[::1] scale):
        """Take a chunk of raw frames ``(n, d)``, standardised here; the state arrays are updated in place.

        Returns -1, or the flat index of the first value that is not finite
        (then nothing is taken: the check runs over the whole chunk first).
        """
        cdef intp i, a, n = frames.shape[0], d = self.d
        cdef double* x = self.x
        for i in range(n):
            for a in range(d):
                if not (frames[i, a] - frames[i, a] == 0.0):  # NaN or infinite
                    return i * d + a
        with nogil:
            for i in range(n):
                for a in range(d):
                    x[a] = (frames[i, a] - center[a]) / scale[a]
                self._frame(x, self.counter[0])
                self.counter[0] += 1
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
        cdef intp a, d = self.d
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
                self.x[a] = (f[a] - self.center[a]) / self.scale[a]
        PyBuffer_Release(&view)
        if not ok:
            return None
        with nogil:
            self._frame(self.x, self.counter[0])
            self.counter[0] += 1
        return self.result()

    cpdef OnlineState result(self):
        """The answers now (after at least one frame).

        ``proba``: the class posterior, each class's value being its best
        graph's running log-likelihood (summed over the scored layers).
        ``next_nodes``/``next_proba``: the kept nodes of the stream layer
        weighted by their forward scores, carried one transition forward on
        the global graph; ties go to the lower node.
        """
        cdef OnlineState out = OnlineState.__new__(OnlineState)
        cdef intp L = self.stream_layer
        out.allocate(self.n_classes, self.n_best)
        out.frame = self.counter[0] - 1
        out.classes = self._answers[2]
        out.ancestors = self._answers[3]
        if L:
            out.node = self.cand[L * self.slots + self.kept[L * self.beam]]
            out.lagged_node = self.lagged(self.lag)
        else:
            out.node = 0
            out.lagged_node = 0 if self.counter[0] > self.lag else -1
        out.label_index = self._posterior(self.class_of_graph, out.proba_buf, self.n_classes)
        if self.n_best:
            if L:
                self._next(out.next_buf, out.proba_buf + self.n_classes, self.n_best)
            else:
                out.next_buf[0] = 0
                out.proba_buf[self.n_classes] = 1.0
        return out

    cpdef intp lagged(self, intp lag):
        """The stream layer's node ``lag`` frames back on the best sequence's backtrace, or -1."""
        cdef intp t = self.counter[0] - 1, slot, k
        if t < lag or self.n_kept[self.stream_layer] == 0:
            return -1
        slot = self.kept[self.stream_layer * self.beam]
        for k in range(lag):
            slot = self.ring_back[((t - k) % self.ring) * self.slots + slot]
        return self.ring_cand[((t - lag) % self.ring) * self.slots + slot]

    cdef double _sum_of_paths(self, intp l, intp g) noexcept nogil:
        """``log sum exp`` of graph ``g``'s ``n_paths`` best sequences at layer ``l`` (as the batch sums them)."""
        cdef intp j, r, G = self.n_graphs, P = self.n_paths
        cdef double* best = self.new_alpha  # scratch: the step's buffer, free between frames
        cdef double rest = 0.0, v
        for r in range(P):
            best[r] = -INFINITY
        for j in range(self.n_cand[l]):
            for r in range(P):  # each candidate's list is in decreasing order
                v = self.alpha[((l * self.slots + j) * G + g) * P + r]
                if not (v > best[P - 1]):
                    break
                _push(v, best, P)
        if best[0] == -INFINITY:
            return best[0]
        for r in range(1, P):
            rest += exp(best[r] - best[0])
        return best[0] + log1p(rest)

    cdef intp _posterior(self, const intp* class_of_graph, double* proba, intp n_classes) noexcept nogil:
        cdef intp l, j, g, c, G = self.n_graphs, arg = 0
        cdef double* ll = <double*> malloc(max(G, 1) * sizeof(double))
        cdef double top = -INFINITY, total = 0.0
        for g in range(G):
            ll[g] = 0.0
        for l in range(1, self.n_layers + 1):
            if self._layers[l - 1].scored:
                for g in range(G):
                    ll[g] += self._sum_of_paths(l, g) + self.alpha_off[l]
        for c in range(n_classes):
            proba[c] = -INFINITY
        for g in range(G):
            c = class_of_graph[g]
            if ll[g] > proba[c]:
                proba[c] = ll[g]
        free(ll)
        for c in range(n_classes):
            if proba[c] > top:
                top = proba[c]
                arg = c
        if top == -INFINITY:  # nothing scored (a one-layer tree): uniform
            for c in range(n_classes):
                proba[c] = 1.0 / n_classes
            return 0
        for c in range(n_classes):
            proba[c] = exp(proba[c] - top)
            total += proba[c]
        for c in range(n_classes):
            proba[c] /= total
        return arg

    cdef void _next(self, intp* next_nodes, double* next_proba, intp n_best) noexcept nogil:
        cdef intp L = self.stream_layer, r, w, m, p, u, n_union = 0, size = 0, arg, node, k
        cdef const Table* t = &self._layers[L - 1].table
        cdef intp n_kept = self.n_kept[L]
        cdef double total = 0.0, base = 0.0, best, unseen
        k = self._layers[L - 1].k
        for w in range(n_kept):
            m = self.cand[L * self.slots + self.kept[L * self.beam + w]]
            size += t.pair_start[m + 1] - t.pair_start[m]
        cdef double* weight = <double*> malloc(max(n_kept, 1) * sizeof(double))
        cdef intp* dests = <intp*> malloc(max(size, 1) * sizeof(intp))
        cdef double* value = <double*> malloc(max(size, 1) * sizeof(double))
        for w in range(n_kept):
            weight[w] = exp(self.delta[L * self.slots + self.kept[L * self.beam + w]])
            total += weight[w]
        for w in range(n_kept):
            weight[w] /= total
            m = self.cand[L * self.slots + self.kept[L * self.beam + w]]
            base += weight[w] * exp(t.unseen_log[m * t.n_cols])
        for w in range(n_kept):
            m = self.cand[L * self.slots + self.kept[L * self.beam + w]]
            unseen = exp(t.unseen_log[m * t.n_cols])
            for p in range(t.pair_start[m], t.pair_start[m + 1]):
                u = self.union_slot[t.pair_dst[p]]
                if u < 0:
                    u = self.union_slot[t.pair_dst[p]] = n_union
                    dests[u] = t.pair_dst[p]
                    value[u] = base
                    n_union += 1
                value[u] += weight[w] * (exp(t.pair_log[p * t.n_cols]) - unseen)
        for u in range(n_union):
            self.union_slot[dests[u]] = -1
        for r in range(n_best):
            arg = -1
            best = -INFINITY
            for u in range(n_union):
                if value[u] > best or (value[u] == best and arg >= 0 and dests[u] < dests[arg]):
                    best = value[u]
                    arg = u
            if arg >= 0 and best > base:
                next_nodes[r] = dests[arg]
                next_proba[r] = best
                value[arg] = -INFINITY
                continue
            # the rest share the base probability: the lowest nodes not listed yet
            node = 0
            while node < k:
                for u in range(r):
                    if next_nodes[u] == node:
                        break
                else:
                    break
                node += 1
            next_nodes[r] = node
            next_proba[r] = base
        free(weight)
        free(dests)
        free(value)
