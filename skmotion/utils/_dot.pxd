# A dot product of two double arrays over four accumulators: independent additions, so the
# processor overlaps them instead of waiting on one running sum. Inline, declared here once
# for the compiled modules that cimport it (tree/_encoding/_walk, neighbors/_psi_rank); the
# order of its additions is part of their results (the same doubles in every caller).


cdef inline double dot4(const double* a, const double* b, Py_ssize_t n) noexcept nogil:
    """``a . b`` over ``n`` entries: four partial sums, then ``(s0 + s1) + (s2 + s3)``."""
    cdef double s0 = 0.0, s1 = 0.0, s2 = 0.0, s3 = 0.0
    cdef Py_ssize_t i = 0
    while i + 4 <= n:
        s0 += a[i] * b[i]
        s1 += a[i + 1] * b[i + 1]
        s2 += a[i + 2] * b[i + 2]
        s3 += a[i + 3] * b[i + 3]
        i += 4
    while i < n:
        s0 += a[i] * b[i]
        i += 1
    return (s0 + s1) + (s2 + s3)
