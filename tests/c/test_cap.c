/* The guided bi-5 cap inside the whole pipeline, on cages rather than c-nets:
 *  - uniform intervals: with cap = GUIDED_BI5 every output vertex outside the open holes,
 *    including the hole boundary, equals the exact limit (cap = REFINE, itself checked
 *    against OpenSubdiv in run_limit.sh) in position and normal: the bi-5 surface joins the
 *    bi-3 surround with matching value and tangent plane;
 *  - cap sectors meet G1: evaluating a separator from both sides gives one point and one
 *    normal (angle <= 1e-9 rad), and all sectors agree at the centre;
 *  - 140 random cages (valences 3, 5, 6, 7, 8, 10, 16, jittered) and the shipped cages, at
 *    levels above the cap level K (at L <= K no cap is built: surface/caps.c). */
#include "bi5/bi5.h"
#include "ccnurbs.h"
#include "surface/patches.h"
#include "surface/plan_types.h"
#include "testlib.h"
#include "plan_with.h"
#include "bi5_props.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

typedef struct { int32_t nv, nf; double *pos; int32_t *fv, *fs; } cage_buf;

/* Open fan: valence-n centre, 3x3 quads per sector, positions jittered by `jit`. */
static void make_fan(int n, double jit, cage_buf *c) {
    int m = 3;
    c->nv = 1 + n * m + n * m * m;
    c->nf = n * m * m;
    c->pos = malloc(sizeof(double) * 3 * c->nv);
    c->fv = malloc(sizeof(int32_t) * 4 * c->nf);
    c->fs = malloc(sizeof(int32_t) * c->nf);
#define VID(s, i, j) ((i) == 0 && (j) == 0 ? 0 : (j) == 0 ? 1 + ((s) % n) * m + (i)-1 \
                      : (i) == 0 ? 1 + (((s) + 1) % n) * m + (j)-1 : 1 + n * m + (s) * m * m + ((i)-1) * m + (j)-1)
    for (int s = 0; s < n; s++) {
        double a0 = 2 * M_PI * s / n, a1 = 2 * M_PI * (s + 1) / n;
        for (int i = 0; i <= m; i++)
            for (int j = 0; j <= m; j++) {
                if (j == 0 && i == 0) continue;
                if (i == 0) continue; /* owned by sector s+1 as its j == 0 spoke */
                int v = VID(s, i, j);
                double *p = c->pos + 3 * v;
                p[0] = i * cos(a0) + j * cos(a1) + jit * (tl_rand01() - 0.5);
                p[1] = i * sin(a0) + j * sin(a1) + jit * (tl_rand01() - 0.5);
                p[2] = 0.3 * sin(p[0]) * cos(p[1]) + jit * (tl_rand01() - 0.5);
            }
        for (int i = 0; i < m; i++)
            for (int j = 0; j < m; j++) {
                int f = s * m * m + i * m + j;
                c->fs[f] = 4;
                c->fv[4 * f + 0] = VID(s, i, j);
                c->fv[4 * f + 1] = VID(s, i + 1, j);
                c->fv[4 * f + 2] = VID(s, i + 1, j + 1);
                c->fv[4 * f + 3] = VID(s, i, j + 1);
            }
    }
#undef VID
    c->pos[0] = c->pos[1] = 0;
    c->pos[2] = 0.5 + jit * (tl_rand01() - 0.5);
}

static void unit(const double *du, const double *dv, double *n) {
    n[0] = du[1] * dv[2] - du[2] * dv[1];
    n[1] = du[2] * dv[0] - du[0] * dv[2];
    n[2] = du[0] * dv[1] - du[1] * dv[0];
    double l = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    for (int k = 0; k < 3; k++) n[k] /= l;
}

typedef struct {
    double pos_err, nrm_err, sep_pos, sep_nrm, centre_nrm;
    double twin_err; /* hole borders and ring faces of caps blended with their uniform twin (intervals
                        within 1 % of equal) */
    int twin_verts;
    double internal, spokes, r2r, cap_ring, curv, surround; /* bi5_props.h, relative */
    int caps, inside, surround_caps;
    double tol_c2;   /* ring C2 tolerance (0: 1e-9) */
    double tol_curv; /* centre curvature spread tolerance (0: 1e-6) */
} cap_stats;

