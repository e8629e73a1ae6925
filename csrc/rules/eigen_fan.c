/* The verification of an eigen matrix M on the infinite regular fan (rules/eigen_fan.h).
 *
 * Grid: point (s, i, j), 0 <= i, j, of sector s sits at i u_s + j u_{s+1}; (s, 0, j) is
 * (s+1, j, 0) and (s, 0, 0) is the EV V. Local coordinates may step over a spoke:
 * (s, -i, j) = (s+1, j, i) and (s, i, -j) = (s-1, j, i) (never both negative: that quadrant
 * does not exist for n != 4). Sector s stores its points with 1 <= i <= R, 0 <= j <= R (its
 * spoke s included), V is slot 0. Intervals: an edge parallel to spoke s carries d_s, so in
 * sector s's chart an edge (i..i+1, j) carries d_s for i >= 0 and d_{s+2} for i < 0 (it lies in
 * sector s+1), an edge (i, j..j+1) d_{s+1} for j >= 0 and d_{s-1} for j < 0; the interval
 * straight through V along spoke s is p_s = (d_{s-2} + d_{s+2})/2 (bspline.c's ccn__beyond).
 *
 * One level, in the engine's order (refine/level.c): green face points (tensor face rule),
 * red face points (M), green edge points (curve point H/2 + the two new face points weighted
 * by the other face's transverse interval), red spoke edge points, green vertex points (the
 * NURSS vertex rule, which is rule (7) at valence 4), red V. A fine point of ring <= 2R-1
 * reads coarse points of ring <= R only, so from an exact R-ring grid the refined (2R-1)-ring
 * grid is exact: the blending function (z = 1 at V, support inside ring 2 of that level) and
 * the 3-ring characteristic net need no boundary rules at all. */
#include "rules/eigen_fan.h"

#include "rules/bspline.h"

#include <lapacke.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#define FAN_PI 3.14159265358979323846
#define FAN_ZMIN 1e-12

typedef struct {
    int32_t n, R, dim;
    const double *d;
    double *v; /* (1 + n R (R+1)) * dim */
} fgrid;

static int32_t md(int64_t i, int32_t n) {
    int64_t r = i % n;
    return (int32_t)(r < 0 ? r + n : r);
}
static double D(const fgrid *g, int64_t k) { return g->d[md(k, g->n)]; }
static double du(const fgrid *g, int32_t s, int32_t i) { return i >= 0 ? D(g, s) : D(g, s + 2); }
static double dv(const fgrid *g, int32_t s, int32_t j) { return j >= 0 ? D(g, s + 1) : D(g, s - 1); }

static size_t grid_points(int32_t n, int32_t R) { return 1 + (size_t)n * (size_t)R * (size_t)(R + 1); }

/* Slot of local point (s, i, j); -1 beyond ring R (or in the quadrant that does not exist). */
static int64_t slot(const fgrid *g, int32_t s, int32_t i, int32_t j) {
    if (i < 0 && j < 0) return -1;
    while (!(i == 0 && j == 0)) {
        if (i < 0) { int32_t t = -i; s += 1; i = j; j = t; }
        else if (j < 0) { int32_t t = -j; s -= 1; j = i; i = t; }
        else if (i == 0) { s += 1; i = j; j = 0; }
        else break;
    }
    if (i == 0 && j == 0) return 0;
    if (i > g->R || j > g->R) return -1;
    return 1 + (int64_t)md(s, g->n) * g->R * (g->R + 1) + (int64_t)(i - 1) * (g->R + 1) + j;
}

/* Value k of local point (s, i, j) (0 beyond the grid). */
static double at(const fgrid *g, int32_t s, int32_t i, int32_t j, int k) {
    int64_t q = slot(g, s, i, j);
    return q < 0 ? 0.0 : g->v[q * g->dim + k];
}

static int grid_alloc(fgrid *g, int32_t n, int32_t R, int dim, const double *d) {
    g->n = n, g->R = R, g->dim = dim, g->d = d;
    g->v = calloc(grid_points(n, R) * (size_t)dim, sizeof(double));
    return g->v ? 0 : -1;
}

/* ---- one refinement level ------------------------------------------------------------ */

static void red_points(const fgrid *c, fgrid *f, const double *M, int which) {
    int32_t n = c->n, sz = 2 * n + 1;
    int32_t r0 = which == 0 ? 0 : which == 1 ? n : 2 * n, r1 = which == 2 ? sz : r0 + n;
    for (int32_t r = r0; r < r1; r++) {
        int64_t out = which == 2 ? 0 : slot(f, r % n, 1, which == 0 ? 1 : 0);
        for (int k = 0; k < c->dim; k++) {
            double acc = 0;
            for (int32_t j = 0; j < sz; j++) {
                double x = j == 2 * n ? c->v[k] : at(c, j % n, 1, j < n ? 1 : 0, k);
                acc += M[(size_t)r * sz + j] * x;
            }
            f->v[out * f->dim + k] = acc;
        }
    }
}

