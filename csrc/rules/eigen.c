/* The extraordinary-vertex refinement matrix M (Li, Finnigan, Sederberg 2016, sections 2, 5, 6).
 *
 * P^{k+1} = M P^k with P = [F_0..F_{n-1}, E_0..E_{n-1}, V] (eq (1)); face i = (V, E_i, F_i,
 * E_{i+1}), spoke i = V-E_i with knot interval d_i, indices mod n. Three rule sets:
 *   CATMULL_CLARK  eqs (2)-(4);
 *   NURSS          Sederberg et al. 1998 / T-NURCC rules with e_i = d_i (SPEC 2.3 "nurss");
 *   EIGEN          eigen polyhedron (section 5), vertex rule (27), face rule (29)-(32),
 *                  edge rule (33)-(38) read as SPEC 2.5 "R1"; falls back to NURSS when the
 *                  construction fails (SPEC 4, DESIGN 4.3).
 * Readings of the garbled equations follow shared/reference/eigen/SPEC.md section 2.
 *
 * Intervals are divided by their maximum and clamped to >= 1e-6 before use (all three rule
 * sets are invariant under a common scale of the intervals; DESIGN 4.5).
 *
 * ccn_ev_info, as filled here:
 *   lambda   eq (15) for every scheme (it depends on n only);
 *   T0       EIGEN: V^1 of eq (28) for the eigen polyhedron built from the given intervals
 *            (scaled back to the caller's units); CC: (0,0); NURSS and EIGEN fallback: (0,0);
 *   residual EIGEN: max |M P0 - lambda P0 - 1 T0| divided by max |P0| (relative, so it does
 *            not depend on the interval scale); CC: the same measured on the Catmull-Clark
 *            polyhedron (11)-(13); NURSS and EIGEN fallback: 0 (no eigen polyhedron).
 * On success err (if given) gets status CCN_OK and an empty message, or, after an eigen
 * fallback, a note saying which rule failed.
 */
#include "rules/eigen.h"

#include "rules/bilinear.h"
#include "rules/eigen_shape.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define CCN__PI 3.14159265358979323846

/* ---- small helpers --------------------------------------------------------------------- */

static void set_error(ccn_error *err, ccn_status st, const char *fmt, ...) {
    va_list ap;
    if (!err) return;
    err->status = st;
    err->element_kind = CCN_ELEM_NONE;
    err->element = -1;
    va_start(ap, fmt);
    vsnprintf(err->message, sizeof err->message, fmt, ap);
    va_end(ap);
}

/* i mod n in [0, n). */
static int32_t wrap(int64_t i, int32_t n) {
    int64_t r = i % n;
    return (int32_t)(r < 0 ? r + n : r);
}

/* Column indices in the ordering of eq (1). */
static size_t col_f(int64_t i, int32_t n) { return (size_t)wrap(i, n); }
static size_t col_e(int64_t i, int32_t n) { return (size_t)n + (size_t)wrap(i, n); }
static size_t col_v(int32_t n) { return 2 * (size_t)n; }

static double *row_of(double *M, int32_t n, size_t r) { return M + r * (2 * (size_t)n + 1); }

static void zero_matrix(double *M, int32_t n) {
    size_t sz = 2 * (size_t)n + 1, k;
    for (k = 0; k < sz * sz; k++) M[k] = 0.0;
}


void ccn__cos_sin_2pi(int64_t k, int64_t n, double *c, double *s) {
    int64_t r = k % n, kc, ks;
    double cs, sn;
    if (r < 0) r += n;
    /* cos: even in r, reduce to kc in [0, n/2]; use cos(pi - x) = -cos x past a quarter. */
    kc = r <= n - r ? r : n - r;
    if (kc == 0) cs = 1.0;
    else if (4 * kc == n) cs = 0.0;
    else if (2 * kc == n) cs = -1.0;
    else if (4 * kc < n) cs = cos(2.0 * CCN__PI * (double)kc / (double)n);
    else cs = -cos(CCN__PI * (double)(n - 2 * kc) / (double)n);
    /* sin: odd in r, reduce to ks in [0, n/2]; sin(pi - x) = sin x past a quarter. */
    ks = r <= n - r ? r : n - r;
    if (ks == 0 || 2 * ks == n) sn = 0.0;
    else if (4 * ks == n) sn = 1.0;
    else if (4 * ks < n) sn = sin(2.0 * CCN__PI * (double)ks / (double)n);
    else sn = sin(CCN__PI * (double)(n - 2 * ks) / (double)n);
    if (r > n - r) sn = -sn;
    *c = cs;
    *s = sn;
}

