/* The guided bi-5 cap inside the whole pipeline (issue 4), on cages rather than c-nets:
 *  - uniform intervals: with cap = GUIDED_BI5 every output vertex outside the open holes,
 *    including the hole boundary, equals the exact limit (cap = REFINE, itself checked
 *    against OpenSubdiv in run_limit.sh) in position and normal: the bi-5 surface joins the
 *    bi-3 surround with matching value and tangent plane;
 *  - cap sectors meet G1: evaluating a separator from both sides gives one point and one
 *    normal (angle <= 1e-9 rad), and all sectors agree at the centre;
 *  - 200 random cages (valences 3, 5, 6, 7, 8, 10, 16, jittered) and the shipped cages. */
#include "bi5.h"
#include "ccnurbs.h"
#include "plan.h"
#include "testlib.h"

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

static double angle(const double *a, const double *b) {
    double d = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    double c[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
    return atan2(sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]), d);
}

static void unit(const double *du, const double *dv, double *n) {
    n[0] = du[1] * dv[2] - du[2] * dv[1];
    n[1] = du[2] * dv[0] - du[0] * dv[2];
    n[2] = du[0] * dv[1] - du[1] * dv[0];
    double l = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    for (int k = 0; k < 3; k++) n[k] /= l;
}

typedef struct { double pos_err, nrm_err, sep_pos, sep_nrm, centre_nrm; int caps, inside; } cap_stats;

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
    ccn_plan_sizes(pb, &s);
    double *xb = malloc(sizeof(double) * 3 * s.num_verts), *nb = malloc(sizeof(double) * 3 * s.num_verts);
    double *xr = malloc(sizeof(double) * 3 * s.num_verts), *nr = malloc(sizeof(double) * 3 * s.num_verts);
    ccn_limit_mesh lb = {xb, nb, NULL, NULL}, lr = {xr, nr, NULL, NULL};
    CHECK(ccn_plan_evaluate(pb, NULL, &lb, &err) == CCN_OK, "%s", err.message);
    CHECK(ccn_plan_evaluate(pr, NULL, &lr, &err) == CCN_OK, "%s", err.message);
    uint8_t *inside = calloc(s.num_verts, 1);
    for (int32_t i = 0; i < pb->nhv; i++)
        if (pb->hv_uv[2 * i] < 1 - 1e-12 && pb->hv_uv[2 * i + 1] < 1 - 1e-12) inside[pb->hv_out[i]] = 1;
    double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
    for (int32_t v = 0; v < s.num_verts; v++)
        for (int k = 0; k < 3; k++) {
            lo[k] = xr[3 * v + k] < lo[k] ? xr[3 * v + k] : lo[k];
            hi[k] = xr[3 * v + k] > hi[k] ? xr[3 * v + k] : hi[k];
        }
    double size = sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) + (hi[2] - lo[2]) * (hi[2] - lo[2]));
    for (int32_t v = 0; v < s.num_verts; v++) {
        if (inside[v]) { st->inside++; continue; }
        for (int k = 0; k < 3; k++) {
            double e = fabs(xb[3 * v + k] - xr[3 * v + k]) / size;
            if (!(e <= st->pos_err)) st->pos_err = e;
        }
        double an = angle(nb + 3 * v, nr + 3 * v);
        if (!(an <= st->nrm_err)) st->nrm_err = an;
    }
    st->caps += s.num_caps;
    check_separators(pb, st, size);
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
    CHECK(st->nrm_err <= 1e-9, "%s: normal outside holes %g", what, st->nrm_err);
    CHECK(st->sep_pos <= 1e-9, "%s: separator position %g", what, st->sep_pos);
    CHECK(st->sep_nrm <= 1e-9, "%s: separator normal angle %g", what, st->sep_nrm);
    CHECK(st->centre_nrm <= 1e-9, "%s: centre normal angle %g", what, st->centre_nrm);
}

static void test_random_fans(void) {
    static const int valences[] = {3, 5, 6, 7, 8, 10, 16};
    cap_stats st = {0};
    for (int k = 0; k < 200; k++) {
        cage_buf c;
        make_fan(valences[k % 7], 0.3, &c);
        ccn_cage cage = {0};
        cage.num_verts = c.nv; cage.num_faces = c.nf; cage.positions = c.pos;
        cage.face_sizes = c.fs; cage.face_verts = c.fv;
        compare_cage(&cage, 2 + k % 3, &st);
        free(c.pos); free(c.fv); free(c.fs);
    }
    report("200 random fans", &st);
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
        ccn_obj_cage(o, &cage);
        compare_cage(&cage, 3, &st);
        ccn_obj_destroy(o);
        free(t);
    }
    report("shipped cages", &st);
}

/* Non-uniform intervals with kappa != 1 that the cap supports (period 4, n = 8): G1 holds. */
static void test_nonuniform_period4(void) {
    cap_stats st = {0};
    for (int k = 0; k < 10; k++) {
        cage_buf c;
        make_fan(8, 0.2, &c);
        double d[4] = {0.3 + tl_rand01(), 0.3 + tl_rand01(), 0.3 + tl_rand01(), 0.3 + tl_rand01()};
        /* every edge parallel to spoke s carries d[s % 4] (opposite edges of quads agree) */
        int32_t *ev = malloc(sizeof(int32_t) * 8 * c.nf);
        double *kn = malloc(sizeof(double) * 4 * c.nf);
        int ne = 0;
        for (int f = 0; f < c.nf; f++) {
            int s = f / 9;
            for (int j = 0; j < 4; j++) {
                ev[2 * ne] = c.fv[4 * f + j];
                ev[2 * ne + 1] = c.fv[4 * f + (j + 1) % 4];
                kn[ne++] = j % 2 == 0 ? d[s % 4] : d[(s + 1) % 4];
            }
        }
        ccn_cage cage = {0};
        cage.num_verts = c.nv; cage.num_faces = c.nf; cage.positions = c.pos;
        cage.face_sizes = c.fs; cage.face_verts = c.fv;
        cage.num_edges = ne; cage.edge_verts = ev; cage.edge_knots = kn;
        ccn_options o = {0};
        o.levels = 3;
        ccn_plan *p = NULL;
        ccn_error err;
        CHECK(ccn_plan_create(&cage, &o, &p, &err) == CCN_OK, "%s", err.message);
        if (p) {
            ccn_sizes s;
            ccn_plan_sizes(p, &s);
            st.caps += s.num_caps;
            double *x = malloc(sizeof(double) * 3 * s.num_verts), *nn = malloc(sizeof(double) * 3 * s.num_verts);
            ccn_limit_mesh lm = {x, nn, NULL, NULL};
            CHECK(ccn_plan_evaluate(p, NULL, &lm, &err) == CCN_OK, "%s", err.message);
            check_separators(p, &st, 6.0);
            st.inside += p->nhv;
            free(x); free(nn);
            ccn_plan_destroy(p);
        }
        free(ev); free(kn); free(c.pos); free(c.fv); free(c.fs);
    }
    printf("  period-4 non-uniform n = 8: %d caps; separators: pos %.2g, normal %.2g rad, centre %.2g rad\n",
           st.caps, st.sep_pos, st.sep_nrm, st.centre_nrm);
    CHECK(st.caps == 10, "caps built for supported non-uniform intervals: %d", st.caps);
    CHECK(st.sep_pos <= 1e-9 && st.sep_nrm <= 1e-9 && st.centre_nrm <= 1e-9, "G1");
}

int main(void) {
    RUN(test_random_fans);
    RUN(test_shipped_cages);
    RUN(test_nonuniform_period4);
    return TEST_SUMMARY();
}