/* G1 across the separators and at the centre, straight from the evaluated patches. */
static void check_separators(const ccn_plan *p, cap_stats *st, double size) {
    for (int32_t c = 0; c < p->ncap; c++) {
        const ccn__cap *cp = &p->caps[c];
        double n0[3] = {0, 0, 0};
        for (int32_t s = 0; s < cp->n; s++) {
            int32_t sp = (s + cp->n - 1) % cp->n;
            for (int k = 0; k <= 20; k++) {
                double t = k / 20.0, x1[3], a1[3], b1[3], x2[3], a2[3], b2[3], nn1[3], nn2[3];
                /* spoke s: v = 0 in sector s, u = 0 in sector s-1 */
                ccn__bi5_eval(cp->op, cp->patches, s, t, 0, x1, a1, b1);
                ccn__bi5_eval(cp->op, cp->patches, sp, 0, t, x2, a2, b2);
                unit(a1, b1, nn1);
                unit(a2, b2, nn2);
                for (int i = 0; i < 3; i++) {
                    double e = fabs(x1[i] - x2[i]) / size;
                    if (!(e <= st->sep_pos)) st->sep_pos = e;
                }
                double an = angle(nn1, nn2);
                if (!(an <= st->sep_nrm)) st->sep_nrm = an;
                if (k == 0) {
                    if (s == 0) memcpy(n0, nn1, sizeof n0);
                    double ac = angle(n0, nn1);
                    if (!(ac <= st->centre_nrm)) st->centre_nrm = ac;
                }
            }
        }
    }
}

/* Level-(K+1) face across the hole boundary next to hole points A, B (on the boundary): the
 * orientation is found by matching the patch's corner values with the cap's values at A and B
 * (not from the library's numbering), then derivatives up to order 2 of the cap's ring 0 (from
 * inside) and of the bicubic patch (outside; patches.c, checked against de Boor in
 * test_patches) are compared along the shared edge, in hole units. */
static double surround_piece(const surf_t *S, int s, const double bez[4][4][3], const double A[2],
                             const double B[2], double size) {
    static const int corner[4][2] = {{0, 0}, {3, 0}, {0, 3}, {3, 3}};
    double pa[3], pb[3], M[6][6][3], worst = 0;
    int ka = 0, kb = 0, kinda = A[0] == 1 ? (A[1] < 0.5 || B[1] < 0.5 ? 0 : 1) : (A[0] < 0.5 || B[0] < 0.5 ? 2 : 1);
    ring_eval(S, 0, kinda, s, A[0], A[1], 0, 0, pa);
    ring_eval(S, 0, kinda, s, B[0], B[1], 0, 0, pb);
    double ea = 1e300, eb = 1e300;
    for (int k = 0; k < 4; k++) {
        const double *c = bez[corner[k][0]][corner[k][1]];
        if (vdiff(c, pa) < ea) { ea = vdiff(c, pa); ka = k; }
        if (vdiff(c, pb) < eb) { eb = vdiff(c, pb); kb = k; }
    }
    if (ea > 1e-9 * size || eb > 1e-9 * size || ka == kb) return INFINITY;
    double cA[2] = {corner[ka][0] / 3.0, corner[ka][1] / 3.0}, cB[2] = {corner[kb][0] / 3.0, corner[kb][1] / 3.0};
    int ax_e = cA[0] != cB[0] ? 0 : 1, ax_f = 1 - ax_e; /* param axis along the edge / outward */
    double sf = cA[ax_f] == 0 ? 1 : -1;                 /* outward sign in param space */
    int uleg = A[0] == 1 && B[0] == 1;
    double along = uleg ? B[1] - A[1] : B[0] - A[0];    /* hole length of the edge (+-1/2) */
    double se = (cB[ax_e] - cA[ax_e]) / along;          /* d(param along e) / d(hole along) */
    power_form(3, &bez[0][0][0], M);
    for (int q = 0; q <= 8; q++) {
        double x = q / 8.0, h[2] = {A[0] + x * (B[0] - A[0]), A[1] + x * (B[1] - A[1])};
        double prm[2];
        prm[ax_e] = cA[ax_e] + x * (cB[ax_e] - cA[ax_e]);
        prm[ax_f] = cA[ax_f];
        int kind = uleg ? (h[1] < 0.5 || (h[1] == 0.5 && x < 0.5) ? 0 : 1) : (h[0] < 0.5 || (h[0] == 0.5 && x < 0.5) ? 2 : 1);
        for (int k = 0; k <= 2; k++)
            for (int l = 0; k + l <= 2; l++) { /* d_u^k d_v^l */
                double a[3], b[3];
                ring_eval(S, 0, kind, s, h[0], h[1], k, l, a);
                int nu = uleg ? k : l, ne = uleg ? l : k; /* outward order, along order */
                int d0 = ax_f == 0 ? nu : ne, d1 = ax_f == 0 ? ne : nu;
                pf_eval(M, prm[0], prm[1], d0, d1, b);
                double f = pow(2 * sf, nu) * pow(se, ne); /* outward: 2 per hole unit */
                for (int c = 0; c < 3; c++) b[c] *= f;
                worst = fmax(worst, vdiff(a, b));
            }
    }
    return worst;
}

