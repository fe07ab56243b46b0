# The C structs of one beam decode (skmotion/tree/_decoder/_beam.pyx), shared by the modules of its stages
# (_beam_candidates: a layer's candidates and emissions; _beam_memory: the views and scratch;
# _beam_passes: the scoring passes), and the small helpers both _beam and _beam_passes call in
# their inner loops, inline so each keeps its own inlined copy.

from libc.math cimport INFINITY

from skmotion.tree._decoder._pairs cimport pair_moves

ctypedef Py_ssize_t intp

# What a call computes per problem (the index into _beam.MODES).
cdef enum:
    BEST = 0
    KBEST = 1
    PRUNE = 2


cdef struct Gaussians:
    const double* means     # (n_tree_nodes, d)
    const double* prec      # diag: (n_tree_nodes, d) precisions; full: (n_tree_nodes, d, d) upper factors
    const double* shifts    # full only: (n_tree_nodes, d), mean @ factor
    const double* const_    # (n_tree_nodes,)
    const intp* lr_start    # full only: first row of a node's low-rank vectors, -1 for the factor
    const intp* lr_rank
    const double* lr_vectors
    const double* lr_weights
    const double* lr_inv_floor
    intp d
    bint full


cdef struct Table:
    const double* dense         # (K + 1, K + 1, n_graphs) log probabilities (K: no node), or NULL
    const intp* pair_start      # (K + 1,): the transitions seen from node m are pairs pair_start[m]:pair_start[m + 1]
    const intp* pair_dst        # their destinations, sorted within m
    const double* pair_log      # (n_pairs, n_graphs) their log probabilities in every graph
    const double* unseen_log    # (K + 1, n_graphs) a never-seen transition from each node; row K: -inf
    intp k
    intp n_graphs


cdef struct Layer:
    const intp* children    # (K_{l-1}, 2): layer indices here of the children of the layer above's nodes
    const intp* ids         # (K_l,): layer index -> tree node id
    Table search            # the search graphs' transitions
    Table score             # the scored graphs' transitions
    const unsigned char* search_allowed    # (n_search_graphs, K_l) nodes a search may visit, or NULL for all
    const unsigned char* score_allowed     # (n_score_graphs, K_l) nodes a scored graph may visit, or NULL
    intp k


cdef struct Work:
    # per frame of the longest clip, at most 2 n_paths candidates (the root has 1 kept node, then n_paths)
    intp* beam          # (T, n_paths) kept nodes of the layer above
    intp* next_beam
    double* beam_emit   # (T, n_paths) their emissions, when known
    double* next_emit
    intp* cand          # (slots, T, 2 n_paths) candidates of each stored layer
    double* emit        # (slots, T, 2 n_paths) their emissions
    double* masked      # (T, 2 n_paths) emissions with a scored graph's forbidden nodes at -inf
    double* steps       # (T, 2 n_paths, 2 n_paths)
    double* fwd
    double* bwd
    double* moves
    double* delta
    double* scratch
    intp* head
    intp* back          # (T, n_paths, 2 n_paths), or NULL when no paths are wanted
    double* moves_all   # (2 n_paths, 2 n_paths, P): the moves in each of a search's P graphs, gathered
    const double** move_rows  # (2 n_paths, 2 n_paths): where each pair's P moves are
    double* prev_all    # (2 n_paths, P)
    double* cur_all
    double* y           # (4 d,)


cdef struct Decode:
    # What one call decodes: the searches' inputs, the layers, the outputs and the scratch.
    const double* frames        # (n_frames, d)
    const intp* frame_start     # (n_searches,)
    const intp* n_steps         # (n_searches,)
    const intp* search_graph    # (n_searches,)
    const intp* problem_start   # (n_searches + 1,)
    const intp* score_graph     # (n_problems,)
    Layer* lays                 # entries 1 .. n_layers
    Gaussians g
    intp n_layers
    intp first_scored
    intp n_scored
    intp n_paths
    intp max_steps
    intp mode
    double* scores              # (n_problems, n_scored, n_paths)
    intp* paths                 # (n_problems, n_paths, max_steps), or NULL when no paths are wanted
    Work w
    intp* best_widths           # (n_scored,) candidates per frame at each scored layer ("prune")
    double* best_sum            # (n_problems,) summed best scores ("prune")
    bint* live                  # (n_problems,) problems that may still win their search ("prune")


cdef inline intp _pick(double* scores, intp n, double* value) noexcept nogil:
    """Index of the first maximum of ``scores[:n]``; its value goes to ``value`` and the entry to -inf."""
    cdef intp i, arg = 0
    cdef double best = scores[0]
    for i in range(1, n):
        if scores[i] > best:
            best = scores[i]
            arg = i
    scores[arg] = -INFINITY
    value[0] = best
    return arg


cdef inline const double* _moves_of(const Table* t, intp src, intp dst) noexcept nogil:
    """``log p(src -> dst)`` in every graph, ``n_graphs`` contiguous values; -inf when either is "no node"."""
    if t.dense != NULL:  # no search and no branch: "no node" is row and column K
        return t.dense + ((t.k if src < 0 else src) * (t.k + 1) + (t.k if dst < 0 else dst)) * t.n_graphs
    if src < 0 or dst < 0:
        return t.unseen_log + t.k * t.n_graphs
    return pair_moves(t.pair_start, t.pair_dst, t.pair_log, t.unseen_log, t.n_graphs, src, dst)


cdef inline bint _same_row(const intp* a, const intp* b, intp n) noexcept nogil:
    cdef intp i
    for i in range(n):
        if a[i] != b[i]:
            return False
    return True
