/* Fairness of the guided bi-5 cap against the refined limit, measured
 * independently of the library: the cap surface from its Bernstein-Bezier patches (power form
 * with exact first and second derivatives, tests/c/bi5_props.h), the refined limit from its
 * exact positions and normals (a least-squares shape operator over each output vertex's ring).
 * Shared by tests/c/test_cap_fair.c (small samples in `make test`) and
 * tests/experiments/cap_fair.c (the long measurement, RESULTS.md). The plan's internals are
 * read only to know which patches belong to which cap and which output vertices lie inside a
 * hole. Measures of one cage at one level (struct fair):
 *   turn      max over output edges of (normal-turn rate of the cap plan - that of the refine
 *             plan at the same edge) / the refine plan's largest rate (rate = angle between the
 *             end normals / edge length);
 *   ksign, hsign  caps where the refined limit's K (H) keeps one sign over the hole and the cap
 *             surface's K (H) takes the other sign somewhere (samples of every bi-5 patch);
 *   kratio    max over caps of max |K| on the cap surface / max |K| of the refined limit in
 *             the same hole;
 *   kring     max over caps of max |K| on the cap surface / max |K| of the refined limit on
 *             the ring of output vertices around the hole (the refined limit's curvature in
 *             the hole is unbounded at a non-uniform EV, so this is the measure there);
 *   kjump     max over caps of the jump of K across cap-cap and cap-ring joins / max |K| there;
 *   centre    angle between the cap-centre normal (from the cap patches) and the exact limit
 *             normal at the EV (the refine plan's), orientation included;
 *   outside   max distance / bbox diagonal between the two plans at every output vertex not
 *             strictly inside a hole;
 *   g1        max angle between the normals of the two sides of every join of the bi-5 patches
 *             (cap-cap, cap-ring, ring-ring, inside rings and across spokes);
 *   jac       min over samples of |X_u x X_v| / its max over the cap (folds: near 0). */
#ifndef CCN_TEST_CAP_FAIR_H
#define CCN_TEST_CAP_FAIR_H

#include "bi5/bi5.h"
#include "ccnurbs.h"
#include "surface/fill_cap.h"
#include "surface/plan_types.h"
#include "bi5_props.h"

#include <stdio.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

typedef struct {
    double turn, turn_ref, kratio, kring, kjump, centre, outside, g1, jac;
    double twin_out, twin_g1; /* the hole border and ring faces of caps blended with their uniform
                                 twin (intervals within 1 % of equal): position over the size and
                                 normal angle against the exact limit there */
    int ksign, hsign, caps, fallbacks, holes_checked, twins;
} fair;

typedef struct {
    int32_t nv, nf, ne;
    double *pos;
    int32_t *fs, *fv, *ev;
    double *kn;
} fcage;

static void fcage_free(fcage *c) { free(c->pos); free(c->fs); free(c->fv); free(c->ev); free(c->kn); }

static ccn_cage fcage_view(const fcage *c) {
    ccn_cage g = {c->nv, c->nf, c->ne, c->pos, c->fs, c->fv, c->ev, c->kn, NULL, NULL};
    return g;
}

/* ---- geometry of the cap surface ---------------------------------------------------------- */

static double dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
static double norm3(const double *a) { return sqrt(dot3(a, a)); }

/* K, H and unit normal from first and second derivatives. */
static void curvatures(const double *xu, const double *xv, const double *xuu, const double *xuv,
                       const double *xvv, double *K, double *H, double N[3]) {
    cross(xu, xv, N);
    double l = norm3(N);
    for (int k = 0; k < 3; k++) N[k] /= l;
    double E = dot3(xu, xu), F = dot3(xu, xv), G = dot3(xv, xv);
    double L = dot3(xuu, N), M = dot3(xuv, N), Nn = dot3(xvv, N), det = E * G - F * F;
    *K = (L * Nn - M * M) / det;
    *H = (E * Nn - 2 * F * M + G * L) / (2 * det);
}

/* Patch k of the cap's patch set at its own (s, t) in [0,1]^2: value, derivatives. */
static void patch_jet(const surf_t *S, int k, double s, double t, double jet[6][3]) {
    static const int order[6][2] = {{0, 0}, {1, 0}, {0, 1}, {2, 0}, {1, 1}, {0, 2}};
    for (int q = 0; q < 6; q++) pf_eval(S->M[k], s, t, order[q][0], order[q][1], jet[q]);
}

/* The same through ring_eval (hole coordinates of sector s, ring r / cap r = nsig). */
static void ring_jet(const surf_t *S, int r, int kind, int s, double u, double v, double jet[6][3]) {
    static const int order[6][2] = {{0, 0}, {1, 0}, {0, 1}, {2, 0}, {1, 1}, {0, 2}};
    for (int q = 0; q < 6; q++) ring_eval(S, r, kind, s, u, v, order[q][0], order[q][1], jet[q]);
}

static void jet_curv(double jet[6][3], double *K, double *H, double N[3]) {
    curvatures(jet[1], jet[2], jet[3], jet[4], jet[5], K, H, N);
}

/* ---- the refined limit: shape operator from exact normals --------------------------------- */