/* Ring/cap properties (bi5_props.h) of every cap, and for exact-surround caps the C2 join of
 * ring 0 with the level-(K+1) bicubic surround. */
static void check_props(const ccn_plan *p, cap_stats *st, double size) {
    for (int32_t c = 0; c < p->ncap; c++) {
        const ccn__cap *cp = &p->caps[c];
        surf_t S;
        surf_init(&S, cp->n, cp->op->nsig, cp->op->sig, cp->patches);
        if (!S.M) continue;
        st->internal = fmax(st->internal, ring_internal(&S) / size);
        st->spokes = fmax(st->spokes, ring_spokes(&S, cp->knots) / size);
        st->r2r = fmax(st->r2r, ring_to_ring(&S, 2) / size);
        st->cap_ring = fmax(st->cap_ring, ring_to_ring(&S, 1) / size);
        st->curv = fmax(st->curv, centre_curvature(&S));
        if (cp->exact_surround) {
            const ccn_mesh *mK = p->lev[p->K], *m1 = p->lev[p->K + 1];
            int32_t ev = cp->cnet[0];
            for (int32_t s = 0; s < cp->n; s++) {
                int32_t h = mK->vfan[mK->vfan_start[ev] + s], g = ccn__next(mK, h), g2 = ccn__next(mK, g);
                int32_t t = mK->htwin[g], t2 = mK->htwin[g2];
                /* children (refine.c numbering: child quad = parent half-edge) */
                const int32_t ch[4] = {ccn__next(mK, t), t, t2, ccn__next(mK, t2)};
                static const double P[4][2][2] = {{{1, 0}, {1, 0.5}}, {{1, 0.5}, {1, 1}},
                                                   {{0, 1}, {0.5, 1}}, {{0.5, 1}, {1, 1}}};
                for (int k = 0; k < 4; k++) {
                    double bez[4][4][3];
                    double e = ccn__bicubic_patch(m1, ch[k], 0, 1, bez)
                                   ? surround_piece(&S, s, (const double(*)[4][3])bez, P[k][0], P[k][1], size)
                                   : INFINITY;
                    st->surround = fmax(st->surround, e / size);
                }
            }
            st->surround_caps++;
        }
        free(S.M);
    }
}