/* eq (14): gamma = 4 / (c + 1 + sqrt((c+9)(c+1))), c = cos(2 pi / n). */
double ccn__ev_gamma(int32_t n) {
    double c, s;
    ccn__cos_sin_2pi(1, n, &c, &s);
    return 4.0 / (c + 1.0 + sqrt((c + 9.0) * (c + 1.0)));
}

/* eq (15): lambda = (1 + gamma) / (4 gamma). */
double ccn__ev_lambda(int32_t n) {
    double c, s;
    ccn__cos_sin_2pi(1, n, &c, &s);
    return (5.0 + c + sqrt((c + 9.0) * (c + 1.0))) / 16.0;
}


/* ---- shared rule pieces --------------------------------------------------------------- */

/* g_i = (d_{i-2} + d_{i+2} + d_i) / (d_{i-2} + d_{i+2} + 4 d_i)  (eq (27); SPEC 2.3: the curve
 * edge weight w(p_i, d_i, d_i) with p_i = (d_{i-2} + d_{i+2})/2 the interval through V). */
static void compute_g(int32_t n, const double *d, double *g) {
    int32_t i;
    for (i = 0; i < n; i++) {
        double p2 = d[wrap(i - 2, n)] + d[wrap(i + 2, n)];
        g[i] = (p2 + d[i]) / (p2 + 4 * d[i]);
    }
}

/* row += w H_i,  H_i = g_i E_i + (1 - g_i) V  (eq (27); the curve edge point of spoke i). */
static void add_H(double *row, int32_t n, const double *g, int32_t i, double w) {
    i = wrap(i, n);
    row[col_e(i, n)] += w * g[i];
    row[col_v(n)] += w * (1 - g[i]);
}

/* row += w G_i, G_i = g_i(1-g_{i+1}) E_i + g_{i+1}(1-g_i) E_{i+1} + g_i g_{i+1} F_i
 * + (1-g_i)(1-g_{i+1}) V  (eq (27) with SPEC A4's g_i g_{i+1}; the NURSS face point, = (5)
 * for n = 4). */
static void add_G(double *row, int32_t n, const double *g, int32_t i, double w) {
    double gi, gj;
    i = wrap(i, n);
    gi = g[i];
    gj = g[wrap(i + 1, n)];
    row[col_e(i, n)] += w * gi * (1 - gj);
    row[col_e(i + 1, n)] += w * gj * (1 - gi);
    row[col_f(i, n)] += w * gi * gj;
    row[col_v(n)] += w * (1 - gi) * (1 - gj);
}

/* Vertex rule (27): V' = (n-3)/n V + (3/n) sum_i (m_i H_i + f_i G_i) / sum_i (m_i + f_i). */
static void vertex_row(double *row, int32_t n, const double *g, const double *f,
                       const double *m) {
    double W = 0;
    int32_t i;
    for (i = 0; i < n; i++) W += m[i] + f[i];
    row[col_v(n)] += (double)(n - 3) / n;
    for (i = 0; i < n; i++) {
        add_H(row, n, g, i, 3.0 * m[i] / (n * W));
        add_G(row, n, g, i, 3.0 * f[i] / (n * W));
    }
}

/* ---- Catmull-Clark, eqs (2)-(4) ------------------------------------------------------- */

/* Rows written out in old points: F' eq (2); E' eq (3) = 3/8 (V + E_i) + 1/16 (E_{i-1} +
 * E_{i+1} + F_{i-1} + F_i); V' eq (4) = (4n-7)/(4n) V + 3/(2n^2) sum E + 1/(4n^2) sum F. */
static void build_cc(int32_t n, double *M) {
    int32_t i;
    double *rv = row_of(M, n, col_v(n));
    zero_matrix(M, n);
    for (i = 0; i < n; i++) {
        double *rf = row_of(M, n, col_f(i, n)), *re = row_of(M, n, col_e(i, n));
        rf[col_v(n)] = rf[col_e(i, n)] = rf[col_e(i + 1, n)] = rf[col_f(i, n)] = 0.25;
        re[col_v(n)] = re[col_e(i, n)] = 0.375;
        re[col_e(i - 1, n)] = re[col_e(i + 1, n)] = 0.0625;
        re[col_f(i - 1, n)] = re[col_f(i, n)] = 0.0625;
        rv[col_e(i, n)] = 1.5 / ((double)n * n);
        rv[col_f(i, n)] = 0.25 / ((double)n * n);
    }
    rv[col_v(n)] = (4.0 * n - 7.0) / (4.0 * n);
}