static void face_point(const fgrid *c, fgrid *f, int32_t s, int32_t i, int32_t j) {
    double su = ccn__edge_weight(du(c, s, i - 1), du(c, s, i), du(c, s, i + 1));
    double tv = ccn__edge_weight(dv(c, s, j - 1), dv(c, s, j), dv(c, s, j + 1));
    int64_t out = slot(f, s, 2 * i + 1, 2 * j + 1);
    for (int k = 0; k < c->dim; k++)
        f->v[out * f->dim + k] = (1 - su) * (1 - tv) * at(c, s, i, j, k) + su * (1 - tv) * at(c, s, i + 1, j, k) +
                                 su * tv * at(c, s, i + 1, j + 1, k) + (1 - su) * tv * at(c, s, i, j + 1, k);
}

/* Edge point of (i..i+1, j) (dir 0) or (i, j..j+1) (dir 1). */
static void edge_point(const fgrid *c, fgrid *f, int32_t s, int32_t i, int32_t j, int dir) {
    double w, ba, bb;
    int32_t ai, aj, bi, bj, qi = i + !dir, qj = j + dir;
    if (!dir) {
        w = ccn__edge_weight(du(c, s, i - 1), du(c, s, i), du(c, s, i + 1));
        ai = 2 * i + 1, aj = 2 * j + 1, bi = 2 * i + 1, bj = 2 * j - 1;
        ba = dv(c, s, j), bb = dv(c, s, j - 1);
    } else {
        w = ccn__edge_weight(dv(c, s, j - 1), dv(c, s, j), dv(c, s, j + 1));
        ai = 2 * i + 1, aj = 2 * j + 1, bi = 2 * i - 1, bj = 2 * j + 1;
        ba = du(c, s, i), bb = du(c, s, i - 1);
    }
    int64_t out = slot(f, s, 2 * i + !dir, 2 * j + dir);
    double t = 1.0 / (2.0 * (ba + bb));
    for (int k = 0; k < c->dim; k++) {
        double H = (1 - w) * at(c, s, i, j, k) + w * at(c, s, qi, qj, k);
        f->v[out * f->dim + k] = 0.5 * H + t * (bb * at(f, s, ai, aj, k) + ba * at(f, s, bi, bj, k));
    }
}

static void vertex_point(const fgrid *c, fgrid *f, int32_t s, int32_t i, int32_t j) {
    double ap = du(c, s, i), am = du(c, s, i - 1), bp = dv(c, s, j), bm = dv(c, s, j - 1);
    double beyond_m = i == 1 && j == 0 ? 0.5 * (D(c, s - 2) + D(c, s + 2)) : du(c, s, i - 2);
    double w[4] = {ccn__edge_weight(am, ap, du(c, s, i + 1)), ccn__edge_weight(ap, am, beyond_m),
                   ccn__edge_weight(bm, bp, dv(c, s, j + 1)), ccn__edge_weight(bp, bm, dv(c, s, j - 2))};
    double mw[4] = {(bp + bm) * am, (bp + bm) * ap, (ap + am) * bm, (ap + am) * bp};
    double fw[4] = {am * bm, ap * bm, ap * bp, am * bp}; /* ++, -+, --, +- */
    const int32_t qi[4] = {i + 1, i - 1, i, i}, qj[4] = {j, j, j + 1, j - 1};
    const int32_t fi[4] = {2 * i + 1, 2 * i - 1, 2 * i - 1, 2 * i + 1};
    const int32_t fj[4] = {2 * j + 1, 2 * j + 1, 2 * j - 1, 2 * j - 1};
    double sw = 0;
    for (int e = 0; e < 4; e++) sw += mw[e] + fw[e];
    int64_t out = slot(f, s, 2 * i, 2 * j);
    for (int k = 0; k < c->dim; k++) {
        double p = at(c, s, i, j, k), acc = 0;
        for (int e = 0; e < 4; e++) {
            acc += mw[e] * ((1 - w[e]) * p + w[e] * at(c, s, qi[e], qj[e], k));
            acc += fw[e] * at(f, s, fi[e], fj[e], k);
        }
        f->v[out * f->dim + k] = 0.25 * p + 0.75 * acc / sw;
    }
}

