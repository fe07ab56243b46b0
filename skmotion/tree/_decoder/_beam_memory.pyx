# cython: language_level=3, boundscheck=False, wraparound=False, initializedcheck=False, cdivision=True
"""The compiled beam decoder's memory: C views of the caller's arrays, and the scratch.

:func:`_allocate` fills a :c:type:`Decode` (see :mod:`skmotion.tree._decoder._beam`)
with the layers' views of the arrays :mod:`skmotion.tree._decoder._tables` lays out
and with the scratch of the longest search; :func:`_release` frees it all.
"""

from libc.stdlib cimport free, malloc

from skmotion.tree._decoder._beam_structs cimport PRUNE, Layer, Table, Work


cdef Gaussians _gaussians(object gauss):
    cdef Gaussians g
    cdef const double[:, ::1] means = gauss["means"]
    cdef const double[::1] prec = gauss["prec"]
    cdef const double[:, ::1] shifts = gauss["shifts"]
    cdef const double[::1] const_ = gauss["const"]
    g.means = &means[0, 0]
    g.prec = &prec[0]
    g.shifts = &shifts[0, 0]
    g.const_ = &const_[0]
    cdef const intp[::1] lr_start = gauss["lr_start"]
    cdef const intp[::1] lr_rank = gauss["lr_rank"]
    cdef const double[:, ::1] lr_vectors = gauss["lr_vectors"]
    cdef const double[::1] lr_weights = gauss["lr_weights"]
    cdef const double[::1] lr_inv_floor = gauss["lr_inv_floor"]
    g.lr_start = &lr_start[0]
    g.lr_rank = &lr_rank[0]
    g.lr_vectors = &lr_vectors[0, 0] if lr_vectors.shape[0] else NULL
    g.lr_weights = &lr_weights[0] if lr_weights.shape[0] else NULL
    g.lr_inv_floor = &lr_inv_floor[0]
    g.d = means.shape[1]
    g.full = gauss["full"]
    return g


cdef Table _table(object table):
    cdef Table t
    cdef const intp[::1] pair_start = table["pair_start"]
    cdef const intp[::1] pair_dst = table["pair_dst"]
    cdef const double[:, ::1] pair_log = table["pair_log"]
    cdef const double[:, ::1] unseen_log = table["unseen_log"]
    cdef const double[::1] dense = table["dense"]
    t.pair_start = &pair_start[0]
    t.pair_dst = &pair_dst[0] if pair_dst.shape[0] else NULL
    t.pair_log = &pair_log[0, 0] if pair_log.shape[0] else NULL
    t.unseen_log = &unseen_log[0, 0]
    t.dense = &dense[0] if dense.shape[0] else NULL
    t.k = table["k"]
    t.n_graphs = table["n_graphs"]
    return t


cdef const unsigned char* _mask(const unsigned char[:, ::1] allowed):
    return &allowed[0, 0] if allowed.shape[0] else NULL


cdef Layer _layer(object spec):
    cdef Layer out
    cdef const intp[:, ::1] children = spec[0]
    cdef const intp[::1] ids = spec[1]
    out.children = &children[0, 0]
    out.ids = &ids[0]
    out.k = ids.shape[0]
    out.search = _table(spec[2])
    out.score = _table(spec[3])
    out.search_allowed = _mask(spec[4])
    out.score_allowed = _mask(spec[5])
    return out


cdef void _free_work(Work* w) noexcept:
    free(w.beam); free(w.next_beam); free(w.beam_emit); free(w.next_emit); free(w.cand); free(w.emit)
    free(w.masked); free(w.steps); free(w.fwd); free(w.bwd); free(w.moves); free(w.delta); free(w.scratch)
    free(w.head); free(w.back); free(w.y); free(w.moves_all); free(w.move_rows); free(w.prev_all)
    free(w.cur_all)