/* ---- NURSS / T-NURCC with e_i = d_i ---------------------------------------------------- */

/* Face F'_i = G_i; edge E'_i = H_i/2 + (d_{i+1} F'_{i-1} + d_{i-1} F'_i) / (2(d_{i-1}+d_{i+1}))
 * (eq (6) in general form); vertex (27) with f_i = d_{i-1} d_{i+2},
 * m_i = (d_{i-1}+d_{i+1})(d_{i-2}+d_{i+2})/2 (SPEC 2.3 "nurss"; = eq (7) for n = 4).
 * Scratch: g, f, m (n each). */
static void build_nurss(int32_t n, const double *d, double *g, double *f, double *m,
                        double *M) {
    int32_t i;
    zero_matrix(M, n);
    compute_g(n, d, g);
    for (i = 0; i < n; i++) {
        double dm1 = d[wrap(i - 1, n)], dp1 = d[wrap(i + 1, n)];
        double *re = row_of(M, n, col_e(i, n)), w = 1.0 / (2.0 * (dm1 + dp1));
        add_G(row_of(M, n, col_f(i, n)), n, g, i, 1.0);
        add_H(re, n, g, i, 0.5);
        add_G(re, n, g, i - 1, w * dp1);
        add_G(re, n, g, i, w * dm1);
        f[i] = dm1 * d[wrap(i + 2, n)];
        m[i] = (dm1 + dp1) * (d[wrap(i - 2, n)] + d[wrap(i + 2, n)]) / 2.0;
    }
    vertex_row(row_of(M, n, col_v(n)), n, g, f, m);
}

/* ---- eigen rules (sections 5, 6) ------------------------------------------------------ */

typedef struct {
    int32_t n;
    const ccn__poly_blend *blend; /* the polyhedron: a blend of designs (rules/eigen_shape.h) */
    const double *d;          /* normalised intervals */
    double *c, *s;            /* cos, sin of 2 pi i / n (eq (25)) */
    double *sc, *ss;          /* the spokes' directions (= c, s but for the angle designs) */
    double *dp;               /* d_i^+ (section 5) */
    double *ex, *ey, *fx, *fy; /* eigen polyhedron E_i^0, F_i^0 (eqs (26), (13)) */
    double *g, *f, *m;        /* vertex-rule weights (27) */
    double *a1, *a2;          /* face-rule parameters alpha_{i,1}, alpha_{i,2} (30) */
    double *tl, *tc, *ts, *ll, *ph; /* one design's lengths and directions; the blend's log l, angle */
    double lambda, T0[2];
    double margin;            /* the construction's distance from failing (build_eigen) */
} eigen_work;

/* Section 5 (SPEC 2.2): d_i^+- = sum over j = i..i+n-1 (j = i included) of d_j max(+-cos, 0),
 * l_i = (d_i + d_i^+ + d_i^-)/3, E_i = l_i (cos, sin)(2 pi i/n) (26), F_i = gamma (E_i +
 * E_{i+1}) (13). Another candidate design (rules/eigen_shape.h) replaces the lengths l_i and,
 * for the angle designs, the spoke directions; d_i^+ (the vertex rule's f_i) is the paper's in
 * every case. A blend of designs takes the weighted geometric mean of their lengths and the
 * weighted mean of their spoke angles (equal angles stay exact when no design moves them, so
 * n = 4 and equal intervals keep their exact rules). Returns -1 if a design could not be built. */