/* K and H at output vertex v from its neighbours w (dN = -S dX in the tangent plane, least
 * squares, symmetrised). nb: CSR neighbours. */
static void ring_curvature(const double *x, const double *n, const int32_t *nbs, const int32_t *nb,
                           int32_t v, double *K, double *H) {
    const double *nv = n + 3 * v, *xv = x + 3 * v;
    double e1[3], e2[3], t[3] = {1, 0, 0};
    if (fabs(nv[0]) > 0.8) t[0] = 0, t[1] = 1;
    cross(nv, t, e1);
    double l = norm3(e1);
    for (int k = 0; k < 3; k++) e1[k] /= l;
    cross(nv, e1, e2);
    double A[2][2] = {{0, 0}, {0, 0}}, B[2][2] = {{0, 0}, {0, 0}}; /* sum a a^T, sum b a^T */
    for (int32_t q = nbs[v]; q < nbs[v + 1]; q++) {
        const double *xw = x + 3 * nb[q], *nw = n + 3 * nb[q];
        double dx[3] = {xw[0] - xv[0], xw[1] - xv[1], xw[2] - xv[2]};
        double dn[3] = {nw[0] - nv[0], nw[1] - nv[1], nw[2] - nv[2]};
        double a[2] = {dot3(dx, e1), dot3(dx, e2)}, b[2] = {-dot3(dn, e1), -dot3(dn, e2)};
        double w = 1 / (a[0] * a[0] + a[1] * a[1]);
        for (int i = 0; i < 2; i++)
            for (int j = 0; j < 2; j++) A[i][j] += w * a[i] * a[j], B[i][j] += w * b[i] * a[j];
    }
    double det = A[0][0] * A[1][1] - A[0][1] * A[1][0];
    double Ai[2][2] = {{A[1][1] / det, -A[0][1] / det}, {-A[1][0] / det, A[0][0] / det}}, Sm[2][2];
    for (int i = 0; i < 2; i++)
        for (int j = 0; j < 2; j++) Sm[i][j] = B[i][0] * Ai[0][j] + B[i][1] * Ai[1][j];
    double s01 = 0.5 * (Sm[0][1] + Sm[1][0]);
    *K = Sm[0][0] * Sm[1][1] - s01 * s01;
    *H = 0.5 * (Sm[0][0] + Sm[1][1]);
}

/* ---- one cage at one level ------------------------------------------------------------------ */

typedef struct { ccn_plan *p; int32_t nv, nf; double *x, *n, *k; int32_t *fv; } fplan;

static int fplan_run(const ccn_cage *cage, ccn_options o, fplan *f) {
    ccn_error err;
    memset(f, 0, sizeof *f);
    if (ccn_plan_create(cage, &o, &f->p, &err)) { fprintf(stderr, "plan: %s\n", err.message); return -1; }
    ccn_sizes s;
    ccn_plan_get_sizes(f->p, &s);
    f->nv = s.num_verts, f->nf = s.num_faces;
    f->x = malloc(sizeof(double) * 3 * (size_t)f->nv);
    f->n = malloc(sizeof(double) * 3 * (size_t)f->nv);
    f->fv = malloc(sizeof(int32_t) * 4 * (size_t)f->nf);
    f->k = malloc(sizeof(double) * 2 * (size_t)f->nv);
    ccn_limit_mesh lm = {.positions = f->x, .normals = f->n, .face_verts = f->fv, .curvatures = f->k};
    if (ccn_plan_evaluate(f->p, NULL, &lm, &err)) { fprintf(stderr, "evaluate: %s\n", err.message); return -1; }
    return 0;
}

static void fplan_free(fplan *f) {
    ccn_plan_destroy(f->p);
    free(f->x); free(f->n); free(f->fv); free(f->k);
}

/* Vertex neighbours (sharing an edge) from the quads, CSR. */
static void neighbours(const fplan *f, int32_t **nbs_out, int32_t **nb_out) {
    int32_t *cnt = calloc((size_t)f->nv + 1, sizeof(int32_t)), *nb = malloc(sizeof(int32_t) * 8 * (size_t)f->nf);
    for (int32_t q = 0; q < f->nf; q++)
        for (int j = 0; j < 4; j++) cnt[f->fv[4 * q + j] + 1] += 2;
    for (int32_t v = 0; v < f->nv; v++) cnt[v + 1] += cnt[v];
    int32_t *fill = malloc(sizeof(int32_t) * (size_t)f->nv);
    memcpy(fill, cnt, sizeof(int32_t) * (size_t)f->nv);
    for (int32_t q = 0; q < f->nf; q++)
        for (int j = 0; j < 4; j++) {
            int32_t a = f->fv[4 * q + j], b = f->fv[4 * q + (j + 1) % 4], c = f->fv[4 * q + (j + 3) % 4];
            nb[fill[a]++] = b;
            nb[fill[a]++] = c; /* each edge seen from both faces: duplicates are harmless */
        }
    free(fill);
    *nbs_out = cnt;
    *nb_out = nb;
}

static double bbox_diag(const double *x, int32_t nv) {
    double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
    for (int32_t v = 0; v < nv; v++)
        for (int k = 0; k < 3; k++) lo[k] = fmin(lo[k], x[3 * v + k]), hi[k] = fmax(hi[k], x[3 * v + k]);
    double d[3] = {hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]};
    return norm3(d);
}