cdef bint _alloc_work(Work* w, intp max_steps, intp n_paths, intp slots, intp d, bint paths,
                      intp max_graphs) noexcept:
    cdef intp t = max(max_steps, 1), nc = 2 * n_paths, g = max(max_graphs, 1)
    w.beam = <intp*> malloc(t * n_paths * sizeof(intp))
    w.next_beam = <intp*> malloc(t * n_paths * sizeof(intp))
    w.beam_emit = <double*> malloc(t * n_paths * sizeof(double))
    w.next_emit = <double*> malloc(t * n_paths * sizeof(double))
    w.cand = <intp*> malloc(slots * t * nc * sizeof(intp))
    w.emit = <double*> malloc(slots * t * nc * sizeof(double))
    w.masked = <double*> malloc(t * nc * sizeof(double))
    w.steps = <double*> malloc(t * nc * nc * sizeof(double))
    w.fwd = <double*> malloc(t * nc * sizeof(double))
    w.bwd = <double*> malloc(t * nc * sizeof(double))
    w.moves = <double*> malloc(nc * nc * sizeof(double))
    w.delta = <double*> malloc(2 * n_paths * nc * sizeof(double))
    w.scratch = <double*> malloc(n_paths * nc * sizeof(double))
    w.head = <intp*> malloc(nc * sizeof(intp))
    w.back = <intp*> malloc(t * n_paths * nc * sizeof(intp)) if paths else NULL
    w.y = <double*> malloc(4 * max(d, 1) * sizeof(double))
    w.moves_all = <double*> malloc(nc * nc * g * sizeof(double))
    w.move_rows = <const double**> malloc(nc * nc * sizeof(double*))
    w.prev_all = <double*> malloc(nc * g * sizeof(double))
    w.cur_all = <double*> malloc(nc * g * sizeof(double))
    return not (w.beam == NULL or w.next_beam == NULL or w.beam_emit == NULL or w.next_emit == NULL
                or w.cand == NULL or w.emit == NULL or w.masked == NULL or w.steps == NULL or w.fwd == NULL
                or w.bwd == NULL or w.moves == NULL or w.delta == NULL or w.scratch == NULL or w.head == NULL
                or (paths and w.back == NULL) or w.y == NULL or w.moves_all == NULL or w.move_rows == NULL or w.prev_all == NULL
                or w.cur_all == NULL)


cdef void _release(Decode* dec) noexcept:
    _free_work(&dec.w)
    free(dec.lays)
    free(dec.best_widths)
    free(dec.best_sum)
    free(dec.live)


cdef int _allocate(Decode* dec, list layers, intp n_searches, intp n_problems) except -1:
    """The layers' views and the scratch of the longest search; a MemoryError when they do not fit.

    Everything is allocated before anything may raise, so :func:`_release` always applies.
    """
    cdef intp s, l, max_graphs = 0
    cdef intp slots = 1 + (dec.n_scored if dec.mode == PRUNE else 0)
    for s in range(n_searches):
        max_graphs = max(max_graphs, dec.problem_start[s + 1] - dec.problem_start[s])
    dec.lays = <Layer*> malloc((dec.n_layers + 1) * sizeof(Layer))
    dec.best_widths = <intp*> malloc((dec.n_scored + 1) * sizeof(intp))
    dec.best_sum = <double*> malloc(max(n_problems, 1) * sizeof(double))
    dec.live = <bint*> malloc(max(n_problems, 1) * sizeof(bint))
    cdef bint ok = _alloc_work(&dec.w, dec.max_steps, dec.n_paths, slots, dec.g.d, dec.paths != NULL,
                               max_graphs)
    if not ok or dec.lays == NULL or dec.best_widths == NULL or dec.best_sum == NULL or dec.live == NULL:
        raise MemoryError(f"decoding {dec.max_steps} frames with {2 * dec.n_paths} candidates each")
    for l in range(1, dec.n_layers + 1):
        dec.lays[l] = _layer(layers[l])
    return 0
