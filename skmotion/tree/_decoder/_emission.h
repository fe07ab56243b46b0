/* Vectorised loops of the compiled decoder (skmotion/tree/_decoder/_beam.pyx): Gaussian log densities.
 *
 * Each density is a sum over the channels. Written as a plain loop, the sum is a
 * chain of dependent additions that a compiler may not reorder (that would change
 * the rounding), so it runs one addition at a time; `omp simd reduction` allows
 * the reordering for these loops alone, and the build passes -fopenmp-simd (no
 * OpenMP runtime is linked). Compilers that do not know the pragma ignore it and
 * sum in the sequential order.
 *
 * The decoder evaluates one node on a run of consecutive frames (a node holds a
 * frame's beam slot for several frames): four frames at a time share each load of
 * the node's parameters and give four independent chains of additions (a single
 * sum waits on its own latency).
 *
 * It also holds the one step of the decoder's max-product pass that runs over several
 * graphs at once (skm_step_all): the graphs are its vector lanes.
 *
 * With GCC on x86-64 Linux these functions are built twice, for AVX2 and for the
 * baseline, and the loader picks the one the processor runs (`target_clones`): the
 * package stays portable, and AVX2 halves the time of these loops where present.
 * The AVX2 build does not fuse multiply-adds, so both give the same sums.
 */
#ifndef SKMOTION_EMISSION_H
#define SKMOTION_EMISSION_H

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__)
#define SKM_DISPATCH __attribute__((target_clones("avx2", "default")))
#define SKM_INLINE static inline __attribute__((always_inline))
#else
#define SKM_DISPATCH
#define SKM_INLINE static inline
#endif

/* sum_a prec[a] (x[a] - mu[a])^2: the Mahalanobis term of a diagonal Gaussian. */
SKM_INLINE double skm_diag_maha(const double *x, const double *mu, const double *prec, Py_ssize_t d)
{
    double s = 0.0;
    Py_ssize_t a;
#pragma omp simd reduction(+:s)
    for (a = 0; a < d; a++) {
        const double v = x[a] - mu[a];
        s += v * v * prec[a];
    }
    return s;
}

/* out[i * stride] = c - maha(x_i) / 2 for the n frames x_i = x + i d, diagonal Gaussian. */
SKM_DISPATCH static void skm_diag_run(const double *x, Py_ssize_t n, Py_ssize_t d, const double *mu, const double *prec,
                                double c, double *out, Py_ssize_t stride)
{
    Py_ssize_t i = 0, a;
    for (; i + 4 <= n; i += 4) {
        const double *x0 = x + i * d, *x1 = x0 + d, *x2 = x1 + d, *x3 = x2 + d;
        double s0 = 0.0, s1 = 0.0, s2 = 0.0, s3 = 0.0;
#pragma omp simd reduction(+:s0, s1, s2, s3)
        for (a = 0; a < d; a++) {
            const double m = mu[a], p = prec[a];
            const double v0 = x0[a] - m, v1 = x1[a] - m, v2 = x2[a] - m, v3 = x3[a] - m;
            s0 += v0 * v0 * p;
            s1 += v1 * v1 * p;
            s2 += v2 * v2 * p;
            s3 += v3 * v3 * p;
        }
        out[i * stride] = c - 0.5 * s0;
        out[(i + 1) * stride] = c - 0.5 * s1;
        out[(i + 2) * stride] = c - 0.5 * s2;
        out[(i + 3) * stride] = c - 0.5 * s3;
    }
    for (; i < n; i++)
        out[i * stride] = c - 0.5 * skm_diag_maha(x + i * d, mu, prec, d);
}

/* |x U - shift|^2 with U (d x d, row-major, zeros below the diagonal) upper triangular
 * and shift = mean U: the Mahalanobis term of a full Gaussian whose precision is U U^T.
 * y is scratch of d. */
SKM_INLINE double skm_full_maha(const double *x, const double *factor, const double *shift, Py_ssize_t d,
                                   double *y)
{
    double s = 0.0;
    Py_ssize_t a, b;
    for (b = 0; b < d; b++)
        y[b] = -shift[b];
    /* Row by row: each row updates a contiguous run of y, independent per column. A row
     * starts at the multiple of 4 at or below the diagonal: the factor holds exact zeros
     * below it, so the sums are unchanged, and every row runs in whole vector lanes
     * (the ragged starts of a strict triangle cost a third of the time at 12 channels). */
    for (a = 0; a < d; a++) {
        const double xa = x[a];
        const double *row = factor + a * d;
#pragma omp simd
        for (b = a & ~(Py_ssize_t)3; b < d; b++)
            y[b] += xa * row[b];
    }
#pragma omp simd reduction(+:s)
    for (b = 0; b < d; b++)
        s += y[b] * y[b];
    return s;
}

/* out[i * stride] = c - maha(x_i) / 2 for the n frames x_i = x + i d, full Gaussian.
 * y is scratch of 4 d. */