/* Refines c into f (f->R = 2 c->R - 1, allocated here). */
static int refine(const fgrid *c, fgrid *f, const double *M) {
    if (grid_alloc(f, c->n, 2 * c->R - 1, c->dim, c->d)) return -1;
    int32_t n = c->n, R = f->R;
    for (int pass = 0; pass < 3; pass++) {
        for (int32_t s = 0; s < n; s++)
            for (int32_t a = 1; a <= R; a++)
                for (int32_t b = 0; b <= R; b++) {
                    int oi = a & 1, oj = b & 1;
                    if (pass == 0 && oi && oj && !(a == 1 && b == 1)) face_point(c, f, s, a / 2, b / 2);
                    if (pass == 1 && oi && !oj && !(a == 1 && b == 0)) edge_point(c, f, s, a / 2, b / 2, 0);
                    if (pass == 1 && !oi && oj) edge_point(c, f, s, a / 2, b / 2, 1);
                    if (pass == 2 && !oi && !oj) vertex_point(c, f, s, a / 2, b / 2);
                }
        red_points(c, f, M, pass);
    }
    return 0;
}

/* ---- maxima ---------------------------------------------------------------------------- */

int32_t ccn__fan_maxima(int32_t n, const double *d, const double *M, int levels) {
    double zsum, zmax;
    int32_t maxima;
    return ccn__fan_blend_stats(n, d, M, levels, &zsum, &zmax, &maxima) ? -1 : maxima;
}

int ccn__fan_blend_stats(int32_t n, const double *d, const double *M, int levels, double *zsum,
                         double *zmax, int32_t *maxima) {
    fgrid g, h;
    if (grid_alloc(&g, n, 3, 1, d)) return -1;
    g.v[0] = 1.0;
    for (int l = 0; l < levels; l++) {
        int rc = refine(&g, &h, M);
        free(g.v);
        if (rc) return -1;
        g = h;
    }
    int32_t count = 0, R = g.R;
    double zv = g.v[0];
    *zsum = *zmax = 0;
    for (size_t q = 0; q < grid_points(n, R); q++) {
        *zsum += g.v[q];
        *zmax = fmax(*zmax, g.v[q]);
    }
    int vmax = zv > FAN_ZMIN;
    for (int32_t s = 0; s < n && vmax; s++)
        vmax = zv > at(&g, s, 1, 0, 0) && zv > at(&g, s, 1, 1, 0);
    count += vmax;
    for (int32_t s = 0; s < n; s++)
        for (int32_t i = 1; i < R; i++)
            for (int32_t j = 0; j < R; j++) {
                double z = at(&g, s, i, j, 0);
                if (!isfinite(z)) count += 1000; /* never a single maximum */
                if (!(z > FAN_ZMIN)) continue;
                int top = 1;
                for (int a = -1; a <= 1 && top; a++)
                    for (int b = -1; b <= 1 && top; b++)
                        if (a || b) top = z > at(&g, s, i + a, j + b, 0);
                count += top;
            }
    free(g.v);
    *maxima = count;
    return 0;
}

/* The margin of the single-maximum property, continuous in the z values (so in M and d).
 * Each vertex u gets f_u = (max_nb z - z_u) / max_nb |z - z_u| in [-1, 1] (neighbours: the
 * vertices sharing a face), negative exactly when u is a strict local maximum; a vertex low in
 * the tail counts less: f_u is raised to 1 as z_u falls from 2e-3 to 1e-3 of the top (a
 * ramp, so no cut-off jumps). Two maxima need two strict maxima that are not neighbours, so
 * the margin is
 *     q = min over pairs {u, v} of vertices that share no face of max(f_u, f_v),
 * negative exactly when a second maximum stands apart from the first. The pairs are a fixed
 * set and each f_u is continuous, so q is continuous: when the top moves to a neighbour, or two
 * vertices beside the top rise level with it, q passes through 0 instead of jumping. Computed
 * from the smallest f in order: the first vertex with a non-neighbour before it. */
#define FAN_TAIL_LO 1e-3
#define FAN_TAIL_HI 2e-3

typedef struct {
    double f;
    int64_t slot;
} fan_rank;

/* The neighbours (sharing a face) of slot k = (s, i, j); returns their count (<= 2n). Inside a
 * sector (i >= 2, j >= 1) they are stored in the sector's own block; elsewhere slot() maps
 * them across the spokes. */
static int neighbours(const fgrid *g, int64_t k, int32_t s, int32_t i, int32_t j, int64_t *nb) {
    int m = 0;
    if (!k) {
        for (int32_t t = 0; t < g->n; t++) nb[m++] = slot(g, t, 1, 0), nb[m++] = slot(g, t, 1, 1);
        return m;
    }
    if (i >= 2 && j >= 1 && i < g->R && j < g->R) {
        for (int a = -1; a <= 1; a++)
            for (int b = -1; b <= 1; b++)
                if (a || b) nb[m++] = k + (int64_t)a * (g->R + 1) + b;
        return m;
    }
    for (int a = -1; a <= 1; a++)
        for (int b = -1; b <= 1; b++) {
            int64_t q = a || b ? slot(g, s, i + a, j + b) : -1;
            if (q >= 0) nb[m++] = q; /* not u itself, nor the quadrant that does not exist */
        }
    return m;
}

