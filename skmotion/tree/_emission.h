/* Gaussian log-density sums of the compiled decoder (skmotion/tree/_beam.pyx).
 *
 * Each is a sum over the channels. Written as a plain loop, the sum is a chain
 * of dependent additions that a compiler may not reorder (that would change the
 * rounding), so it runs one addition at a time; `omp simd reduction` allows the
 * reordering for these loops alone, and the build passes -fopenmp-simd (no
 * OpenMP runtime is linked). Compilers that do not know the pragma ignore it and
 * give the same sums in the sequential order.
 */
#ifndef SKMOTION_EMISSION_H
#define SKMOTION_EMISSION_H

/* sum_a prec[a] (x[a] - mu[a])^2: the Mahalanobis term of a diagonal Gaussian. */
static inline double skm_diag_maha(const double *x, const double *mu, const double *prec, Py_ssize_t d)
{
    double s = 0.0;
    Py_ssize_t a;
#pragma omp simd reduction(+:s)
    for (a = 0; a < d; a++) {
        double v = x[a] - mu[a];
        s += v * v * prec[a];
    }
    return s;
}

/* |x U - shift|^2 with U (d x d, row-major) upper triangular and shift = mean U:
 * the Mahalanobis term of a full Gaussian whose precision is U U^T. y is scratch of d. */
static inline double skm_full_maha(const double *x, const double *factor, const double *shift, Py_ssize_t d,
                                   double *y)
{
    double s = 0.0;
    Py_ssize_t a, b;
    for (b = 0; b < d; b++)
        y[b] = -shift[b];
    /* row by row: each row updates a contiguous run of y, independent per column */
    for (a = 0; a < d; a++) {
        const double xa = x[a];
        const double *row = factor + a * d;
#pragma omp simd
        for (b = a; b < d; b++)
            y[b] += xa * row[b];
    }
#pragma omp simd reduction(+:s)
    for (b = 0; b < d; b++)
        s += y[b] * y[b];
    return s;
}

#endif