/* Angle between two normals up to orientation (tangent planes). */
static double plane_angle(const double *a, const double *b) {
    double t = angle(a, b);
    return fmin(t, M_PI - t);
}

/* Normal-turn rates per output edge (angle between the end normals / edge length): the largest
 * of pb's minus pr's over the edges; *rmax gets pr's largest rate. */
static inline double turn_excess(const fplan *pr, const fplan *pb, double *rmax) {
    double excess = -1e300;
    *rmax = 0;
    for (int32_t q = 0; q < pr->nf; q++)
        for (int j = 0; j < 4; j++) {
            int32_t a = pr->fv[4 * q + j], b = pr->fv[4 * q + (j + 1) % 4];
            double dr[3], db[3];
            for (int k = 0; k < 3; k++) dr[k] = pr->x[3 * a + k] - pr->x[3 * b + k], db[k] = pb->x[3 * a + k] - pb->x[3 * b + k];
            double rr = angle(pr->n + 3 * a, pr->n + 3 * b) / norm3(dr), rb = angle(pb->n + 3 * a, pb->n + 3 * b) / norm3(db);
            *rmax = fmax(*rmax, rr);
            excess = fmax(excess, rb - rr);
        }
    return excess;
}

/* Everything about one cap. */
static void measure_cap(const ccn_plan *plan, const ccn__cap *cp, const fplan *pr, const uint8_t *in_hole_of,
                        int32_t cap_id, const int32_t *nbs, const int32_t *nb, int32_t ev_out, fair *F) {
    surf_t S;
    int n = cp->n, L = cp->op->nsig, np = (3 * L + 1) * n;
    /* the plan works in a unit box (plan.c): the patches in the caller's coordinates */
    double *P = malloc(sizeof(double) * 108 * (size_t)np);
    if (!P) return;
    for (int i = 0; i < 36 * np; i++)
        for (int k = 0; k < 3; k++) P[3 * i + k] = plan->centre[k] + plan->scale * cp->patches[3 * i + k];
    surf_init(&S, n, L, cp->op->sig, P);
    if (!S.M) return;
    /* the refined limit in the hole */
    double kmin = 1e300, kmax = -1e300, hmin = 1e300, hmax = -1e300, kref = 0;
    for (int32_t v = 0; v < pr->nv; v++) {
        if (in_hole_of[v] != cap_id + 1) continue;
        double K, H;
        ring_curvature(pr->x, pr->n, nbs, nb, v, &K, &H);
        kmin = fmin(kmin, K), kmax = fmax(kmax, K), hmin = fmin(hmin, H), hmax = fmax(hmax, H);
        kref = fmax(kref, fabs(K));
    }
    double kout = 0; /* the ring around the hole: outside it, next to a vertex inside */
    for (int32_t v = 0; v < pr->nv; v++) {
        if (in_hole_of[v]) continue;
        int next = 0;
        for (int32_t q = nbs[v]; q < nbs[v + 1] && !next; q++) next = in_hole_of[nb[q]] == cap_id + 1;
        if (!next) continue;
        double K, H;
        ring_curvature(pr->x, pr->n, nbs, nb, v, &K, &H);
        kout = fmax(kout, fabs(K));
    }
    const double *nev = pr->n + 3 * ev_out;
    /* the cap surface: samples of every patch */
    double kc = 0, cmin = 1e300, cmaxk = -1e300, chmin = 1e300, chmax = -1e300;
    for (int k = 0; k < np; k++) {
        double jmax = 0, jmin = 1e300;
        for (int a = 0; a <= 10; a++)
            for (int b = 0; b <= 10; b++) {
                double jet[6][3], K, H, N[3], c[3];
                patch_jet(&S, k, a / 10.0, b / 10.0, jet);
                cross(jet[1], jet[2], c);
                double jn = norm3(c);
                jmax = fmax(jmax, jn), jmin = fmin(jmin, jn);
                if (!(jn > 0)) continue;
                jet_curv(jet, &K, &H, N);
                if (dot3(N, nev) < 0) H = -H; /* the refined limit's orientation */
                kc = fmax(kc, fabs(K));
                cmin = fmin(cmin, K), cmaxk = fmax(cmaxk, K), chmin = fmin(chmin, H), chmax = fmax(chmax, H);
            }
        F->jac = fmin(F->jac, jmin / jmax); /* per patch: the patches contract ring by ring */
    }
    if ((kmin > 0 && cmin <= 0) || (kmax < 0 && cmaxk >= 0)) F->ksign++;
    if ((hmin > 0 && chmin <= 0) || (hmax < 0 && chmax >= 0)) F->hsign++;
    if (kref > 0) F->kratio = fmax(F->kratio, kc / kref);
    if (kout > 0) F->kring = fmax(F->kring, kc / kout);
    /* joins: cap-cap separators (cap s edge u = 0 vs cap s+1 edge v = 0, bi5_props.h cap_g1) and
     * cap-ring (cap edge u = 1 / v = 1 vs the last ring's A / C at u = rho / v = rho) */
    double jump = 0;
    for (int s = 0; s < n; s++) {
        int s1 = (s + 1) % n;
        for (int q = 1; q <= 20; q++) {
            double t = q / 20.0, j1[6][3], j2[6][3], K1, K2, H1, H2, N1[3], N2[3];
            ring_jet(&S, L, 0, s, 0, t, j1);
            ring_jet(&S, L, 0, s1, t, 0, j2);
            jet_curv(j1, &K1, &H1, N1), jet_curv(j2, &K2, &H2, N2);
            jump = fmax(jump, fabs(K1 - K2));
            F->g1 = fmax(F->g1, plane_angle(N1, N2));
            double rho = 1 - S.sig[L - 1];
            for (int e = 0; e < 2; e++) { /* u = 1 with kind A, v = 1 with kind C */
                double u = e ? t : 1, v = e ? 1 : t;
                ring_jet(&S, L, 0, s, u, v, j1);
                ring_jet(&S, L - 1, e ? 2 : 0, s, rho * u, rho * v, j2);
                jet_curv(j1, &K1, &H1, N1), jet_curv(j2, &K2, &H2, N2);
                jump = fmax(jump, fabs(K1 - K2));
                F->g1 = fmax(F->g1, plane_angle(N1, N2));
            }
        }
    }
    if (kc > 0) F->kjump = fmax(F->kjump, jump / kc);
    /* G1 inside the rings, ring to ring and across spokes: normals of both sides */
    for (int r = 0; r < L; r++) {
        double sg = S.sig[r], rho = 1 - sg;
        for (int s = 0; s < n; s++)
            for (int q = 0; q <= 10; q++) {
                double t = rho + sg * q / 10.0, j1[6][3], j2[6][3], K, H, N1[3], N2[3];
                const int kinds[3][2] = {{0, 1}, {1, 2}, {0, 2}};
                for (int w = 0; w < 3; w++) {
                    if (w < 2) {
                        double u = w == 0 ? t : rho, v = w == 0 ? rho : t;
                        ring_jet(&S, r, kinds[w][0], s, u, v, j1);
                        ring_jet(&S, r, kinds[w][1], s, u, v, j2);
                    } else { /* across spoke s: A^s(t, 0) vs C^{s-1}(0, t) */
                        ring_jet(&S, r, 0, s, t, 0, j1);
                        ring_jet(&S, r, 2, (s + n - 1) % n, 0, t, j2);
                    }
                    jet_curv(j1, &K, &H, N1), jet_curv(j2, &K, &H, N2);
                    F->g1 = fmax(F->g1, plane_angle(N1, N2));
                }
                if (r + 1 < L) { /* ring r inner edge u = rho vs ring r+1 outer edge u = 1 */
                    double tt = q / 10.0, rr = 1 - S.sig[r + 1];
                    ring_jet(&S, r, 0, s, rho, rho * tt, j1);
                    ring_jet(&S, r + 1, tt <= rr ? 0 : 1, s, 1.0, tt, j2);
                    jet_curv(j1, &K, &H, N1), jet_curv(j2, &K, &H, N2);
                    F->g1 = fmax(F->g1, plane_angle(N1, N2));
                }
            }
    }
    /* the centre: every cap sector's normal at (0, 0), oriented by the refined limit */
    for (int s = 0; s < n; s++) {
        double j1[6][3], K, H, N[3];
        ring_jet(&S, L, 0, s, 0, 0, j1);
        jet_curv(j1, &K, &H, N);
        if (dot3(N, nev) < 0)
            for (int k = 0; k < 3; k++) N[k] = -N[k];
        F->centre = fmax(F->centre, angle(N, nev));
    }
    free(S.M);
    free(P);
    F->holes_checked++;
}