static void slot_coords(const fgrid *g, int64_t k, int32_t *s, int32_t *i, int32_t *j) {
    *s = *i = *j = 0;
    if (!k) return;
    int64_t r = k - 1, per = (int64_t)g->R * (g->R + 1);
    *s = (int32_t)(r / per);
    r %= per;
    *i = (int32_t)(r / (g->R + 1)) + 1;
    *j = (int32_t)(r % (g->R + 1));
}

int ccn__fan_maxima_margin(int32_t n, const double *d, const double *M, int levels, double *q,
                           int32_t *maxima) {
    fgrid g, h;
    if (grid_alloc(&g, n, 3, 1, d)) return -1;
    g.v[0] = 1.0;
    for (int l = 0; l < levels; l++) {
        int rc = refine(&g, &h, M);
        free(g.v);
        if (rc) return -1;
        g = h;
    }
    size_t np = grid_points(n, g.R);
    fan_rank *rk = malloc(sizeof *rk * (size_t)(2 * n + 10));
    int64_t *nb = malloc(sizeof(int64_t) * (size_t)(2 * n + 8));
    if (!rk || !nb) { free(rk); free(nb); free(g.v); return -1; }
    double zt = 0;
    int finite = 1;
    for (size_t k = 0; k < np; k++) {
        if (!isfinite(g.v[k])) finite = 0;
        else zt = fmax(zt, g.v[k]);
    }
    /* the K smallest f, sorted (K > any neighbourhood, so a vertex apart is among them) */
    size_t m = 0, K = (size_t)(2 * n + 10);
    int32_t count = 0;
    for (size_t k = 0; k < np && finite && zt > 0; k++) {
        int32_t s, i, j;
        slot_coords(&g, (int64_t)k, &s, &i, &j);
        if (k && (i >= g.R || j >= g.R)) continue; /* the outer ring: its neighbours are not all here */
        double z = g.v[k], up = -INFINITY, spread = 0;
        int c = neighbours(&g, (int64_t)k, s, i, j, nb);
        for (int t = 0; t < c; t++) {
            double y = g.v[nb[t]] - z;
            up = y > up ? y : up;
            spread = fabs(y) > spread ? fabs(y) : spread;
        }
        double f = spread > 0 ? up / spread : 0.0;
        count += z > FAN_ZMIN && f < 0;
        double hgt = z / zt;
        if (hgt <= FAN_TAIL_LO) continue; /* f raised to 1: never below a counted one */
        if (hgt < FAN_TAIL_HI) f = fmax(f, (FAN_TAIL_HI - hgt) / (FAN_TAIL_HI - FAN_TAIL_LO));
        if (m == K && !(f < rk[K - 1].f)) continue;
        size_t at_ = m < K ? m++ : K - 1;
        while (at_ > 0 && f < rk[at_ - 1].f) { rk[at_] = rk[at_ - 1]; at_--; }
        rk[at_] = (fan_rank){f, (int64_t)k};
    }
    double margin = 1.0;
    if (finite && zt > 0) {
        for (size_t a = 1; a < m && rk[a].f < margin; a++) {
            int32_t s, i, j;
            slot_coords(&g, rk[a].slot, &s, &i, &j);
            int c = neighbours(&g, rk[a].slot, s, i, j, nb), apart = 0;
            if ((size_t)c < a) apart = 1; /* more earlier vertices than neighbours */
            for (size_t e = 0; e < a && !apart; e++) {
                int adj = 0;
                for (int t = 0; t < c && !adj; t++) adj = nb[t] == rk[e].slot;
                apart = !adj;
            }
            if (apart) margin = rk[a].f;
        }
    }
    free(rk);
    free(nb);
    free(g.v);
    *q = finite ? margin : -1.0;
    *maxima = finite ? count : 1000;
    return 0;
}

/* ---- characteristic map ------------------------------------------------------------------ */

