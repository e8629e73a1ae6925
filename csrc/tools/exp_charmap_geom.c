/* ccnurbs experiment charmap: regularity and injectivity of the characteristic map, on the
 * limit surface (Bezier form of det J, limit ring curves) and on the control net. */
#include "exp.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static double orient2(const double *a, const double *b, const double *c) {
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
}

/* Closed segments ab and cd intersect (touching and collinear overlap count). */
static int seg_meet(const double *a, const double *b, const double *c, const double *d) {
    if (fmax(a[0], b[0]) < fmin(c[0], d[0]) || fmax(c[0], d[0]) < fmin(a[0], b[0]) ||
        fmax(a[1], b[1]) < fmin(c[1], d[1]) || fmax(c[1], d[1]) < fmin(a[1], b[1]))
        return 0;
    double o1 = orient2(a, b, c), o2 = orient2(a, b, d), o3 = orient2(c, d, a), o4 = orient2(c, d, b);
    return ((o1 <= 0 && o2 >= 0) || (o1 >= 0 && o2 <= 0)) &&
           ((o3 <= 0 && o4 >= 0) || (o3 >= 0 && o4 <= 0));
}

/* Winding number of the closed polygon pts[0..m-1] (xy pairs) around p; 99 if not integral. */
static int winding(const double *pts, int m, const double *p) {
    double sum = 0;
    for (int i = 0; i < m; i++) {
        const double *a = pts + 2 * i, *b = pts + 2 * ((i + 1) % m);
        double ax = a[0] - p[0], ay = a[1] - p[1], bx = b[0] - p[0], by = b[1] - p[1];
        sum += atan2(ax * by - ay * bx, ax * bx + ay * by);
    }
    double w = sum / (2 * EXP_PI);
    return fabs(w - round(w)) < 1e-6 ? (int)round(w) : 99;
}

typedef struct {
    int n, G;              /* valence, grid size per sector */
    const int32_t *idx;    /* exp_fan_vid(n, G, ...) -> vertex */
    const quad_mesh *q;    /* positions, edges, intervals */
} char_grid;

/* Grid vertex (s, i, j); i < 0 or j < 0 reach into the neighbouring sectors:
 * (s, -i, j) = (s+1, j, i) and (s, i, -j) = (s-1, j, i). */
static int32_t grid_vertex(const char_grid *g, int s, int i, int j) {
    if (i < 0) return grid_vertex(g, s + 1, j, -i);
    if (j < 0) return grid_vertex(g, s + g->n - 1, -j, i);
    return g->idx[exp_fan_vid(g->n, g->G, s, i, j)];
}

static const double *gp(const char_grid *g, int s, int i, int j) {
    return g->q->pos + 3 * (size_t)grid_vertex(g, s, i, j);
}

/* -- control-net test: quads of rings R..2R, every corner triangle with one orientation -- */

static void annulus_quads(const char_grid *g, int R, cm_result *r) {
    r->net_orient = 0;
    r->net_bad_quads = 0;
    for (int s = 0; s < g->n; s++)
        for (int i = 0; i < 2 * R; i++)
            for (int j = 0; j < 2 * R; j++) {
                if (i < R && j < R) continue;
                const double *q[4] = {gp(g, s, i, j), gp(g, s, i + 1, j), gp(g, s, i + 1, j + 1),
                                      gp(g, s, i, j + 1)};
                int bad = 0;
                for (int k = 0; k < 4; k++) {
                    double o = orient2(q[(k + 3) % 4], q[k], q[(k + 1) % 4]);
                    int sg = o > 0 ? 1 : o < 0 ? -1 : 0;
                    if (!r->net_orient) r->net_orient = sg;
                    bad |= sg == 0 || sg != r->net_orient;
                }
                r->net_bad_quads += bad;
            }
}

/* The ring-r polygon (2 r n points): per sector (s,r,0..r) then (s,r-1..1,r). */
static void ring_polygon(const char_grid *g, int r, double *pts) {
    int m = 0;
    for (int s = 0; s < g->n; s++) {
        for (int j = 0; j <= r; j++, m++) memcpy(pts + 2 * m, gp(g, s, r, j), 2 * sizeof(double));
        for (int i = r - 1; i >= 1; i--, m++) memcpy(pts + 2 * m, gp(g, s, i, r), 2 * sizeof(double));
    }
}

/* Pairs of non-adjacent edges of the two closed polygons (m1 + m2 points) that meet. */
static int polygon_crossings(const double *pts, int m1, int m2) {
    int m = m1 + m2, count = 0;
    for (int e = 0; e < m; e++) {
        int pe = e < m1 ? 0 : 1, base_e = pe ? m1 : 0, len_e = pe ? m2 : m1;
        int e0 = e, e1 = base_e + (e - base_e + 1) % len_e;
        for (int f = e + 1; f < m; f++) {
            int pf = f < m1 ? 0 : 1, base_f = pf ? m1 : 0, len_f = pf ? m2 : m1;
            int f0 = f, f1 = base_f + (f - base_f + 1) % len_f;
            if (pe == pf && (e1 == f0 || f1 == e0)) continue; /* neighbours share a vertex */
            count += seg_meet(pts + 2 * e0, pts + 2 * e1, pts + 2 * f0, pts + 2 * f1);
        }
    }
    return count;
}

