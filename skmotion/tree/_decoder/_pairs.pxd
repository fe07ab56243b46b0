# The lookup of one transition in the sparse tables both compiled modules read (_beam, _online):
# inline, so each keeps its own inlined loop.

cdef inline const double* pair_moves(const Py_ssize_t* pair_start, const Py_ssize_t* pair_dst,
                                     const double* pair_log, const double* unseen_log, Py_ssize_t n_cols,
                                     Py_ssize_t src, Py_ssize_t dst) noexcept nogil:
    """``log p(src -> dst)`` in the ``n_cols`` columns: the seen pair's row, else ``src``'s unseen row."""
    cdef Py_ssize_t lo = pair_start[src], hi = pair_start[src + 1], end = pair_start[src + 1], mid
    while lo < hi:
        mid = (lo + hi) >> 1
        if pair_dst[mid] < dst:
            lo = mid + 1
        else:
            hi = mid
    if lo < end and pair_dst[lo] == dst:
        return pair_log + lo * n_cols
    return unseen_log + src * n_cols