/* bi-5 plan vs refine plan: equal outside the open holes. */
static void compare_cage(const ccn_cage *cage, int levels, cap_stats *st) {
    ccn_options ob = {0}, orf = {0};
    ob.levels = orf.levels = levels;
    orf.cap = CCN_CAP_REFINE;
    ccn_plan *pb = NULL, *pr = NULL;
    ccn_error err;
    CHECK(ccn_plan_create(cage, &ob, &pb, &err) == CCN_OK, "%s", err.message);
    CHECK(ccn_plan_create(cage, &orf, &pr, &err) == CCN_OK, "%s", err.message);
    if (!pb || !pr) { ccn_plan_destroy(pb); ccn_plan_destroy(pr); return; }
    ccn_sizes s;
    ccn_plan_get_sizes(pb, &s);
    ccn_plan_stats s_st;
    ccn_plan_get_stats(pb, &s_st);
    double *xb = malloc(sizeof(double) * 3 * s.num_verts), *nb = malloc(sizeof(double) * 3 * s.num_verts);
    double *xr = malloc(sizeof(double) * 3 * s.num_verts), *nr = malloc(sizeof(double) * 3 * s.num_verts);
    ccn_limit_mesh lb = {.positions = xb, .normals = nb}, lr = {.positions = xr, .normals = nr};
    CHECK(ccn_plan_evaluate(pb, NULL, &lb, &err) == CCN_OK, "%s", err.message);
    CHECK(ccn_plan_evaluate(pr, NULL, &lr, &err) == CCN_OK, "%s", err.message);
    uint8_t *inside = calloc(s.num_verts, 1);
    for (int32_t i = 0; i < pb->nhv; i++)
        if (pb->hv_uv[2 * i] < 1 - 1e-12 && pb->hv_uv[2 * i + 1] < 1 - 1e-12) inside[pb->hv_out[i]] = 1;
    for (int32_t i = 0; i < pb->nhv; i++) /* a twin's hole border and ring faces: the blend, apart */
        if (pb->caps[pb->hv_cap[i]].wu > 0 && !inside[pb->hv_out[i]]) inside[pb->hv_out[i]] = 2;
    for (int32_t i = 0; i < pb->nbv; i++)
        if (pb->caps[pb->rf_cap[pb->bv_rf[i]]].exact_surround) inside[pb->bv_out[i]] = 2;
    double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
    for (int32_t v = 0; v < s.num_verts; v++)
        for (int k = 0; k < 3; k++) {
            lo[k] = xr[3 * v + k] < lo[k] ? xr[3 * v + k] : lo[k];
            hi[k] = xr[3 * v + k] > hi[k] ? xr[3 * v + k] : hi[k];
        }
    double size = sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) + (hi[2] - lo[2]) * (hi[2] - lo[2]));
    for (int32_t v = 0; v < s.num_verts; v++) {
        if (inside[v] == 2) {
            st->twin_verts++;
            for (int k = 0; k < 3; k++) st->twin_err = fmax(st->twin_err, fabs(xb[3 * v + k] - xr[3 * v + k]) / size);
            continue;
        }
        if (inside[v]) { st->inside++; continue; }
        for (int k = 0; k < 3; k++) {
            double e = fabs(xb[3 * v + k] - xr[3 * v + k]) / size;
            if (!(e <= st->pos_err)) st->pos_err = e;
        }
        double an = angle(nb + 3 * v, nr + 3 * v);
        if (!(an <= st->nrm_err)) st->nrm_err = an;
    }
    st->caps += s_st.num_caps;
    check_separators(pb, st, size);
    check_props(pb, st, size);
    free(inside); free(xb); free(nb); free(xr); free(nr);
    ccn_plan_destroy(pb);
    ccn_plan_destroy(pr);
}

static void report(const char *what, const cap_stats *st) {
    printf("  %s: %d caps, %d hole vertices; outside holes vs exact limit: pos %.2g, normal %.2g rad; "
           "separators: pos %.2g, normal %.2g rad, centre %.2g rad\n", what, st->caps, st->inside,
           st->pos_err, st->nrm_err, st->sep_pos, st->sep_nrm, st->centre_nrm);
    CHECK(st->caps > 0, "%s: caps were built", what);
    CHECK(st->inside > 0, "%s: vertices inside holes", what);
    CHECK(st->pos_err <= 1e-9, "%s: position outside holes %g", what, st->pos_err);
    if (st->twin_verts)
        printf("  %s: %d ring-face vertices of caps blended with their uniform twin: %.2g of the size from the "
               "exact limit (their hole borders included)\n", what, st->twin_verts, st->twin_err);
    CHECK(st->twin_err <= 1e-4, "%s: a uniform twin's ring faces %g from the exact limit", what, st->twin_err);
    CHECK(st->nrm_err <= 1e-9, "%s: normal outside holes %g", what, st->nrm_err);
    CHECK(st->sep_pos <= 1e-9, "%s: separator position %g", what, st->sep_pos);
    CHECK(st->sep_nrm <= 1e-9, "%s: separator normal angle %g", what, st->sep_nrm);
    CHECK(st->centre_nrm <= 1e-9, "%s: centre normal angle %g", what, st->centre_nrm);
    printf("  %s: C2 in ring %.1e, across spokes %.1e, ring-ring %.1e, cap-ring C1 %.1e, centre (H,K) "
           "spread %.1e; %d exact-surround caps, ring 0 vs bi-3 surround C2 %.1e\n", what, st->internal,
           st->spokes, st->r2r, st->cap_ring, st->curv, st->surround_caps, st->surround);
    double tol = st->tol_c2 > 0 ? st->tol_c2 : 1e-9;
    CHECK(st->internal <= tol && st->spokes <= tol && st->r2r <= tol, "%s: ring C2 (%g, %g, %g)",
          what, st->internal, st->spokes, st->r2r);
    CHECK(st->cap_ring <= 1e-9, "%s: cap-ring C1 %g", what, st->cap_ring);
    CHECK(st->curv <= (st->tol_curv > 0 ? st->tol_curv : 1e-6), "%s: centre curvature spread %g", what, st->curv);
    CHECK(st->surround <= 1e-9, "%s: ring 0 / surround C2 %g", what, st->surround);
}