/* ---- the G1 fill cap ------------------------------------------------------------------------ */

/* Degree-5 Bernstein basis with first and second derivatives at t. */
static void bern5(double t, double B[6], double D[6], double DD[6]) {
    static const double C5[6] = {1, 5, 10, 10, 5, 1}, C4[5] = {1, 4, 6, 4, 1}, C3[4] = {1, 3, 3, 1};
    double b4[5], b3[4];
    for (int i = 0; i < 6; i++) B[i] = C5[i] * pow(t, i) * pow(1 - t, 5 - i);
    for (int i = 0; i < 5; i++) b4[i] = C4[i] * pow(t, i) * pow(1 - t, 4 - i);
    for (int i = 0; i < 4; i++) b3[i] = C3[i] * pow(t, i) * pow(1 - t, 3 - i);
    for (int i = 0; i < 6; i++) {
        D[i] = 5 * ((i > 0 ? b4[i - 1] : 0) - (i < 5 ? b4[i] : 0));
        DD[i] = 20 * ((i > 1 ? b3[i - 2] : 0) - 2 * (i > 0 && i < 5 ? b3[i - 1] : 0) + (i < 4 ? b3[i] : 0));
    }
}

/* Quintic Bezier patch b at (s, t): value, d/ds, d/dt, d2/ds2, d2/dsdt, d2/dt2. */
static void bez5_jet(const double b[6][6][3], double s, double t, double jet[6][3]) {
    double Bs[6], Ds[6], DDs[6], Bt[6], Dt[6], DDt[6];
    bern5(s, Bs, Ds, DDs);
    bern5(t, Bt, Dt, DDt);
    memset(jet, 0, sizeof(double) * 18);
    for (int i = 0; i < 6; i++)
        for (int j = 0; j < 6; j++) {
            double w[6] = {Bs[i] * Bt[j], Ds[i] * Bt[j], Bs[i] * Dt[j], DDs[i] * Bt[j], Ds[i] * Dt[j], Bs[i] * DDt[j]};
            for (int q = 0; q < 6; q++)
                for (int k = 0; k < 3; k++) jet[q][k] += w[q] * b[i][j][k];
        }
}