/* 1 simple, mu2 = mu3 = lambda (real, double), |mu4| < lambda: the experiment's criteria. */
static int spectrum_ok(int32_t n, const double *M, double lambda) {
    int32_t N = 2 * n + 1;
    double *A = malloc(sizeof(double) * ((size_t)N * N + 3 * (size_t)N));
    if (!A) return -1;
    double *wr = A + (size_t)N * N, *wi = wr + N, *mod = wi + N;
    memcpy(A, M, sizeof(double) * (size_t)N * N);
    int ok = LAPACKE_dgeev(LAPACK_ROW_MAJOR, 'N', 'N', N, A, N, wr, wi, NULL, 1, NULL, 1) == 0;
    int32_t o[4] = {-1, -1, -1, -1};
    for (int32_t i = 0; ok && i < N; i++) { /* the four largest moduli, in order */
        mod[i] = hypot(wr[i], wi[i]);
        for (int k = 0; k < 4; k++) {
            if (o[k] >= 0 && !(mod[i] > mod[o[k]])) continue;
            for (int t = 3; t > k; t--) o[t] = o[t - 1];
            o[k] = i;
            break;
        }
    }
    if (ok) {
        double m2 = mod[o[1]];
        ok = fabs(wr[o[0]] - 1) <= 1e-9 && wi[o[0]] == 0 && m2 < 1 - 1e-9 &&
             hypot(wr[o[1]] - wr[o[2]], wi[o[1]] - wi[o[2]]) <= 1e-7 * m2 &&
             fabs(wi[o[1]]) <= 1e-7 * m2 && wr[o[1]] > 0 && mod[o[3]] < m2 * (1 - 1e-9) &&
             fabs(wr[o[1]] - lambda) <= 1e-9 && fabs(wr[o[2]] - lambda) <= 1e-9;
    }
    free(A);
    return ok;
}

/* The eigenvector of lambda on the 3-ring: 1-ring = P + T0/(lambda - 1) (an eigenvector of M),
 * rings 2, 3 by power iteration (refine, keep the 3-ring, divide by lambda). */
static int charnet(int32_t n, const double *d, const double *M, const double *P, const double T0[2],
                   double lambda, fgrid *g, int *converged, int iterations) {
    if (grid_alloc(g, n, 3, 2, d)) return -1;
    double c[2] = {T0[0] / (lambda - 1), T0[1] / (lambda - 1)}, scale = 0;
    for (int32_t r = 0; r <= 2 * n; r++) {
        int64_t q = r == 2 * n ? 0 : slot(g, r % n, 1, r < n ? 1 : 0);
        for (int k = 0; k < 2; k++) {
            g->v[q * 2 + k] = P[2 * r + k] + c[k];
            scale = fmax(scale, fabs(g->v[q * 2 + k]));
        }
    }
    *converged = 0;
    for (int it = 0; it < iterations && !*converged; it++) {
        fgrid h;
        if (refine(g, &h, M)) return -1;
        double change = 0;
        for (int32_t s = 0; s < n; s++)
            for (int32_t i = 1; i <= 3; i++)
                for (int32_t j = 0; j <= 3; j++) {
                    if (i == 1 && j <= 1) continue; /* the 1-ring stays the exact eigenvector */
                    int64_t q = slot(g, s, i, j);
                    for (int k = 0; k < 2; k++) {
                        double x = at(&h, s, i, j, k) / lambda;
                        change = fmax(change, fabs(x - g->v[q * 2 + k]));
                        g->v[q * 2 + k] = x;
                    }
                }
        free(h.v);
        *converged = change <= 1e-14 * scale;
    }
    return 0;
}

static double orient2(const double *a, const double *b, const double *c) {
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
}

static int seg_meet(const double *a, const double *b, const double *c, const double *e) {
    if (fmax(a[0], b[0]) < fmin(c[0], e[0]) || fmax(c[0], e[0]) < fmin(a[0], b[0]) ||
        fmax(a[1], b[1]) < fmin(c[1], e[1]) || fmax(c[1], e[1]) < fmin(a[1], b[1]))
        return 0;
    double o1 = orient2(a, b, c), o2 = orient2(a, b, e), o3 = orient2(c, e, a), o4 = orient2(c, e, b);
    return ((o1 <= 0 && o2 >= 0) || (o1 >= 0 && o2 <= 0)) && ((o3 <= 0 && o4 >= 0) || (o3 >= 0 && o4 <= 0));
}

/* Winding number of the closed polygon pts[0..m) around p; 99 if not integral. */
static int winding(const double *pts, int m, const double *p) {
    double sum = 0;
    for (int i = 0; i < m; i++) {
        const double *a = pts + 2 * i, *b = pts + 2 * ((i + 1) % m);
        double ax = a[0] - p[0], ay = a[1] - p[1], bx = b[0] - p[0], by = b[1] - p[1];
        sum += atan2(ax * by - ay * bx, ax * bx + ay * by);
    }
    double w = sum / (2 * FAN_PI);
    return fabs(w - round(w)) < 1e-6 ? (int)round(w) : 99;
}

/* Bezier points of the cubic span P0 P1 of the polygon p[0..3] = P_{-1..2}, intervals
 * e[0..4] = D_{-2..2} (knot-interval form: the inner points divide P0 P1 in the ratio
 * D_{-1} : D_0 : D_1). */