/* the number of random fans per test: 140, or 28 (every valence, both parities) in the
 * sanitizer run (CCN_TEST_SMALL), where the paths matter and the plain build checks the figures */
static int fan_cases(void) { return getenv("CCN_TEST_SMALL") ? 28 : 140; }

static void test_random_fans(void) {
    static const int valences[] = {3, 5, 6, 7, 8, 10, 16};
    cap_stats st = {0};
    int ncases = fan_cases();
    for (int k = 0; k < ncases; k++) {
        cage_buf c;
        make_fan(valences[k % 7], 0.3, &c);
        ccn_cage cage = {0};
        cage.num_verts = c.nv; cage.num_faces = c.nf; cage.positions = c.pos;
        cage.face_sizes = c.fs; cage.face_verts = c.fv;
        compare_cage(&cage, 3 + k % 2, &st); /* levels above K = 2: no cap is built at L <= K */
        free(c.pos); free(c.fv); free(c.fs);
    }
    char what[64];
    snprintf(what, sizeof what, "%d random fans", ncases);
    report(what, &st);
}

static void test_shipped_cages(void) {
    const char *names[] = {"cube.obj", "icosa_quad.obj", "pole12.obj", "pentaprism.obj", "jitter_sphere.obj", "flip35.obj", "ngon_prism.obj"};
    cap_stats st = {0};
    for (size_t i = 0; i < sizeof names / sizeof *names; i++) {
        char path[128];
        snprintf(path, sizeof path, "tests/data/%s", names[i]);
        size_t len;
        char *t = tl_slurp(path, &len);
        ccn_obj *o = NULL;
        ccn_error err;
        if (!t || ccn_obj_parse(t, len, &o, &err)) { CHECK(0, "load %s", names[i]); free(t); continue; }
        ccn_cage cage;
        ccn_obj_get_cage(o, &cage);
        compare_cage(&cage, 4, &st); /* above K (2, or 3 for close EVs) */
        ccn_obj_destroy(o);
        free(t);
    }
    /* Holes of level 3-4 on unit-box cages: second derivatives in hole units of the inner rings
     * carry the rounding of the BB coefficients amplified by 1/rho^2 per ring (the c-net tests
     * of test_bi5 hold 1e-9); measured 2.5e-9 at most. */
    st.tol_c2 = 1e-8;
    report("shipped cages", &st);
}

/* Fan cage whose edges parallel to spoke s carry d[s] (opposite edges of quads agree). */
static void fan_knots(const cage_buf *c, int n, const double *d, ccn_cage *cage, int32_t **ev, double **kn) {
    *ev = malloc(sizeof(int32_t) * 8 * c->nf);
    *kn = malloc(sizeof(double) * 4 * c->nf);
    int ne = 0;
    for (int f = 0; f < c->nf; f++) {
        int s = f / 9;
        for (int j = 0; j < 4; j++) {
            (*ev)[2 * ne] = c->fv[4 * f + j];
            (*ev)[2 * ne + 1] = c->fv[4 * f + (j + 1) % 4];
            (*kn)[ne++] = j % 2 == 0 ? d[s] : d[(s + 1) % n];
        }
    }
    memset(cage, 0, sizeof *cage);
    cage->num_verts = c->nv; cage->num_faces = c->nf; cage->positions = c->pos;
    cage->face_sizes = c->fs; cage->face_verts = c->fv;
    cage->num_edges = ne; cage->edge_verts = *ev; cage->edge_knots = *kn;
}