/* Sector s of a fill cap at face coordinates (u, v) in [0,1]^2 (its four patches b). */
static void fill_jet(double (*b)[4][6][6][3], int s, double u, double v, double jet[6][3]) {
    int a = u < 0.5 ? 0 : 1, c = v < 0.5 ? 0 : 1;
    bez5_jet((const double(*)[6][3])b[s][2 * a + c], 2 * u - a, 2 * v - c, jet);
}

/* The refined limit around cap cap_id: its K, H range and max |K| in the hole, max |K| on the
 * ring of output vertices around it. */
static void hole_reference(const fplan *pr, const uint8_t *in_hole_of, int32_t cap_id, const int32_t *nbs,
                           const int32_t *nb, double r[6]) {
    double kmin = 1e300, kmax = -1e300, hmin = 1e300, hmax = -1e300, kref = 0, kout = 0;
    for (int32_t v = 0; v < pr->nv; v++) {
        double K, H;
        if (in_hole_of[v] == cap_id + 1) {
            ring_curvature(pr->x, pr->n, nbs, nb, v, &K, &H);
            kmin = fmin(kmin, K), kmax = fmax(kmax, K), hmin = fmin(hmin, H), hmax = fmax(hmax, H);
            kref = fmax(kref, fabs(K));
            continue;
        }
        if (in_hole_of[v]) continue;
        int next = 0;
        for (int32_t q = nbs[v]; q < nbs[v + 1] && !next; q++) next = in_hole_of[nb[q]] == cap_id + 1;
        if (!next) continue;
        ring_curvature(pr->x, pr->n, nbs, nb, v, &K, &H);
        kout = fmax(kout, fabs(K));
    }
    r[0] = kmin, r[1] = kmax, r[2] = hmin, r[3] = hmax, r[4] = kref, r[5] = kout;
}

/* The fill cap's measures (the same as measure_cap's): samples of its patches; joins across
 * its spokes (both sectors' normals and K) and along its border (K against the refined plan's
 * exact curvature at the border's output vertices). */
static void measure_fill(const ccn_plan *plan, const ccn__cap *cp, const fplan *pr, const uint8_t *in_hole_of,
                         int32_t cap_id, const int32_t *nbs, const int32_t *nb, int32_t ev_out, fair *F) {
    int n = cp->n;
    double (*b)[4][6][6][3] = malloc(sizeof *b * (size_t)n), ref[6];
    if (!b) return;
    for (int s = 0; s < n; s++) {
        ccn__fill_cap_bezier(cp->fill, s, b[s]);
        for (int q = 0; q < 4; q++)
            for (int i = 0; i < 6; i++)
                for (int j = 0; j < 6; j++)
                    for (int k = 0; k < 3; k++) b[s][q][i][j][k] = plan->centre[k] + plan->scale * b[s][q][i][j][k];
    }
    hole_reference(pr, in_hole_of, cap_id, nbs, nb, ref);
    const double *nev = pr->n + 3 * ev_out;
    double kc = 0, cmin = 1e300, cmaxk = -1e300, chmin = 1e300, chmax = -1e300, jmax = 0, jmin = 1e300;
    for (int s = 0; s < n; s++)
        for (int a = 0; a <= 20; a++)
            for (int c = 0; c <= 20; c++) {
                double jet[6][3], K, H, N[3], x[3];
                fill_jet(b, s, a / 20.0, c / 20.0, jet);
                cross(jet[1], jet[2], x);
                double jn = norm3(x);
                if (a && c) jmax = fmax(jmax, jn), jmin = fmin(jmin, jn); /* not on the spokes */
                if (!(jn > 0)) continue;
                jet_curv(jet, &K, &H, N);
                if (dot3(N, nev) < 0) H = -H;
                kc = fmax(kc, fabs(K));
                cmin = fmin(cmin, K), cmaxk = fmax(cmaxk, K), chmin = fmin(chmin, H), chmax = fmax(chmax, H);
            }
    F->jac = fmin(F->jac, jmin / jmax);
    if ((ref[0] > 0 && cmin <= 0) || (ref[1] < 0 && cmaxk >= 0)) F->ksign++;
    if ((ref[2] > 0 && chmin <= 0) || (ref[3] < 0 && chmax >= 0)) F->hsign++;
    if (ref[4] > 0) F->kratio = fmax(F->kratio, kc / ref[4]);
    if (ref[5] > 0) F->kring = fmax(F->kring, kc / ref[5]);
    double jump = 0;
    for (int s = 0; s < n; s++) { /* spoke s + 1: sector s's v-axis, sector s + 1's u-axis */
        int s1 = (s + 1) % n;
        for (int q = 1; q <= 40; q++) {
            double t = q / 41.0, j1[6][3], j2[6][3], K1, K2, H1, H2, N1[3], N2[3];
            fill_jet(b, s, 0, t, j1);
            fill_jet(b, s1, t, 0, j2);
            jet_curv(j1, &K1, &H1, N1), jet_curv(j2, &K2, &H2, N2);
            jump = fmax(jump, fabs(K1 - K2));
            F->g1 = fmax(F->g1, plane_angle(N1, N2));
        }
    }
    for (int32_t i = 0; i < plan->nhv; i++) { /* the border against the exact curvature there */
        double u = plan->hv_uv[2 * i], v = plan->hv_uv[2 * i + 1];
        if (plan->hv_cap[i] != cap_id || (u < 1 - 1e-12 && v < 1 - 1e-12)) continue;
        double j1[6][3], K, H, N[3];
        fill_jet(b, plan->hv_sector[i], u, v, j1);
        jet_curv(j1, &K, &H, N);
        const double *k = pr->k + 2 * (size_t)plan->hv_out[i];
        if (isfinite(k[0]) && isfinite(k[1])) jump = fmax(jump, fabs(K - k[0] * k[1]));
    }
    if (kc > 0) F->kjump = fmax(F->kjump, jump / kc);
    for (int s = 0; s < n; s++) { /* the centre */
        double j1[6][3], K, H, N[3];
        fill_jet(b, s, 0, 0, j1);
        jet_curv(j1, &K, &H, N);
        if (dot3(N, nev) < 0)
            for (int k = 0; k < 3; k++) N[k] = -N[k];
        F->centre = fmax(F->centre, angle(N, nev));
    }
    free(b);
    F->holes_checked++;
}