/* Inner polygon pts[0..m1), outer pts[m1..m1+m2): both simple, disjoint, winding `orient`
 * around the origin (the EV's limit), the inner one inside the outer one. */
static int rings_injective(const double *pts, int m1, int m2, int orient, int *wind_in,
                           int *wind_out, int *crossings) {
    const double origin[2] = {0, 0};
    *wind_in = winding(pts, m1, origin);
    *wind_out = winding(pts + 2 * m1, m2, origin);
    int nested = winding(pts + 2 * m1, m2, pts) == orient;
    *crossings = polygon_crossings(pts, m1, m2);
    return *crossings == 0 && nested && *wind_in == orient && *wind_out == orient;
}

static int net_check(const char_grid *g, int R, cm_result *r) {
    annulus_quads(g, R, r);
    r->net_regular = r->net_bad_quads == 0 && r->net_orient != 0;
    int m1 = 2 * R * g->n, m2 = 4 * R * g->n;
    double *pts = malloc(sizeof(double) * 2 * (size_t)(m1 + m2));
    if (!pts) return -1;
    ring_polygon(g, R, pts);
    ring_polygon(g, 2 * R, pts + 2 * m1);
    int wi, wo, cr;
    r->net_injective = r->net_regular && rings_injective(pts, m1, m2, r->net_orient, &wi, &wo, &cr);
    free(pts);
    return 0;
}

/* -- surface test: the limit patches of the annulus, exact Bezier form of det J ------------ */

/* Bezier points of the cubic span of edge P0 P1 of the control polygon P_{-1..2} (p[0..3])
 * with knot intervals d_{-2..2} (d[0..4]; d_j on edge P_j P_{j+1}): the inner points divide
 * P0 P1 in the ratio d_{-1} : d_0 : d_1, the ends divide the neighbouring thirds d_{-1} : d_0
 * and d_0 : d_1 (C2 knot-interval form, Sederberg et al. 1998). */
static void span_bezier(double p[4][2], const double d[5], double b[4][2]) {
    double s0 = d[0] + d[1] + d[2], s1 = d[1] + d[2] + d[3], s2 = d[2] + d[3] + d[4];
    for (int k = 0; k < 2; k++) {
        double rm = p[0][k] + (d[0] + d[1]) / s0 * (p[1][k] - p[0][k]);
        double l0 = p[1][k] + d[1] / s1 * (p[2][k] - p[1][k]);
        double r0 = p[1][k] + (d[1] + d[2]) / s1 * (p[2][k] - p[1][k]);
        double l1 = p[2][k] + d[2] / s2 * (p[3][k] - p[2][k]);
        b[0][k] = (d[2] * rm + d[1] * l0) / (d[1] + d[2]);
        b[1][k] = l0;
        b[2][k] = r0;
        b[3][k] = (d[3] * r0 + d[2] * l1) / (d[2] + d[3]);
    }
}

/* Bicubic Bezier net B[a][b] (a along i, b along j) of the limit patch of face (s, i, j). */
static int face_patch(const char_grid *g, int s, int i, int j, double B[4][4][2]) {
    double du[5], dv[5], P[4][2], T[4][4][2], b[4][2];
    for (int t = 0; t < 5; t++) {
        du[t] = exp_edge_knot(g->q, grid_vertex(g, s, i - 2 + t, j),
                              grid_vertex(g, s, i - 1 + t, j));
        dv[t] = exp_edge_knot(g->q, grid_vertex(g, s, i, j - 2 + t),
                              grid_vertex(g, s, i, j - 1 + t));
        if (!(du[t] > 0) || !(dv[t] > 0)) return -1;
    }
    for (int row = 0; row < 4; row++) { /* along i, rows j-1 .. j+2 */
        for (int a = 0; a < 4; a++) memcpy(P[a], gp(g, s, i - 1 + a, j - 1 + row), sizeof P[a]);
        span_bezier(P, du, b);
        for (int a = 0; a < 4; a++) memcpy(T[a][row], b[a], sizeof b[a]);
    }
    for (int a = 0; a < 4; a++) {
        span_bezier(T[a], dv, b);
        memcpy(B[a], b, sizeof b);
    }
    return 0;
}

/* Bernstein coefficients (bidegree 5, 5) of det J = x_u y_v - y_u x_v (up to a positive
 * factor): x_u has bidegree (2, 3), x_v (3, 2); B^m_i B^n_j = C(m,i) C(n,j) / C(m+n,i+j) B^{m+n}_{i+j}. */
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