static void span_bezier(double p[4][2], const double e[5], double b[4][2]) {
    double s0 = e[0] + e[1] + e[2], s1 = e[1] + e[2] + e[3], s2 = e[2] + e[3] + e[4];
    for (int k = 0; k < 2; k++) {
        double rm = p[0][k] + (e[0] + e[1]) / s0 * (p[1][k] - p[0][k]);
        double l0 = p[1][k] + e[1] / s1 * (p[2][k] - p[1][k]);
        double r0 = p[1][k] + (e[1] + e[2]) / s1 * (p[2][k] - p[1][k]);
        double l1 = p[2][k] + e[2] / s2 * (p[3][k] - p[2][k]);
        b[0][k] = (e[2] * rm + e[1] * l0) / (e[1] + e[2]);
        b[1][k] = l0;
        b[2][k] = r0;
        b[3][k] = (e[3] * r0 + e[2] * l1) / (e[2] + e[3]);
    }
}

/* Bicubic Bezier net (a along i, b along j) of the limit patch of face (s, i..i+1, j..j+1). */
static void face_patch(const fgrid *g, int32_t s, int32_t i, int32_t j, double B[4][4][2]) {
    double eu[5], ev[5], P[4][2], T[4][4][2], b[4][2];
    for (int t = 0; t < 5; t++) eu[t] = du(g, s, i - 2 + t), ev[t] = dv(g, s, j - 2 + t);
    for (int row = 0; row < 4; row++) {
        for (int a = 0; a < 4; a++)
            for (int k = 0; k < 2; k++) P[a][k] = at(g, s, i - 1 + a, j - 1 + row, k);
        span_bezier(P, eu, b);
        for (int a = 0; a < 4; a++) memcpy(T[a][row], b[a], sizeof b[a]);
    }
    for (int a = 0; a < 4; a++) {
        span_bezier(T[a], ev, b);
        memcpy(B[a], b, sizeof b);
    }
}

/* Bernstein coefficients (bidegree 5, 5) of det J = x_u y_v - y_u x_v up to a positive factor. */
static void jacobian_bezier(double B[4][4][2], double J[6][6]) {
    static const double C2[3] = {1, 2, 1}, C3[4] = {1, 3, 3, 1}, C5[6] = {1, 5, 10, 10, 5, 1};
    memset(J, 0, sizeof(double) * 36);
    for (int a1 = 0; a1 < 3; a1++)
        for (int b1 = 0; b1 < 4; b1++) {
            double ux = B[a1 + 1][b1][0] - B[a1][b1][0], uy = B[a1 + 1][b1][1] - B[a1][b1][1];
            for (int a2 = 0; a2 < 4; a2++)
                for (int b2 = 0; b2 < 3; b2++) {
                    double vx = B[a2][b2 + 1][0] - B[a2][b2][0], vy = B[a2][b2 + 1][1] - B[a2][b2][1];
                    double w = C2[a1] * C3[a2] / C5[a1 + a2] * C3[b1] * C2[b2] / C5[b1 + b2];
                    J[a1 + a2][b1 + b2] += w * (ux * vy - uy * vx);
                }
        }
}

static void bern_split(double J[6][6], int dir, double lo[6][6], double hi[6][6]) {
    for (int l = 0; l < 6; l++) {
        double c[6];
        for (int t = 0; t < 6; t++) c[t] = dir ? J[l][t] : J[t][l];
        for (int r = 0; r < 6; r++) {
            double *L = dir ? &lo[l][r] : &lo[r][l], *H = dir ? &hi[l][5 - r] : &hi[5 - r][l];
            *L = c[0];
            *H = c[5 - r];
            for (int t = 0; t < 5 - r; t++) c[t] = 0.5 * (c[t] + c[t + 1]);
        }
    }
}

/* 1: all coefficients of sign sg; -1: a corner (a value of det J) of the other sign or 0;
 * 0: undecided after `depth` splits. */
static int jacobian_sign(double J[6][6], int sg, int depth) {
    const double corner[4] = {J[0][0], J[5][0], J[0][5], J[5][5]};
    for (int k = 0; k < 4; k++)
        if (!(sg * corner[k] > 0)) return -1;
    int all = 1;
    for (int a = 0; a < 6 && all; a++)
        for (int b = 0; b < 6 && all; b++) all = sg * J[a][b] > 0;
    if (all) return 1;
    if (depth == 0) return 0;
    double U0[6][6], U1[6][6], Q[4][6][6];
    bern_split(J, 0, U0, U1);
    bern_split(U0, 1, Q[0], Q[1]);
    bern_split(U1, 1, Q[2], Q[3]);
    int res = 1;
    for (int k = 0; k < 4 && res != -1; k++) {
        int t = jacobian_sign(Q[k], sg, depth - 1);
        res = t < res ? t : res;
    }
    return res;
}