static inline void fair_init(fair *F) {
    memset(F, 0, sizeof *F);
    F->jac = 1;
}

/* Both plans of one cage at level L (the cap plan with base.cap G1_FILL, else GUIDED_BI5);
 * returns -1 if a plan failed. */
static inline int fair_measure(const ccn_cage *cage, int L, ccn_options base, fair *F) {
    fplan pb, pr;
    ccn_options ob = base, orf = base;
    ob.levels = orf.levels = L;
    ob.cap = base.cap == CCN_CAP_G1_FILL ? CCN_CAP_G1_FILL : CCN_CAP_GUIDED_BI5;
    orf.cap = CCN_CAP_REFINE;
    if (fplan_run(cage, ob, &pb) || fplan_run(cage, orf, &pr)) { fplan_free(&pb); fplan_free(&pr); return -1; }
    ccn_sizes sz;
    ccn_plan_get_sizes(pb.p, &sz);
    ccn_plan_stats sz_st;
    ccn_plan_get_stats(pb.p, &sz_st);
    F->caps += sz_st.num_caps;
    F->fallbacks += sz_st.num_cap_fallbacks;
    double size = bbox_diag(pr.x, pr.nv);
    /* hole membership: output vertex strictly inside cap c -> c + 1 */
    uint8_t *hole = calloc((size_t)pr.nv, 1);
    int32_t *evout = malloc(sizeof(int32_t) * (size_t)(pb.p->ncap + 1));
    for (int32_t c = 0; c < pb.p->ncap; c++) evout[c] = -1;
    for (int32_t i = 0; i < pb.p->nhv; i++) {
        double u = pb.p->hv_uv[2 * i], v = pb.p->hv_uv[2 * i + 1];
        if (u < 1 - 1e-12 && v < 1 - 1e-12) hole[pb.p->hv_out[i]] = (uint8_t)(pb.p->hv_cap[i] + 1);
        if (u == 0 && v == 0) evout[pb.p->hv_cap[i]] = pb.p->hv_out[i];
    }
    uint8_t *twin = calloc((size_t)pr.nv, 1);
    for (int32_t i = 0; i < pb.p->nhv; i++) twin[pb.p->hv_out[i]] = pb.p->caps[pb.p->hv_cap[i]].wu > 0;
    for (int32_t i = 0; i < pb.p->nbv; i++) twin[pb.p->bv_out[i]] |= pb.p->caps[pb.p->rf_cap[pb.p->bv_rf[i]]].exact_surround;
    for (int32_t c = 0; c < pb.p->ncap; c++) F->twins += pb.p->caps[c].wu > 0;
    for (int32_t v = 0; v < pr.nv; v++) {
        if (hole[v]) continue;
        double d[3] = {pb.x[3 * v] - pr.x[3 * v], pb.x[3 * v + 1] - pr.x[3 * v + 1], pb.x[3 * v + 2] - pr.x[3 * v + 2]};
        if (twin[v]) {
            F->twin_out = fmax(F->twin_out, norm3(d) / size);
            F->twin_g1 = fmax(F->twin_g1, angle(pb.n + 3 * v, pr.n + 3 * v));
            continue;
        }
        F->outside = fmax(F->outside, norm3(d) / size);
        F->g1 = fmax(F->g1, angle(pb.n + 3 * v, pr.n + 3 * v)); /* the hole's border and beyond */
    }
    free(twin);
    double rmax, excess = turn_excess(&pr, &pb, &rmax);
    F->turn = fmax(F->turn, excess / rmax);
    F->turn_ref = fmax(F->turn_ref, rmax);
    int32_t *nbs, *nb;
    neighbours(&pr, &nbs, &nb);
    for (int32_t c = 0; c < pb.p->ncap; c++)
        if (evout[c] >= 0 && !(pb.p->caps[c].w > 0))
            measure_fill(pb.p, &pb.p->caps[c], &pr, hole, c, nbs, nb, evout[c], F);
        else if (evout[c] >= 0)
            measure_cap(pb.p, &pb.p->caps[c], &pr, hole, c, nbs, nb, evout[c], F);
    free(nbs); free(nb); free(hole); free(evout);
    fplan_free(&pb);
    fplan_free(&pr);
    return 0;
}