static int eigen_polyhedron(eigen_work *w) {
    int32_t n = w->n, i, k;
    double gamma = ccn__ev_gamma(n);
    for (i = 0; i < n; i++) ccn__cos_sin_2pi(i, n, &w->c[i], &w->s[i]);
    for (i = 0; i < n; i++) {
        double plus = 0, minus = 0;
        for (k = 0; k < n; k++) {
            double dj = w->d[wrap((int64_t)i + k, n)], ck = w->c[k];
            if (ck > 0) plus += dj * ck;
            else if (ck < 0) minus -= dj * ck;
        }
        w->dp[i] = plus;
        w->ex[i] = (w->d[i] + plus + minus) / 3.0; /* l_i, scaled below */
        w->sc[i] = w->c[i];
        w->ss[i] = w->s[i];
    }
    const ccn__poly_blend *b = w->blend;
    if (b->count == 1) {
        if (ccn__poly_apply(ccn__poly_design_of(b->poly[0]), n, w->d, w->ex, w->sc, w->ss)) return -1;
    } else {
        int angles = 0;
        for (i = 0; i < n; i++) w->ll[i] = w->ph[i] = 0;
        for (int32_t c = 0; c < b->count; c++) {
            const ccn__poly_design *des = ccn__poly_design_of(b->poly[c]);
            for (i = 0; i < n; i++) w->tl[i] = w->ex[i], w->tc[i] = w->c[i], w->ts[i] = w->s[i];
            if (ccn__poly_apply(des, n, w->d, w->tl, w->tc, w->ts)) return -1;
            angles |= des->a != 0;
            double prev = 0;
            for (i = 0; i < n; i++) {
                w->ll[i] += b->w[c] * log(w->tl[i]);
                /* the angle of spoke i, increasing from 0 (each step in (0, 2 pi)) */
                double a = i ? atan2(w->ts[i], w->tc[i]) : 0.0;
                while (i && a <= prev) a += 2 * CCN__PI;
                w->ph[i] += b->w[c] * a;
                prev = a;
            }
        }
        for (i = 0; i < n; i++) {
            w->ex[i] = exp(w->ll[i]);
            if (angles) w->sc[i] = cos(w->ph[i]), w->ss[i] = sin(w->ph[i]);
        }
    }
    for (i = 0; i < n; i++) {
        double l = w->ex[i];
        w->ex[i] = l * w->sc[i];
        w->ey[i] = l * w->ss[i];
    }
    for (i = 0; i < n; i++) {
        int32_t j = wrap(i + 1, n);
        w->fx[i] = gamma * (w->ex[i] + w->ex[j]);
        w->fy[i] = gamma * (w->ey[i] + w->ey[j]);
    }
    return 0;
}

/* (M P0)_r for one row (V^0 = 0, so the V column does not contribute). */
static void apply_row(const double *row, const eigen_work *w, double out[2]) {
    int32_t n = w->n, i;
    out[0] = out[1] = 0;
    for (i = 0; i < n; i++) {
        double cf = row[col_f(i, n)], ce = row[col_e(i, n)];
        out[0] += cf * w->fx[i] + ce * w->ex[i];
        out[1] += cf * w->fy[i] + ce * w->ey[i];
    }
}

/* Vertex rule (27) with f_i = prod_{j != i,i+1} d_j^+ (SPEC A5 "prodplus"), m_i = f_i +
 * f_{i-1}. Since every d_j^+ >= d_j > 0, f_i = (prod_j d_j^+) / (d_i^+ d_{i+1}^+) and the
 * common product cancels in (27): f_i = 1 / (d_i^+ d_{i+1}^+) avoids over/underflow.
 * Then T0 = V^1 (eq (28)). */
static void eigen_vertex(eigen_work *w, double *M) {
    int32_t n = w->n, i;
    double *rv = row_of(M, n, col_v(n));
    compute_g(n, w->d, w->g);
    for (i = 0; i < n; i++) w->f[i] = 1.0 / (w->dp[i] * w->dp[wrap(i + 1, n)]);
    for (i = 0; i < n; i++) w->m[i] = w->f[i] + w->f[wrap(i - 1, n)];
    vertex_row(rv, n, w->g, w->f, w->m);
    apply_row(rv, w, w->T0);
}

static int param_ok(double a) { return a >= CCN__EV_PARAM_LO && a <= CCN__EV_PARAM_HI; }

/* The construction's margin (eigen_work.margin): the smallest of the face and edge parameters'
 * distance from the limits [CCN__EV_PARAM_LO, CCN__EV_PARAM_HI] over CCN__EV_PARAM_BAND and of
 * the bilinear discriminants D / Dscale over CCN__EV_D_BAND; >= 1 is clear of failing, <= 0
 * fails. run_scheme blends towards the NURSS rules over (0, 1), so the rules do not jump where
 * the construction stops working. */