static void bezier3(double b[4][2], double t, double out[2]) {
    for (int k = 0; k < 2; k++) {
        double u = 1 - t, a = b[0][k] * u + b[1][k] * t, c = b[1][k] * u + b[2][k] * t,
               e = b[2][k] * u + b[3][k] * t;
        a = a * u + c * t;
        c = c * u + e * t;
        out[k] = a * u + c * t;
    }
}

/* The limit curve of parameter ring r, m samples per face side (sides i = r, then j = r). */
static void ring_curve(const fgrid *g, int32_t r, int m, double *pts) {
    int k = 0;
    for (int32_t s = 0; s < g->n; s++) {
        double B[4][4][2], c[4][2];
        for (int32_t j = 0; j < r; j++) {
            face_patch(g, s, r, j, B);
            for (int b = 0; b < 4; b++) memcpy(c[b], B[0][b], sizeof c[b]);
            for (int l = 0; l < m; l++, k++) bezier3(c, (double)l / m, pts + 2 * k);
        }
        for (int32_t i = r - 1; i >= 0; i--) {
            face_patch(g, s, i, r, B);
            for (int a = 0; a < 4; a++) memcpy(c[a], B[a][0], sizeof c[a]);
            for (int l = 0; l < m; l++, k++) bezier3(c, 1.0 - (double)l / m, pts + 2 * k);
        }
    }
}

static int polygon_crossings(const double *pts, int m1, int m2) {
    int m = m1 + m2, count = 0;
    for (int e = 0; e < m; e++) {
        int pe = e >= m1, be = pe ? m1 : 0, le = pe ? m2 : m1, e1 = be + (e - be + 1) % le;
        for (int f = e + 1; f < m; f++) {
            int pf = f >= m1, bf = pf ? m1 : 0, lf = pf ? m2 : m1, f1 = bf + (f - bf + 1) % lf;
            if (pe == pf && (e1 == f || f1 == e)) continue;
            count += seg_meet(pts + 2 * e, pts + 2 * e1, pts + 2 * f, pts + 2 * f1);
        }
    }
    return count;
}

#define FAN_CURVE_SAMPLES 8

/* Regularity of the limit patches of rings R..2R and injectivity of the ring curves. */
static int surface_test(const fgrid *g, int32_t R, ccn__charmap_result *r) {
    int orient = 0;
    for (int32_t s = 0; s < g->n; s++)
        for (int32_t i = 0; i < 2 * R; i++)
            for (int32_t j = 0; j < 2 * R; j++) {
                if (i < R && j < R) continue;
                double B[4][4][2], J[6][6];
                face_patch(g, s, i, j, B);
                jacobian_bezier(B, J);
                if (!orient) orient = J[0][0] > 0 ? 1 : J[0][0] < 0 ? -1 : 0;
                int t = orient ? jacobian_sign(J, orient, 6) : -1;
                r->bad_patches += t < 0;
                r->undecided += t == 0;
            }
    r->regular = r->bad_patches == 0 && r->undecided == 0 && orient != 0;
    if (!r->regular) return 0;
    int m1 = 2 * R * g->n * FAN_CURVE_SAMPLES, m2 = 2 * m1;
    double *pts = malloc(sizeof(double) * 2 * (size_t)(m1 + m2));
    if (!pts) return -1;
    ring_curve(g, R, FAN_CURVE_SAMPLES, pts);
    ring_curve(g, 2 * R, FAN_CURVE_SAMPLES, pts + 2 * m1);
    const double origin[2] = {0, 0};
    r->injective = winding(pts, m1, origin) == orient && winding(pts + 2 * m1, m2, origin) == orient &&
                   winding(pts + 2 * m1, m2, pts) == orient && polygon_crossings(pts, m1, m2) == 0;
    free(pts);
    return 0;
}

int ccn__fan_charmap(int32_t n, const double *d, const double *M, const double *P,
                     const double T0[2], double lambda, ccn__charmap_result *r) {
    memset(r, 0, sizeof *r);
    int sp = spectrum_ok(n, M, lambda);
    if (sp < 0) return -1;
    if (!sp) return 0;
    fgrid g, h;
    int converged;
    if (charnet(n, d, M, P, T0, lambda, &g, &converged, 500)) { free(g.v); return -1; }
    r->spectrum = converged;
    int rc = 0;
    for (int l = 0; l < 2 && r->spectrum && !rc; l++) { /* rings 3 -> 5 -> 9 */
        rc = refine(&g, &h, M);
        free(g.v);
        g = h;
    }
    if (!rc && r->spectrum) rc = surface_test(&g, 2, r);
    free(g.v);
    return rc;
}

/* ---- continuous margins of the characteristic-map test --------------------------------- */