SKM_DISPATCH static void skm_full_run(const double *x, Py_ssize_t n, Py_ssize_t d, const double *factor,
                                const double *shift, double c, double *out, Py_ssize_t stride, double *y)
{
    Py_ssize_t i = 0, a, b;
    double *y0 = y, *y1 = y + d, *y2 = y + 2 * d, *y3 = y + 3 * d;
    for (; i + 4 <= n; i += 4) {
        const double *x0 = x + i * d, *x1 = x0 + d, *x2 = x1 + d, *x3 = x2 + d;
        double s0 = 0.0, s1 = 0.0, s2 = 0.0, s3 = 0.0;
        for (b = 0; b < d; b++)
            y0[b] = y1[b] = y2[b] = y3[b] = -shift[b];
        for (a = 0; a < d; a++) {
            const double *row = factor + a * d;
            const double a0 = x0[a], a1 = x1[a], a2 = x2[a], a3 = x3[a];
#pragma omp simd
            for (b = a & ~(Py_ssize_t)3; b < d; b++) {
                const double r = row[b];
                y0[b] += a0 * r;
                y1[b] += a1 * r;
                y2[b] += a2 * r;
                y3[b] += a3 * r;
            }
        }
#pragma omp simd reduction(+:s0, s1, s2, s3)
        for (b = 0; b < d; b++) {
            s0 += y0[b] * y0[b];
            s1 += y1[b] * y1[b];
            s2 += y2[b] * y2[b];
            s3 += y3[b] * y3[b];
        }
        out[i * stride] = c - 0.5 * s0;
        out[(i + 1) * stride] = c - 0.5 * s1;
        out[(i + 2) * stride] = c - 0.5 * s2;
        out[(i + 3) * stride] = c - 0.5 * s3;
    }
    for (; i < n; i++)
        out[i * stride] = c - 0.5 * skm_full_maha(x + i * d, factor, shift, d, y);
}

/* out[i * stride] = c - maha(x_i) / 2 for the n frames x_i = x + i d, full Gaussian in
 * low-rank form, covariance floor I + V^T diag(values) V with r orthonormal rows v_k:
 * maha = |y|^2 / floor - sum_k w_k (v_k . y)^2, y = x - mu, w_k = values_k / (floor
 * (floor + values_k)) (Woodbury). O(r d) where the triangular factor costs O(d^2 / 2).
 * y is scratch of d. */
SKM_DISPATCH static void skm_lowrank_run(const double *x, Py_ssize_t n, Py_ssize_t d, const double *mu,
                                         const double *vectors, const double *w, Py_ssize_t r, double inv_floor,
                                         double c, double *out, Py_ssize_t stride, double *y)
{
    Py_ssize_t i, a, k;
    for (i = 0; i < n; i++) {
        const double *xi = x + i * d;
        double s = 0.0;
#pragma omp simd reduction(+:s)
        for (a = 0; a < d; a++) {
            y[a] = xi[a] - mu[a];
            s += y[a] * y[a];
        }
        s *= inv_floor;
        /* four projections at a time: four independent sums */
        for (k = 0; k + 4 <= r; k += 4) {
            const double *v0 = vectors + k * d, *v1 = v0 + d, *v2 = v1 + d, *v3 = v2 + d;
            double p0 = 0.0, p1 = 0.0, p2 = 0.0, p3 = 0.0;
#pragma omp simd reduction(+:p0, p1, p2, p3)
            for (a = 0; a < d; a++) {
                p0 += v0[a] * y[a];
                p1 += v1[a] * y[a];
                p2 += v2[a] * y[a];
                p3 += v3[a] * y[a];
            }
            s -= w[k] * p0 * p0 + w[k + 1] * p1 * p1 + w[k + 2] * p2 * p2 + w[k + 3] * p3 * p3;
        }
        for (; k < r; k++) {
            const double *v = vectors + k * d;
            double p = 0.0;
#pragma omp simd reduction(+:p)
            for (a = 0; a < d; a++)
                p += v[a] * y[a];
            s -= w[k] * p * p;
        }
        out[i * stride] = c - 0.5 * s;
    }
}

/* One step of the max-product pass of several graphs at once: for every slot j,
 * cur[j][q] = max_i prev[i][q] + (rows[i n_cand + j][q] + emit[j]) over the P graphs q
 * (rows[...] points at a candidate pair's P transition log probabilities). The sums
 * and their order are those of one graph's pass; the graphs are the vector lanes. */
SKM_DISPATCH static void skm_step_all(const double *prev, const double *const *rows, const double *emit,
                                      Py_ssize_t n_cand, Py_ssize_t P, double *cur)
{
    Py_ssize_t i, j, q;
    for (j = 0; j < n_cand; j++) {
        const double e = emit[j];
        double *out = cur + j * P;
        const double *mv = rows[j];
#pragma omp simd
        for (q = 0; q < P; q++)
            out[q] = prev[q] + (mv[q] + e);
        for (i = 1; i < n_cand; i++) {
            const double *pi = prev + i * P;
            mv = rows[i * n_cand + j];
#pragma omp simd
            for (q = 0; q < P; q++) {
                const double v = pi[q] + (mv[q] + e);
                out[q] = v > out[q] ? v : out[q];
            }
        }
    }
}

#endif