static void note_margin(eigen_work *w, double a, double b, double dratio) {
    double slack = fmin(fmin(a - CCN__EV_PARAM_LO, CCN__EV_PARAM_HI - a),
                        fmin(b - CCN__EV_PARAM_LO, CCN__EV_PARAM_HI - b));
    w->margin = fmin(w->margin, fmin(slack / CCN__EV_PARAM_BAND, dratio / CCN__EV_D_BAND));
}

/* Face rule (29)-(30): F_i^1 = V^1 + lambda F_i^0 written as the bilinear combination of
 * (V, E_i, F_i, E_{i+1}); (alpha_{i,1}, alpha_{i,2}) by the inverse bilinear map. */
static int eigen_faces(eigen_work *w, double *M, char *why, size_t whylen) {
    int32_t n = w->n, i;
    for (i = 0; i < n; i++) {
        int32_t j = wrap(i + 1, n);
        double p[8] = {0, 0, w->ex[i], w->ey[i], w->fx[i], w->fy[i], w->ex[j], w->ey[j]};
        double x[2] = {w->T0[0] + w->lambda * w->fx[i], w->T0[1] + w->lambda * w->fy[i]};
        double u, v, dr, *rf = row_of(M, n, col_f(i, n));
        int rc = ccn__bilinear_inverse_d(p, x, &u, &v, &dr);
        if (rc) {
            snprintf(why, whylen, "face rule (30) of face %d: %s", (int)i,
                     rc == 1 ? "no real bilinear solution (D < 0)" : "degenerate face quad");
            return 1;
        }
        if (!param_ok(u) || !param_ok(v)) {
            snprintf(why, whylen, "face rule (30) of face %d: alpha = (%.3g, %.3g) outside [%g, %g]",
                     (int)i, u, v, CCN__EV_PARAM_LO, CCN__EV_PARAM_HI);
            return 1;
        }
        note_margin(w, u, v, dr);
        w->a1[i] = u;
        w->a2[i] = v;
        rf[col_v(n)] = (1 - u) * (1 - v);
        rf[col_e(i, n)] = u * (1 - v);
        rf[col_e(j, n)] = (1 - u) * v;
        rf[col_f(i, n)] = u * v;
    }
    return 0;
}

/* Edge rule (33)-(38), SPEC 2.5 reading R1: a = alpha_{i-1,1}, b = alpha_{i,2},
 * P1 = (1-a)V + a E_{i-1} (34), P2 = (1-b)V + b E_{i+1} (35), P3 = (1-a)E_i + a F_{i-1} (36),
 * P4 = (1-b)E_i + b F_i (37), Q1..Q4 = (P1+V)/2, (P2+V)/2, (P3+E_i)/2, (P4+E_i)/2 and
 * E_i^1 = V^1 + lambda E_i^0 (33) = (1-b2)[(1-b1)Q1 + b1 Q2] + b2[(1-b1)Q3 + b1 Q4] (38). */
static int eigen_edges(eigen_work *w, double *M, char *why, size_t whylen) {
    int32_t n = w->n, i;
    for (i = 0; i < n; i++) {
        int32_t im = wrap(i - 1, n), ip = wrap(i + 1, n);
        double a = w->a1[im], b = w->a2[i], q[8], x[2], b1, b2, dr, *re;
        int rc, k;
        double E[2] = {w->ex[i], w->ey[i]};
        for (k = 0; k < 2; k++) {
            double Em = k ? w->ey[im] : w->ex[im], Ep = k ? w->ey[ip] : w->ex[ip];
            double Fm = k ? w->fy[im] : w->fx[im], Fi = k ? w->fy[i] : w->fx[i];
            q[0 + k] = 0.5 * (a * Em);                       /* Q1 (V^0 = 0) */
            q[2 + k] = 0.5 * (b * Ep);                       /* Q2 */
            q[4 + k] = 0.5 * ((1 - b) * E[k] + b * Fi + E[k]); /* Q4 */
            q[6 + k] = 0.5 * ((1 - a) * E[k] + a * Fm + E[k]); /* Q3 */
            x[k] = w->T0[k] + w->lambda * E[k];
        }
        rc = ccn__bilinear_inverse_d(q, x, &b1, &b2, &dr);
        if (rc) {
            snprintf(why, whylen, "edge rule (38) of spoke %d: %s", (int)i,
                     rc == 1 ? "no real bilinear solution (D < 0)" : "degenerate edge quad");
            return 1;
        }
        if (!param_ok(b1) || !param_ok(b2)) {
            snprintf(why, whylen, "edge rule (38) of spoke %d: beta = (%.3g, %.3g) outside [%g, %g]",
                     (int)i, b1, b2, CCN__EV_PARAM_LO, CCN__EV_PARAM_HI);
            return 1;
        }
        note_margin(w, b1, b2, dr);
        re = row_of(M, n, col_e(i, n));
        re[col_v(n)] = (1 - b2) * ((1 - b1) * (1 - a) / 2 + b1 * (1 - b) / 2 + 0.5);
        re[col_e(im, n)] = (1 - b2) * (1 - b1) * a / 2;
        re[col_e(ip, n)] = (1 - b2) * b1 * b / 2;
        re[col_e(i, n)] = b2 * ((1 - b1) * (1 - a) / 2 + b1 * (1 - b) / 2 + 0.5);
        re[col_f(im, n)] = b2 * (1 - b1) * a / 2;
        re[col_f(i, n)] = b2 * b1 * b / 2;
    }
    return 0;
}