/* Plan (levels 3, default options) of fan c with spoke intervals d; frees c and the knot arrays
 * (the plan keeps its own copies). NULL after a failed CHECK. */
static ccn_plan *fan_plan(cage_buf *c, int n, const double *d) {
    ccn_cage cage;
    int32_t *ev;
    double *kn;
    fan_knots(c, n, d, &cage, &ev, &kn);
    ccn_options o = {0};
    o.levels = 3;
    ccn_plan *p = NULL;
    ccn_error err;
    CHECK(ccn_plan_create(&cage, &o, &p, &err) == CCN_OK, "%s", err.message);
    free(ev); free(kn); free(c->pos); free(c->fv); free(c->fs);
    return p;
}

/* Period-4 intervals (n = 8) with kappa within the cap's range (1.05): G1 holds. */
static void test_nonuniform_period4(void) {
    cap_stats st = {0};
    for (int k = 0; k < 10; k++) {
        cage_buf c;
        make_fan(8, 0.2, &c);
        double d[4] = {1 + 0.02 * tl_rand01(), 1 + 0.02 * tl_rand01(), 1 + 0.02 * tl_rand01(), 1 + 0.02 * tl_rand01()};
        double d8[8]; /* every edge parallel to spoke s carries d[s % 4] */
        for (int s = 0; s < 8; s++) d8[s] = d[s % 4];
        ccn_plan *p = fan_plan(&c, 8, d8);
        ccn_error err;
        if (p) {
            ccn_sizes s;
            ccn_plan_get_sizes(p, &s);
            ccn_plan_stats s_st;
            ccn_plan_get_stats(p, &s_st);
            st.caps += s_st.num_caps;
            double *x = malloc(sizeof(double) * 3 * s.num_verts), *nn = malloc(sizeof(double) * 3 * s.num_verts);
            ccn_limit_mesh lm = {.positions = x, .normals = nn};
            CHECK(ccn_plan_evaluate(p, NULL, &lm, &err) == CCN_OK, "%s", err.message);
            check_separators(p, &st, 6.0);
            st.inside += p->nhv;
            free(x); free(nn);
            ccn_plan_destroy(p);
        }
    }
    printf("  period-4 non-uniform n = 8: %d caps; separators: pos %.2g, normal %.2g rad, centre %.2g rad\n",
           st.caps, st.sep_pos, st.sep_nrm, st.centre_nrm);
    CHECK(st.caps == 10, "caps built for supported non-uniform intervals: %d", st.caps);
    CHECK(st.sep_pos <= 1e-9 && st.sep_nrm <= 1e-9 && st.centre_nrm <= 1e-9, "G1");
}

/* Arbitrary non-uniform spoke intervals within the cap's kappa range (bi5.h [R13]): the cap is
 * built on the exact level-(K+1) surround, so outside the open holes (hole boundary included)
 * the surface is the exact limit, and the sectors meet G1. Half the cases have kappa = 1
 * (alternating intervals, even n, ratio up to 1:4), which is not limited. */