/* Spectrum: with 1 and the double lambda (which M has by construction) set aside, the
 * largest modulus left over lambda, ratio in [0, inf). Returns -1 when out of memory. */
static int spectrum_ratio(int32_t n, const double *M, double lambda, double *ratio) {
    int32_t N = 2 * n + 1;
    double *A = malloc(sizeof(double) * ((size_t)N * N + 2 * (size_t)N));
    if (!A) return -1;
    double *wr = A + (size_t)N * N, *wi = wr + N;
    memcpy(A, M, sizeof(double) * (size_t)N * N);
    *ratio = INFINITY;
    if (LAPACKE_dgeev(LAPACK_ROW_MAJOR, 'N', 'N', N, A, N, wr, wi, NULL, 1, NULL, 1) == 0) {
        int32_t skip[3] = {-1, -1, -1};
        for (int k = 0; k < 3; k++) { /* the eigenvalue nearest 1, then the two nearest lambda */
            double target = k ? lambda : 1.0, best = INFINITY;
            for (int32_t i = 0; i < N; i++) {
                if (i == skip[0] || i == skip[1]) continue;
                double dist = hypot(wr[i] - target, wi[i]);
                if (dist < best) best = dist, skip[k] = i;
            }
        }
        double mu = 0;
        for (int32_t i = 0; i < N; i++)
            if (i != skip[0] && i != skip[1] && i != skip[2]) mu = fmax(mu, hypot(wr[i], wi[i]));
        *ratio = mu / lambda;
    }
    free(A);
    return 0;
}

/* The smallest Bernstein coefficient of det J (times the orientation) after `depth` uniform
 * splits, over the largest coefficient of the patch: a lower bound of min det J / max, and a
 * continuous function of the net (the adaptive test above decides, this one measures). */
static double jacobian_margin(double J[6][6], int sg, int depth, double scale) {
    if (depth == 0) {
        double mn = INFINITY;
        for (int a = 0; a < 6; a++)
            for (int b = 0; b < 6; b++) mn = fmin(mn, sg * J[a][b]);
        return mn / scale;
    }
    double U0[6][6], U1[6][6], Q[4][6][6], m = INFINITY;
    bern_split(J, 0, U0, U1);
    bern_split(U0, 1, Q[0], Q[1]);
    bern_split(U1, 1, Q[2], Q[3]);
    for (int k = 0; k < 4; k++) m = fmin(m, jacobian_margin(Q[k], sg, depth - 1, scale));
    return m;
}

#define FAN_REG_DEPTH 2

int ccn__fan_charmap_margin(int32_t n, const double *d, const double *M, const double *P,
                            const double T0[2], double lambda, ccn__charmap_margin *r) {
    r->spectrum = r->regular = -1;
    r->injective = 0;
    double ratio;
    if (spectrum_ratio(n, M, lambda, &ratio)) return -1;
    r->spectrum = 1 - ratio - FAN_SPECTRUM_MIN;
    if (!(r->spectrum > 0)) return 0;
    fgrid g, h;
    int converged, rc = 0;
    /* iterations enough for |mu4| / lambda up to 1 - FAN_SPECTRUM_MIN */
    int its = (int)ceil(log(1e-15) / log(1 - FAN_SPECTRUM_MIN));
    if (charnet(n, d, M, P, T0, lambda, &g, &converged, its)) { free(g.v); return -1; }
    if (!converged) r->spectrum = -1;
    for (int l = 0; l < 2 && converged && !rc; l++) { /* rings 3 -> 5 -> 9 */
        rc = refine(&g, &h, M);
        free(g.v);
        g = h;
    }
    if (!rc && converged) {
        int orient = 0;
        double margin = INFINITY;
        const int32_t R = 2;
        for (int32_t s = 0; s < n; s++)
            for (int32_t i = 0; i < 2 * R; i++)
                for (int32_t j = 0; j < 2 * R; j++) {
                    if (i < R && j < R) continue;
                    double B[4][4][2], J[6][6], scale = 0;
                    face_patch(&g, s, i, j, B);
                    jacobian_bezier(B, J);
                    if (!orient) orient = J[0][0] > 0 ? 1 : J[0][0] < 0 ? -1 : 0;
                    for (int a = 0; a < 6; a++)
                        for (int b = 0; b < 6; b++) scale = fmax(scale, fabs(J[a][b]));
                    margin = orient && scale > 0 ? fmin(margin, jacobian_margin(J, orient, FAN_REG_DEPTH, scale)) : -1;
                }
        r->regular = isfinite(margin) ? margin : -1;
        if (r->regular > 0) {
            ccn__charmap_result cr;
            memset(&cr, 0, sizeof cr);
            rc = surface_test(&g, R, &cr);
            r->injective = cr.injective;
        }
    }
    free(g.v);
    return rc;
}