/* max |M P0 - lambda P0 - 1 T0| / max |P0|  (eq (10)). */
static double eigen_residual(const double *M, const eigen_work *w) {
    int32_t n = w->n;
    size_t r, rows = 2 * (size_t)n + 1;
    double res = 0, scale = 0;
    for (r = 0; r < rows; r++) {
        double mp[2], p0[2] = {0, 0};
        int32_t i = (int32_t)(r % (size_t)n);
        apply_row(M + r * rows, w, mp);
        if (r < (size_t)n) p0[0] = w->fx[i], p0[1] = w->fy[i];
        else if (r < 2 * (size_t)n) p0[0] = w->ex[i], p0[1] = w->ey[i];
        scale = fmax(scale, fmax(fabs(p0[0]), fabs(p0[1])));
        res = fmax(res, fabs(mp[0] - w->lambda * p0[0] - w->T0[0]));
        res = fmax(res, fabs(mp[1] - w->lambda * p0[1] - w->T0[1]));
    }
    return scale > 0 ? res / scale : res;
}

static int all_finite(const double *M, int32_t n) {
    size_t k, sz = 2 * (size_t)n + 1;
    for (k = 0; k < sz * sz; k++)
        if (!isfinite(M[k])) return 0;
    return 1;
}

/* Builds the eigen M. Returns 0, or 1 with a reason in why (M is then garbage). */
static int build_eigen(eigen_work *w, double *M, double *residual, char *why, size_t whylen) {
    int32_t n = w->n;
    zero_matrix(M, n);
    w->lambda = ccn__ev_lambda(n);
    w->margin = INFINITY;
    if (eigen_polyhedron(w)) {
        snprintf(why, whylen, "the candidate polyhedron could not be built");
        return 1;
    }
    eigen_vertex(w, M);
    if (!isfinite(w->T0[0]) || !isfinite(w->T0[1])) {
        snprintf(why, whylen, "vertex rule (27) is not finite");
        return 1;
    }
    if (eigen_faces(w, M, why, whylen) || eigen_edges(w, M, why, whylen)) return 1;
    if (!all_finite(M, n)) {
        snprintf(why, whylen, "non-finite entry in M");
        return 1;
    }
    *residual = eigen_residual(M, w);
    if (!(*residual <= CCN__EV_MAX_RESIDUAL)) {
        snprintf(why, whylen, "eigen identity (10) residual %.3g > %g", *residual,
                 CCN__EV_MAX_RESIDUAL);
        return 1;
    }
    return 0;
}

/* Residual of the Catmull-Clark matrix on its polyhedron (11)-(13) (all l_i = 1). */
static double cc_residual(const double *M, int32_t n, double *scratch) {
    eigen_work w;
    int32_t i;
    memset(&w, 0, sizeof w);
    w.n = n;
    w.ex = scratch;
    w.ey = scratch + n;
    w.fx = scratch + 2 * (size_t)n;
    w.fy = scratch + 3 * (size_t)n;
    w.lambda = ccn__ev_lambda(n);
    for (i = 0; i < n; i++) ccn__cos_sin_2pi(i, n, &w.ex[i], &w.ey[i]);
    for (i = 0; i < n; i++) {
        double gm = ccn__ev_gamma(n);
        w.fx[i] = gm * (w.ex[i] + w.ex[wrap(i + 1, n)]);
        w.fy[i] = gm * (w.ey[i] + w.ey[wrap(i + 1, n)]);
    }
    return eigen_residual(M, &w);
}