static void test_nonuniform_general(void) {
    static const int valences[] = {3, 5, 6, 7, 8, 10, 16};
    cap_stats st = {0};
    int fallbacks = 0, cases = 0, ncases = fan_cases();
    for (int k = 0; k < ncases; k++) {
        int n = valences[k % 7];
        cage_buf c;
        make_fan(n, 0.3, &c);
        double d[16], r = 0.5 + 1.5 * tl_rand01();
        for (int s = 0; s < n; s++) d[s] = (k & 1) && !(n & 1) ? (s & 1 ? r : 1) : 1 + 0.04 * (tl_rand01() - 0.5);
        ccn_cage cage;
        int32_t *ev;
        double *kn;
        fan_knots(&c, n, d, &cage, &ev, &kn);
        cap_stats one = {0};
        compare_cage(&cage, 3 + k % 2, &one);
        cases++;
        fallbacks += one.caps != 1;
        if (one.caps != 1) printf("  fallback: n = %d, levels %d\n", n, 2 + k % 3);
        st.caps += one.caps; st.inside += one.inside;
        st.pos_err = fmax(st.pos_err, one.pos_err); st.nrm_err = fmax(st.nrm_err, one.nrm_err);
        st.twin_err = fmax(st.twin_err, one.twin_err); st.twin_verts += one.twin_verts;
        st.sep_pos = fmax(st.sep_pos, one.sep_pos); st.sep_nrm = fmax(st.sep_nrm, one.sep_nrm);
        st.centre_nrm = fmax(st.centre_nrm, one.centre_nrm);
        st.internal = fmax(st.internal, one.internal); st.spokes = fmax(st.spokes, one.spokes);
        st.r2r = fmax(st.r2r, one.r2r); st.cap_ring = fmax(st.cap_ring, one.cap_ring);
        st.curv = fmax(st.curv, one.curv); st.surround = fmax(st.surround, one.surround);
        st.surround_caps += one.surround_caps;
        free(ev); free(kn); free(c.pos); free(c.fv); free(c.fs);
    }
    /* G1 is what the cap promises; with non-uniform spokes the sectors' curvatures at the centre
     * agree only approximately (the centre's cubic expansion is fitted, not interpolated) */
    st.tol_curv = 1e-3;
    char what[96];
    snprintf(what, sizeof what, "%d fans, intervals 1 +- 0.02 or alternating 1, r (r in [0.5, 2])", ncases);
    report(what, &st);
    CHECK(fallbacks == 0, "%d of %d cages fell back", fallbacks, cases);
    CHECK(st.surround_caps == cases, "%d of %d caps on the exact surround", st.surround_caps, cases);
}

/* Spoke ratios outside the cap's kappa range (Fig. 16: kappa = r beside 1/r) fall back to the
 * exact refined limit and are counted: r = 1.04 gets a cap, 1.06, 3 and 10 do not. */
static void test_nonuniform_extreme(void) {
    static const double pat[6] = {1, 0, 0, 1, 1, 0}; /* 1 or r on the spokes (Fig. 16) */
    const double ratios[4] = {1.04, 1.06, 3, 10};
    for (int q = 0; q < 4; q++) {
        cage_buf c;
        make_fan(6, 0.0, &c);
        double d[6];
        for (int s = 0; s < 6; s++) d[s] = pat[s] ? 1 : ratios[q];
        ccn_plan *p = fan_plan(&c, 6, d);
        if (p) {
            ccn_sizes sz;
            ccn_plan_get_sizes(p, &sz);
            ccn_plan_stats sz_st;
            ccn_plan_get_stats(p, &sz_st);
            printf("  Fig. 16 pattern, ratio %g: %d caps, %d cap fallbacks\n", ratios[q], sz_st.num_caps, sz_st.num_cap_fallbacks);
            CHECK(q == 0 ? sz_st.num_caps == 1 && sz_st.num_cap_fallbacks == 0 : sz_st.num_caps == 0 && sz_st.num_cap_fallbacks == 1,
                  "ratio %g: %d caps, %d fallbacks", ratios[q], sz_st.num_caps, sz_st.num_cap_fallbacks);
            ccn_plan_destroy(p);
        }
    }
}

/* Linear precision with arbitrary non-uniform intervals: a planar cage gives a planar surface,
 * caps included (every rule and the cap construction are affine combinations). */