static inline void fair_print(const char *what, const fair *F) {
    printf("%-34s caps %d (fallbacks %d): turn excess %.3f of max %.3g; K sign %d, H sign %d; max|K| ratio %.2f; "
           "K jump %.3f; centre %.2g rad; outside %.2g; G1 %.2g rad; min|Xu x Xv| %.3f\n", what, F->caps,
           F->fallbacks, F->turn, F->turn_ref, F->ksign, F->hsign, F->kratio, F->kjump, F->centre, F->outside,
           F->g1, F->jac);
}

/* ---- the cages --------------------------------------------------------------------------------- */

/* Open star: valence n, m x m quads per sector, every edge parallel to spoke s carries d[s],
 * a dome (z = 0.5 (1 - r^2/(2 m^2)) at radius r). */
static void star_cage(int n, int m, const double *d, fcage *c) {
    c->nv = 1 + n * m * (m + 1), c->nf = n * m * m, c->ne = n * (2 * m * m + m);
    c->pos = malloc(sizeof(double) * 3 * (size_t)c->nv);
    c->fs = malloc(sizeof(int32_t) * (size_t)c->nf);
    c->fv = malloc(sizeof(int32_t) * 4 * (size_t)c->nf);
    c->ev = malloc(sizeof(int32_t) * 2 * (size_t)c->ne);
    c->kn = malloc(sizeof(double) * (size_t)c->ne);
#define SV(s, i, j) ((i) == 0 ? ((j) == 0 ? 0 : 1 + (((s) + 1) % n) * m * (m + 1) + ((j) - 1) * (m + 1)) \
                              : 1 + ((s) % n) * m * (m + 1) + ((i) - 1) * (m + 1) + (j))
    c->pos[0] = c->pos[1] = 0, c->pos[2] = 0.5;
    for (int s = 0; s < n; s++)
        for (int i = 1; i <= m; i++)
            for (int j = 0; j <= m; j++) {
                double *p = c->pos + 3 * SV(s, i, j);
                p[0] = i * cos(2 * M_PI * s / n) + j * cos(2 * M_PI * (s + 1) / n);
                p[1] = i * sin(2 * M_PI * s / n) + j * sin(2 * M_PI * (s + 1) / n);
                p[2] = 0.5 * (1 - (p[0] * p[0] + p[1] * p[1]) / (2.0 * m * m));
            }
    int32_t f = 0, e = 0;
    for (int s = 0; s < n; s++) {
        for (int i = 0; i < m; i++)
            for (int j = 0; j < m; j++, f++) {
                c->fs[f] = 4;
                c->fv[4 * f] = SV(s, i, j), c->fv[4 * f + 1] = SV(s, i + 1, j);
                c->fv[4 * f + 2] = SV(s, i + 1, j + 1), c->fv[4 * f + 3] = SV(s, i, j + 1);
            }
        for (int j = 0; j <= m; j++)
            for (int i = 0; i < m; i++, e++)
                c->ev[2 * e] = SV(s, i, j), c->ev[2 * e + 1] = SV(s, i + 1, j), c->kn[e] = d[s];
        for (int i = 1; i <= m; i++)
            for (int j = 0; j < m; j++, e++)
                c->ev[2 * e] = SV(s, i, j), c->ev[2 * e + 1] = SV(s, i, j + 1), c->kn[e] = d[(s + 1) % n];
    }
#undef SV
}

/* Random general stars (tests/experiments/cap_table.c, cap_mesh_table.c): spoke intervals
 * log-uniform in [1, R] with one spoke at 1 and one at R (R > 1); 3 x 3 quads per sector,
 * jittered, random heights (not a symmetric dome). */
static inline void random_spokes(int n, double R, double *d) {
    for (int s = 0; s < n; s++) d[s] = exp(log(R) * tl_rand01());
    if (R > 1) {
        int a = (int)(tl_rand01() * n), b = (a + 1 + (int)(tl_rand01() * (n - 1))) % n;
        d[a] = 1, d[b] = R;
    }
}