/* ---- public entry ---------------------------------------------------------------------- */

#define SCRATCH_PER_N 20

ccn_status ccn__ev_validate(int32_t n, const double *d, ccn_scheme scheme, const double *M,
                           ccn_error *err) {
    int32_t i;
    if (n < 3 || n > CCN__EV_MAX_VALENCE) {
        set_error(err, CCN_ERR_ARGUMENT, "ev matrix: valence %d outside [3, %d]", (int)n,
                  CCN__EV_MAX_VALENCE);
        return CCN_ERR_ARGUMENT;
    }
    if (!d || !M) {
        set_error(err, CCN_ERR_ARGUMENT, "ev matrix: %s is NULL", !d ? "spoke_knots" : "M");
        return CCN_ERR_ARGUMENT;
    }
    if (scheme != CCN_SCHEME_EIGEN && scheme != CCN_SCHEME_NURSS &&
        scheme != CCN_SCHEME_CATMULL_CLARK) {
        set_error(err, CCN_ERR_ARGUMENT, "ev matrix: unknown scheme %d", (int)scheme);
        return CCN_ERR_ARGUMENT;
    }
    for (i = 0; i < n; i++) {
        if (!isfinite(d[i]) || !(d[i] > 0)) {
            set_error(err, CCN_ERR_KNOTS,
                      "ev matrix: spoke interval %d is %g; intervals must be finite and > 0",
                      (int)i, d[i]);
            return CCN_ERR_KNOTS;
        }
    }
    return CCN_OK;
}

double ccn__ev_normalise(int32_t n, const double *d, double *out) {
    double mx = 0;
    int32_t i;
    for (i = 0; i < n; i++) mx = fmax(mx, d[i]);
    for (i = 0; i < n; i++) out[i] = fmax(d[i] / mx, CCN__EV_MIN_INTERVAL);
    return mx;
}

/* Points the eigen work arrays into scratch (19 n doubles). */
static void work_init(eigen_work *w, int32_t n, const double *d, const ccn__poly_blend *blend,
                      double *scratch) {
    double **arrays[19];
    int k;
    memset(w, 0, sizeof *w);
    w->n = n;
    w->blend = blend;
    w->d = d;
    arrays[0] = &w->c, arrays[1] = &w->s, arrays[2] = &w->dp, arrays[3] = &w->ex;
    arrays[4] = &w->ey, arrays[5] = &w->fx, arrays[6] = &w->fy, arrays[7] = &w->g;
    arrays[8] = &w->f, arrays[9] = &w->m, arrays[10] = &w->a1, arrays[11] = &w->a2;
    arrays[12] = &w->sc, arrays[13] = &w->ss;
    arrays[14] = &w->tl, arrays[15] = &w->tc, arrays[16] = &w->ts, arrays[17] = &w->ll;
    arrays[18] = &w->ph;
    for (k = 0; k < 19; k++) *arrays[k] = scratch + (size_t)k * (size_t)n;
}

static double smoothstep01(double x) {
    if (!(x > 0)) return 0.0;
    if (x >= 1) return 1.0;
    return x * x * (3 - 2 * x);
}

/* Fills M and info for a validated call; buf holds SCRATCH_PER_N * n doubles. The eigen M of
 * a construction within CCN__EV_PARAM_BAND / CCN__EV_D_BAND of failing is blended with the
 * NURSS M by smoothstep(margin), and a failed one is the NURSS M: so M is a continuous
 * function of the intervals up to and across the eigen rules' range. */
