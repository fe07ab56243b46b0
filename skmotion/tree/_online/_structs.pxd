# The C state of the online stream's kernel (skmotion/tree/_online/_kernel.pyx), shared by the modules that
# run it: _step (a frame through every layer) and _answers (the answers after it); and
# the small helpers of their inner loops, inline so each module keeps its own inlined copy.

from skmotion.tree._decoder._pairs cimport pair_moves

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


cdef struct Kernel:
    # the fields of an OnlineKernel the compiled loops read: pointers into the model's tables
    # and the stream's arrays (owned by the caller), and the scratch
    Layer* _layers
    intp n_layers, beam, slots, n_graphs, n_paths, stream_layer, ring, d, _n_made
    # Gaussians
    const double* means
    const double* prec
    const double* shifts
    const double* const_
    const intp* lr_start
    const intp* lr_rank
    const double* lr_vectors
    const double* lr_weights
    const double* lr_inv_floor
    bint full
    # state (owned by the caller)
    intp* cand          # (n_layers + 1, slots) candidates of the last frame at each layer, -1 for none
    intp* n_cand        # (n_layers + 1,)
    intp* kept          # (n_layers + 1, beam) slots of the kept candidates, best first
    intp* n_kept        # (n_layers + 1,)
    double* emit        # (n_layers + 1, slots) their log densities
    double* delta       # (n_layers + 1, slots) global forward scores (minus the offset)
    double* alpha       # (n_layers + 1, slots, n_graphs, n_paths) per-graph list scores (minus the offset)
    double* delta_off   # (n_layers + 1,)
    double* alpha_off   # (n_layers + 1,)
    intp* ring_cand     # (ring, slots) the stream layer's candidates of the last `ring` frames
    intp* ring_back     # (ring, slots) their back-pointers (slot at the frame before)
    intp* counter       # (1,) frames seen
    # scratch
    double* new_delta
    double* new_alpha
    double* new_emit
    intp* new_cand
    intp* parent_slot
    intp* back
    intp* union_slot    # (K at the stream layer,) a node's entry in the next-node union, -1 for none
    double* y
    double* x           # (d,) a standardised frame


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