static inline void general_star(int n, const double *d, fcage *c) {
    star_cage(n, 3, d, c);
    for (int32_t v = 1; v < c->nv; v++) {
        c->pos[3 * v] += 0.25 * (tl_rand01() - 0.5);
        c->pos[3 * v + 1] += 0.25 * (tl_rand01() - 0.5);
        c->pos[3 * v + 2] += 0.5 * (tl_rand01() - 0.5);
    }
    c->pos[2] = 0.3 + 0.6 * tl_rand01();
}

/* A row of the tables: `cases` random general stars of valence n and ratio R, each given to fn
 * (k: its index in the row) and freed after. */
typedef void (*star_fn)(void *ctx, int k, fcage *c);
static inline void star_row(int n, double R, int cases, star_fn fn, void *ctx) {
    for (int k = 0; k < cases; k++) {
        double d[12];
        random_spokes(n, R, d);
        fcage c;
        general_star(n, d, &c);
        fn(ctx, k, &c);
        fcage_free(&c);
    }
}

/* The cage as an OBJ with `# knot` lines (to look at a case of the tables). */
static inline void fcage_write_obj(const fcage *c, const char *path) {
    FILE *fo = fopen(path, "w");
    if (!fo) return;
    for (int32_t v = 0; v < c->nv; v++) fprintf(fo, "v %.17g %.17g %.17g\n", c->pos[3 * v], c->pos[3 * v + 1], c->pos[3 * v + 2]);
    for (int32_t f = 0; f < c->nf; f++)
        fprintf(fo, "f %d %d %d %d\n", c->fv[4 * f] + 1, c->fv[4 * f + 1] + 1, c->fv[4 * f + 2] + 1, c->fv[4 * f + 3] + 1);
    for (int32_t e = 0; e < c->ne; e++) fprintf(fo, "# knot %d %d %.17g\n", c->ev[2 * e] + 1, c->ev[2 * e + 1] + 1, c->kn[e]);
    fclose(fo);
}

/* The tear box: a cube of 3 x 3 quads per side, x scaled by 1.4 and z by 0.8; the
 * x-parallel edges of the slab of largest x carry 0.25, the z-parallel edges of the middle z
 * slab 3, every other edge 1. */
static inline void tear_box(fcage *c) {
    int32_t id[4][4][4];
    c->nv = 0;
    c->pos = malloc(sizeof(double) * 3 * 64);
    for (int x = 0; x < 4; x++)
        for (int y = 0; y < 4; y++)
            for (int z = 0; z < 4; z++) {
                id[x][y][z] = -1;
                if (x > 0 && x < 3 && y > 0 && y < 3 && z > 0 && z < 3) continue;
                id[x][y][z] = c->nv;
                c->pos[3 * c->nv] = 1.4 * (x - 1.5), c->pos[3 * c->nv + 1] = y - 1.5, c->pos[3 * c->nv + 2] = 0.8 * (z - 1.5);
                c->nv++;
            }
    c->nf = 54;
    c->fs = malloc(sizeof(int32_t) * 54);
    c->fv = malloc(sizeof(int32_t) * 4 * 54);
    int32_t f = 0;
    for (int ax = 0; ax < 3; ax++)
        for (int side = 0; side < 4; side += 3)
            for (int a = 0; a < 3; a++)
                for (int b = 0; b < 3; b++, f++) {
                    const int du[4] = {0, 1, 1, 0}, dv[4] = {0, 0, 1, 1};
                    int32_t q[4];
                    for (int k = 0; k < 4; k++) {
                        int p[3];
                        p[ax] = side, p[(ax + 1) % 3] = a + du[k], p[(ax + 2) % 3] = b + dv[k];
                        q[k] = id[p[0]][p[1]][p[2]];
                    }
                    if (side == 0) { int32_t t = q[1]; q[1] = q[3]; q[3] = t; }
                    c->fs[f] = 4;
                    memcpy(c->fv + 4 * f, q, sizeof q);
                }
    /* the edges with their intervals: grid coordinates back from the positions */
    c->ev = malloc(sizeof(int32_t) * 2 * 216);
    c->kn = malloc(sizeof(double) * 216);
    c->ne = 0;
    for (int32_t q = 0; q < 54; q++)
        for (int j = 0; j < 4; j++) {
            int32_t a = c->fv[4 * q + j], b = c->fv[4 * q + (j + 1) % 4], dup = 0;
            for (int32_t e = 0; e < c->ne && !dup; e++)
                dup = (c->ev[2 * e] == b && c->ev[2 * e + 1] == a) || (c->ev[2 * e] == a && c->ev[2 * e + 1] == b);
            if (dup) continue;
            const double *pa = c->pos + 3 * a, *pb = c->pos + 3 * b;
            double gx = (pa[0] + pb[0]) / 2 / 1.4 + 1.5, gz = (pa[2] + pb[2]) / 2 / 0.8 + 1.5;
            double k = 1;
            if (fabs(pa[0] - pb[0]) > 1e-9 && gx > 2) k = 0.25;  /* x-parallel, slab x in [2, 3] */
            if (fabs(pa[2] - pb[2]) > 1e-9 && gz > 1 && gz < 2) k = 3; /* z-parallel, middle z slab */
            c->ev[2 * c->ne] = a, c->ev[2 * c->ne + 1] = b, c->kn[c->ne++] = k;
        }
}

#endif