static void test_nonuniform_planar(void) {
    static const int valences[] = {3, 5, 6, 7, 8, 10, 16};
    double worst = 0;
    int caps = 0;
    for (int k = 0; k < 14; k++) {
        int n = valences[k % 7];
        cage_buf c;
        make_fan(n, 0.3, &c);
        for (int v = 0; v < c.nv; v++) c.pos[3 * v + 2] = 0.25 * c.pos[3 * v] - 0.5 * c.pos[3 * v + 1] + 1;
        double d[16];
        for (int s = 0; s < n; s++) d[s] = 1 + 0.04 * (tl_rand01() - 0.5);
        ccn_plan *p = fan_plan(&c, n, d);
        ccn_error err;
        if (p) {
            ccn_sizes sz;
            ccn_plan_get_sizes(p, &sz);
            ccn_plan_stats sz_st;
            ccn_plan_get_stats(p, &sz_st);
            caps += sz_st.num_caps;
            double *x = malloc(sizeof(double) * 3 * sz.num_verts);
            ccn_limit_mesh lm = {.positions = x};
            CHECK(ccn_plan_evaluate(p, NULL, &lm, &err) == CCN_OK, "%s", err.message);
            for (int32_t v = 0; v < sz.num_verts; v++)
                worst = fmax(worst, fabs(x[3 * v + 2] - (0.25 * x[3 * v] - 0.5 * x[3 * v + 1] + 1)));
            free(x);
            ccn_plan_destroy(p);
        }
    }
    printf("  planar cages, random intervals: %d caps, largest distance from the plane %.1e\n", caps, worst);
    CHECK(caps == 14, "caps built: %d", caps);
    CHECK(worst <= 1e-12, "off-plane %g", worst);
}

/* ccn_plan_create with options.cache: plans sharing one ccn_cache of bi-5 operators give output
 * byte-identical to ccn_plan_create, also the second plan of each valence (operator reused),
 * with uniform and non-uniform (exact surround) caps; the cache outlives the plans. */
static void test_shared_cache(void) {
    static const int valences[] = {3, 5, 8, 5, 3, 8};
    ccn_cache *cache = NULL;
    ccn_error err;
    CHECK(ccn_cache_create(&cache, &err) == CCN_OK, "%s", err.message);
    int same = 0, caps = 0;
    for (int k = 0; k < 6 && cache; k++) {
        int n = valences[k];
        cage_buf c;
        make_fan(n, 0.2, &c);
        double d[8];
        for (int s = 0; s < n; s++) d[s] = k < 3 ? 1.0 : 1 + 0.04 * (tl_rand01() - 0.5);
        ccn_cage cage;
        int32_t *ev;
        double *kn;
        fan_knots(&c, n, d, &cage, &ev, &kn);
        ccn_options o = {0};
        o.levels = 3;
        ccn_plan *a = NULL, *b = NULL;
        CHECK(ccn_plan_create(&cage, &o, &a, &err) == CCN_OK, "%s", err.message);
        CHECK(plan_cached(&cage, &o, cache, &b, &err) == CCN_OK, "%s", err.message);
        if (a && b) {
            ccn_sizes sa, sb;
            ccn_plan_get_sizes(a, &sa);
            ccn_plan_stats sa_st;
            ccn_plan_get_stats(a, &sa_st);
            ccn_plan_get_sizes(b, &sb);
            ccn_plan_stats sb_st;
            ccn_plan_get_stats(b, &sb_st);
            caps += sb_st.num_caps;
            size_t nv = (size_t)sa.num_verts;
            double *xa = malloc(sizeof(double) * 6 * nv), *xb = malloc(sizeof(double) * 6 * nv);
            ccn_limit_mesh la = {.positions = xa, .normals = xa + 3 * nv}, lb = {.positions = xb, .normals = xb + 3 * nv};
            CHECK(ccn_plan_evaluate(a, NULL, &la, &err) == CCN_OK, "%s", err.message);
            CHECK(ccn_plan_evaluate(b, NULL, &lb, &err) == CCN_OK, "%s", err.message);
            int eq = sa.num_verts == sb.num_verts && sa_st.num_caps == sb_st.num_caps &&
                     memcmp(xa, xb, sizeof(double) * 6 * nv) == 0;
            CHECK(eq, "n = %d (case %d): the cached plan's output differs", n, k);
            same += eq;
            free(xa); free(xb);
        }
        ccn_plan_destroy(a);
        ccn_plan_destroy(b);
        free(ev); free(kn); free(c.pos); free(c.fv); free(c.fs);
    }
    printf("  shared ccn_cache: %d of 6 plans byte-identical, %d caps\n", same, caps);
    CHECK(caps >= 6, "caps built: %d", caps);
    ccn_cache_destroy(cache);
}

int main(void) {
    RUN(test_shared_cache);
    RUN(test_nonuniform_planar);
    RUN(test_nonuniform_extreme);
    RUN(test_nonuniform_general);
    RUN(test_random_fans);
    RUN(test_shipped_cages);
    RUN(test_nonuniform_period4);
    return TEST_SUMMARY();
}
