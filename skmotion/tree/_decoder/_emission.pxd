# The C loops of _emission.h, declared once for the modules that call them (_beam, _online).

cdef extern from "_emission.h" nogil:
    void skm_diag_run(const double* x, Py_ssize_t n, Py_ssize_t d, const double* mu, const double* prec, double c,
                      double* out, Py_ssize_t stride)
    void skm_full_run(const double* x, Py_ssize_t n, Py_ssize_t d, const double* factor, const double* shift,
                      double c, double* out, Py_ssize_t stride, double* y)
    void skm_lowrank_run(const double* x, Py_ssize_t n, Py_ssize_t d, const double* mu, const double* vectors,
                         const double* w, Py_ssize_t r, double inv_floor, double c, double* out, Py_ssize_t stride,
                         double* y)
    void skm_step_all(const double* prev, const double** rows, const double* emit, Py_ssize_t n_cand, Py_ssize_t P,
                      double* cur)