/* Halves a bidegree-(5,5) Bernstein polynomial at u = 1/2 (dir 0) or v = 1/2 (dir 1). */
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

/* 1: every coefficient has sign sg (det J has sign sg on the whole patch); -1: a corner value
 * (an actual value of det J) has the wrong sign or is zero; 0: undecided after `depth` splits. */
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

/* Regularity of the limit patches of rings R..2R. */
static int surface_patches(const char_grid *g, int R, cm_result *r) {
    r->orient = 0;
    for (int s = 0; s < g->n; s++)
        for (int i = 0; i < 2 * R; i++)
            for (int j = 0; j < 2 * R; j++) {
                if (i < R && j < R) continue;
                double B[4][4][2], J[6][6];
                if (face_patch(g, s, i, j, B)) return -1;
                jacobian_bezier(B, J);
                if (!r->orient) r->orient = J[0][0] > 0 ? 1 : J[0][0] < 0 ? -1 : 0;
                int t = r->orient ? jacobian_sign(J, r->orient, 6) : -1;
                r->bad_patches += t < 0;
                r->undecided += t == 0;
            }
    return 0;
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

/* The limit curve of parameter ring r, m samples per face side, in ring_polygon's order. */
static int ring_curve(const char_grid *g, int r, int m, double *pts) {
    int k = 0;
    for (int s = 0; s < g->n; s++) {
        double B[4][4][2], c[4][2];
        for (int j = 0; j < r; j++) { /* side i = r, from j to j+1: u = 0 of face (s, r, j) */
            if (face_patch(g, s, r, j, B)) return -1;
            for (int b = 0; b < 4; b++) memcpy(c[b], B[0][b], sizeof c[b]);
            for (int l = 0; l < m; l++, k++) bezier3(c, (double)l / m, pts + 2 * k);
        }
        for (int i = r - 1; i >= 0; i--) { /* side j = r, from i+1 to i: v = 0 of face (s, i, r) */
            if (face_patch(g, s, i, r, B)) return -1;
            for (int a = 0; a < 4; a++) memcpy(c[a], B[a][0], sizeof c[a]);
            for (int l = 0; l < m; l++, k++) bezier3(c, 1.0 - (double)l / m, pts + 2 * k);
        }
    }
    return 0;
}

#define EXP_CURVE_SAMPLES 8

static int surface_check(const char_grid *g, int R, cm_result *r) {
    if (surface_patches(g, R, r)) return -1;
    r->regular = r->bad_patches == 0 && r->undecided == 0 && r->orient != 0;
    int m1 = 2 * R * g->n * EXP_CURVE_SAMPLES, m2 = 2 * m1;
    double *pts = malloc(sizeof(double) * 2 * (size_t)(m1 + m2));
    if (!pts) return -1;
    int rc = ring_curve(g, R, EXP_CURVE_SAMPLES, pts) || ring_curve(g, 2 * R, EXP_CURVE_SAMPLES, pts + 2 * m1);
    if (!rc)
        r->injective = r->regular && rings_injective(pts, m1, m2, r->orient, &r->wind_in,
                                                     &r->wind_out, &r->crossings);
    free(pts);
    return rc ? -1 : 0;
}

/* The grid of G rings around the EV of mesh m, and `check` on it. */
static ccn_status grid_check(const ccn_mesh *m, int n, int32_t ev, int32_t s0, int G, int R,
                             int (*check)(const char_grid *, int, cm_result *), cm_result *r,
                             ccn_error *err) {
    quad_mesh q = {0};
    ccn_status st = CCN_OK;
    int32_t *idx = malloc(sizeof(int32_t) * (size_t)(1 + n * G * (G + 1)));
    if (!idx || exp_quad_load_knots(m, &q)) st = exp_fail_memory(err);
    if (!st && exp_ring_grid(&q, ev, s0, n, G, idx)) {
        err->status = st = CCN_ERR_INTERNAL;
        snprintf(err->message, sizeof err->message, "characteristic net is not a quad grid");
    }
    char_grid g = {n, G, idx, &q};
    if (!st && check(&g, R, r)) {
        err->status = st = CCN_ERR_INTERNAL;
        snprintf(err->message, sizeof err->message, "characteristic ring check failed");
    }
    exp_quad_free(&q);
    free(idx);
    return st;
}

ccn_status exp_surface_test(const ccn_mesh *m, int n, int32_t ev, int32_t s0, int G, int R,
                            cm_result *r, ccn_error *err) {
    return grid_check(m, n, ev, s0, G, R, surface_check, r, err);
}

ccn_status exp_net_test(const ccn_mesh *m, int n, int32_t ev, int32_t s0, int G, int R,
                        cm_result *r, ccn_error *err) {
    return grid_check(m, n, ev, s0, G, R, net_check, r, err);
}