static ccn_status run_scheme(int32_t n, const double *d, ccn_scheme scheme,
                             const ccn__poly_blend *blend, double *M, ccn_ev_info *info,
                             double *P, double *margin, ccn_error *err, double *buf) {
    double *nd = buf, *rest = buf + n, dmax, residual = 0, keep = 0;
    char why[200];
    eigen_work w;
    info->lambda = ccn__ev_lambda(n);
    if (scheme == CCN_SCHEME_CATMULL_CLARK) {
        build_cc(n, M);
        info->residual = cc_residual(M, n, rest);
        return CCN_OK;
    }
    dmax = ccn__ev_normalise(n, d, nd);
    if (scheme == CCN_SCHEME_EIGEN) {
        work_init(&w, n, nd, blend, rest);
        if (!build_eigen(&w, M, &residual, why, sizeof why)) {
            keep = margin ? 1.0 : smoothstep01(w.margin);
            if (margin) *margin = w.margin;
            info->T0[0] = w.T0[0] * dmax;
            info->T0[1] = w.T0[1] * dmax;
            info->residual = residual;
            int32_t best = 0;
            for (int32_t c = 1; c < blend->count; c++)
                if (blend->w[c] > blend->w[best]) best = c;
            info->polyhedron = blend->poly[best];
            if (keep == 1.0) {
                for (int32_t i = 0; P && i < n; i++) {
                    P[2 * col_f(i, n)] = w.fx[i], P[2 * col_f(i, n) + 1] = w.fy[i];
                    P[2 * col_e(i, n)] = w.ex[i], P[2 * col_e(i, n) + 1] = w.ey[i];
                }
                if (P) P[2 * col_v(n)] = P[2 * col_v(n) + 1] = 0;
                return CCN_OK;
            }
            snprintf(why, sizeof why, "within %.3g of failing", w.margin);
        }
        info->fallback = 1;
        set_error(err, CCN_OK, "eigen rules %s; NURSS rules %s", why, keep > 0 ? "blended in" : "used");
    }
    size_t sz = 2 * (size_t)n + 1;
    double *E = NULL;
    if (keep > 0) { /* the eigen M, to blend with */
        E = malloc(sizeof(double) * sz * sz);
        if (!E) {
            set_error(err, CCN_ERR_MEMORY, "ev matrix: out of memory for valence %d", (int)n);
            return CCN_ERR_MEMORY;
        }
        memcpy(E, M, sizeof(double) * sz * sz);
    }
    build_nurss(n, nd, rest, rest + n, rest + 2 * (size_t)n, M);
    if (E) {
        for (size_t k = 0; k < sz * sz; k++) M[k] = keep * E[k] + (1 - keep) * M[k];
        free(E);
    } else
        info->T0[0] = info->T0[1] = info->residual = 0, info->polyhedron = 0;
    if (!all_finite(M, n)) {
        set_error(err, CCN_ERR_INTERNAL, "ev matrix: NURSS rules gave a non-finite entry");
        return CCN_ERR_INTERNAL;
    }
    return CCN_OK;
}

ccn_status ccn__ev_matrix_blend(int32_t n, const double *spoke_knots, ccn_scheme scheme,
                                const ccn__poly_blend *blend, double *M, ccn_ev_info *info,
                                double *P, double *margin, ccn_error *err) {
    double stack[SCRATCH_PER_N * CCN__EV_STACK_VALENCE], *buf = stack;
    ccn_ev_info local;
    ccn_status st = ccn__ev_validate(n, spoke_knots, scheme, M, err);
    if (st != CCN_OK) return st;
    for (int32_t c = 0; c < blend->count; c++)
        if (!ccn__poly_design_of(blend->poly[c])) {
            if (info) memset(info, 0, sizeof *info);
            set_error(err, CCN_ERR_ARGUMENT, "ev matrix: polyhedron %d outside [1, %d]",
                      (int)blend->poly[c], CCN__POLY_COUNT);
            return CCN_ERR_ARGUMENT;
        }
    if (n > CCN__EV_STACK_VALENCE) {
        buf = malloc(sizeof(double) * SCRATCH_PER_N * (size_t)n);
        if (!buf) {
            set_error(err, CCN_ERR_MEMORY, "ev matrix: out of memory for valence %d", (int)n);
            return CCN_ERR_MEMORY;
        }
    }
    if (!info) info = &local;
    memset(info, 0, sizeof *info);
    set_error(err, CCN_OK, "%s", "");
    if (margin) *margin = -1;
    st = run_scheme(n, spoke_knots, scheme, blend, M, info, P, margin, err, buf);
    if (buf != stack) free(buf);
    return st;
}

ccn_status ccn__ev_matrix_poly(int32_t n, const double *spoke_knots, ccn_scheme scheme,
                               int32_t poly, double *M, ccn_ev_info *info, double *P,
                               ccn_error *err) {
    ccn__poly_blend one = {1, {poly}, {1.0}};
    return ccn__ev_matrix_blend(n, spoke_knots, scheme, &one, M, info, P, NULL, err);
}
