/* The closure of a star cage's centre hole in the CAD export, measured on the exported faces
 * (RESULTS.md, "The export's caps and fills beyond the κ range"): which closure the export
 * chose (bi-5 cap or fill faces: the faces of those kinds within 1 of the star's axis), the
 * largest |K| over it against the largest |K| of the exact pieces within twice its reach, and
 * the export's G1 figures. Gaussian curvature by its own Cox-de Boor evaluation and central
 * differences (25 x 25 samples per face, to 0.005 of its sides; poles relative to the hole's
 * centre so that tiny faces keep their digits), independent of the library's.
 *
 *
 *   cc -O2 -Icsrc/include tests/experiments/hole_curvature.c build/libccnurbs.a \
 *      -llapacke -llapack -lm -lpthread -o build/hole_curvature
 *   build/hole_curvature star.obj [FILL_LEVELS]
 * prints "cap|fill FACES kmin kmax ring_kmax ratio g1 fill_g1 ksign S hsign S jump J K[..]
 * ringK[..] H[..] ringH[..]": ksign (hsign) 1 where the ring keeps one sign of K (H) and the
 * hole takes the other (H's sign as each face's normal has it), jump the largest jump of K
 * across the joins of the hole's faces (sides that meet, K 0.002 inside either side at 7
 * points) over the hole's largest |K| (with HOLE_JUMPS set in the environment; else nan).
 * FILL_LEVELS: the export's --fill-levels (default 6). fill_force.patch makes the export close
 * every hole beyond the κ range with the cap (CCN_X_FORCE=c) or the fill (CCN_X_FORCE=f). */
#include "ccnurbs.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    int kind, p[2], n[2];
    double *t[2], *P, c[3];
} face;

typedef struct { face *f; int n, cap; } faces;

static int sink(void *u, const char *d, size_t l) { (void)u, (void)d, (void)l; return 0; }

static void grab(void *user, const ccn_export_face *e) {
    faces *F = user;
    if (F->n == F->cap) {
        F->cap = F->cap ? 2 * F->cap : 1024;
        F->f = realloc(F->f, sizeof *F->f * (size_t)F->cap);
    }
    face *g = &F->f[F->n++];
    g->kind = e->kind;
    for (int d = 0; d < 2; d++) {
        g->p[d] = e->degree[d], g->n[d] = e->num_poles[d];
        g->t[d] = malloc(sizeof(double) * (size_t)(g->n[d] + g->p[d] + 1));
        int k = 0;
        for (int i = 0; i < e->num_knots[d]; i++)
            for (int j = 0; j < e->mults[d][i] && k < g->n[d] + g->p[d] + 1; j++) g->t[d][k++] = e->knots[d][i];
        if (e->periodic[d]) g->kind = -1;
    }
    size_t np = (size_t)g->n[0] * g->n[1];
    g->P = malloc(sizeof(double) * 3 * np);
    memcpy(g->P, e->poles, sizeof(double) * 3 * np);
    g->c[0] = g->c[1] = g->c[2] = 0;
    for (size_t i = 0; i < np; i++)
        for (int k = 0; k < 3; k++) g->c[k] += g->P[3 * i + k] / (double)np;
}

/* The p + 1 basis functions non-zero at u (the NURBS Book A2.2) and their span. */
static int basis(const double *t, int p, int n, double u, double *N) {
    int s = p;
    for (int i = n - 1; i >= p; i--)
        if (t[i] <= u && t[i] < t[i + 1]) { s = i; break; }
    double left[32], right[32];
    N[0] = 1;
    for (int j = 1; j <= p; j++) {
        left[j] = u - t[s + 1 - j], right[j] = t[s + j] - u;
        double saved = 0;
        for (int r = 0; r < j; r++) {
            double tmp = N[r] / (right[r + 1] + left[j - r]);
            N[r] = saved + right[r + 1] * tmp;
            saved = left[j - r] * tmp;
        }
        N[j] = saved;
    }
    return s;
}

static void eval(const face *g, double u, double v, double *o) {
    double Nu[32], Nv[32];
    int su = basis(g->t[0], g->p[0], g->n[0], u, Nu), sv = basis(g->t[1], g->p[1], g->n[1], v, Nv);
    o[0] = o[1] = o[2] = 0;
    for (int a = 0; a <= g->p[0]; a++)
        for (int b = 0; b <= g->p[1]; b++) {
            const double *P = g->P + 3 * ((size_t)(su - g->p[0] + a) * g->n[1] + (sv - g->p[1] + b));
            for (int k = 0; k < 3; k++) o[k] += Nu[a] * Nv[b] * P[k];
        }
}

/* K and H of face g at (u, v) by central differences of steps hu, hv; its distance from the
 * origin into *d. 0 where the normal is undefined. */
static int curv(const face *g, double u, double v, double hu, double hv, double *K, double *H, double *d) {
    double p[3][3][3];
    for (int a = -1; a <= 1; a++)
        for (int b = -1; b <= 1; b++) eval(g, u + a * hu, v + b * hv, p[a + 1][b + 1]);
    *d = sqrt(p[1][1][0] * p[1][1][0] + p[1][1][1] * p[1][1][1] + p[1][1][2] * p[1][1][2]);
    double Su[3], Sv[3], Suu[3], Svv[3], Suv[3], n[3];
    for (int k = 0; k < 3; k++) {
        Su[k] = (p[2][1][k] - p[0][1][k]) / (2 * hu), Sv[k] = (p[1][2][k] - p[1][0][k]) / (2 * hv);
        Suu[k] = (p[2][1][k] - 2 * p[1][1][k] + p[0][1][k]) / (hu * hu);
        Svv[k] = (p[1][2][k] - 2 * p[1][1][k] + p[1][0][k]) / (hv * hv);
        Suv[k] = (p[2][2][k] - p[2][0][k] - p[0][2][k] + p[0][0][k]) / (4 * hu * hv);
    }
    n[0] = Su[1] * Sv[2] - Su[2] * Sv[1], n[1] = Su[2] * Sv[0] - Su[0] * Sv[2], n[2] = Su[0] * Sv[1] - Su[1] * Sv[0];
    double l = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]), E = 0, F = 0, G = 0, L = 0, M = 0, N = 0;
    if (!(l > 0)) return 0;
    for (int k = 0; k < 3; k++) {
        n[k] /= l;
        E += Su[k] * Su[k], F += Su[k] * Sv[k], G += Sv[k] * Sv[k];
        L += Suu[k] * n[k], M += Suv[k] * n[k], N += Svv[k] * n[k];
    }
    double den = E * G - F * F;
    *K = (L * N - M * M) / den;
    *H = (E * N - 2 * F * M + G * L) / (2 * den);
    return isfinite(*K) && isfinite(*H);
}

typedef struct { double kmax, kmin, kmaxs, hmin, hmax; } krange; /* kmax: largest |K|, kmaxs: largest K */

/* Largest |K| of face g at samples within [rmin, rmax) of the origin (rmax <= 0: all), its K
 * and H ranges into *r (orientation: H's sign as the face's normal has it). */
static double face_k(const face *g, double rmin, double rmax, krange *r) {
    double u0 = g->t[0][g->p[0]], u1 = g->t[0][g->n[0]], v0 = g->t[1][g->p[1]], v1 = g->t[1][g->n[1]];
    double hu = 1e-4 * (u1 - u0), hv = 1e-4 * (v1 - v0), km = 0;
    for (int i = 0; i <= 24; i++)
        for (int j = 0; j <= 24; j++) {
            double u = u0 + (u1 - u0) * (0.005 + 0.99 * i / 24), v = v0 + (v1 - v0) * (0.005 + 0.99 * j / 24), K, H, d;
            if (!curv(g, u, v, hu, hv, &K, &H, &d) || d < rmin || (rmax > 0 && d >= rmax)) continue;
            km = fmax(km, fabs(K));
            r->kmax = fmax(r->kmax, fabs(K)), r->kmin = fmin(r->kmin, K), r->kmaxs = fmax(r->kmaxs, K);
            r->hmin = fmin(r->hmin, H), r->hmax = fmax(r->hmax, H);
        }
    return km;
}

/* Point and K on side s of face g (0: v = v0, 1: v = v1, 2: u = u0, 3: u = u1) at x in [0, 1],
 * 0.002 of the face inside it. */
static int side_k(const face *g, int s, double x, double *P, double *K) {
    double u0 = g->t[0][g->p[0]], u1 = g->t[0][g->n[0]], v0 = g->t[1][g->p[1]], v1 = g->t[1][g->n[1]];
    double hu = 1e-4 * (u1 - u0), hv = 1e-4 * (v1 - v0), in = 0.002, H, d;
    double u = s < 2 ? u0 + (u1 - u0) * x : s == 2 ? u0 + in * (u1 - u0) : u1 - in * (u1 - u0);
    double v = s >= 2 ? v0 + (v1 - v0) * x : s == 0 ? v0 + in * (v1 - v0) : v1 - in * (v1 - v0);
    double us = s < 2 ? u : s == 2 ? u0 : u1, vs = s >= 2 ? v : s == 0 ? v0 : v1;
    eval(g, us, vs, P);
    return curv(g, u, v, hu, hv, K, &H, &d);
}

/* The largest jump of K across the joins of the hole's faces (with each other and with the
 * faces around): sides whose midpoints and ends meet, K just inside either side at 7 points. */
static double hole_jumps(const faces *F, const char *hole) {
    double worst = 0;
    for (int a = 0; a < F->n; a++) {
        if (!hole[a]) continue;
        for (int b = 0; b < F->n; b++) {
            if (b == a || (hole[b] && b < a) || F->f[b].kind < 0) continue;
            for (int sa = 0; sa < 4; sa++)
                for (int sb = 0; sb < 4; sb++) {
                    double pa[3], pb[3], K;
                    side_k(&F->f[a], sa, 0.5, pa, &K);
                    side_k(&F->f[b], sb, 0.5, pb, &K);
                    double gap = fabs(pa[0] - pb[0]) + fabs(pa[1] - pb[1]) + fabs(pa[2] - pb[2]);
                    double size = 0, e0[3], e1[3];
                    side_k(&F->f[a], sa, 0, e0, &K);
                    side_k(&F->f[a], sa, 1, e1, &K);
                    for (int k = 0; k < 3; k++) size = fmax(size, fabs(e1[k] - e0[k]));
                    if (!(gap <= 1e-7 * size)) continue;
                    double f0[3];
                    side_k(&F->f[b], sb, 0, f0, &K);
                    int rev = fabs(f0[0] - e0[0]) + fabs(f0[1] - e0[1]) + fabs(f0[2] - e0[2]) > 1e-7 * size;
                    for (int q = 1; q <= 7; q++) {
                        double x = q / 8.0, Ka, Kb;
                        if (side_k(&F->f[a], sa, x, pa, &Ka) && side_k(&F->f[b], sb, rev ? 1 - x : x, pb, &Kb))
                            worst = fmax(worst, fabs(Ka - Kb));
                    }
                }
        }
    }
    return worst;
}

int main(int argc, char **argv) {
    if (argc < 2) { fprintf(stderr, "usage: hole_curvature star.obj\n"); return 2; }
    FILE *fp = fopen(argv[1], "rb");
    if (!fp) { fprintf(stderr, "cannot open %s\n", argv[1]); return 2; }
    fseek(fp, 0, SEEK_END);
    long len = ftell(fp);
    fseek(fp, 0, SEEK_SET);
    char *text = malloc((size_t)len + 1);
    if (fread(text, 1, (size_t)len, fp) != (size_t)len) return 2;
    fclose(fp);
    ccn_obj *obj;
    ccn_cage cage;
    ccn_plan *plan;
    ccn_error err;
    ccn_options o = {0};
    if (ccn_obj_parse(text, (size_t)len, &obj, &err) || ccn_obj_get_cage(obj, &cage) || ccn_plan_create(&cage, &o, &plan, &err)) {
        fprintf(stderr, "%s\n", err.message);
        return 2;
    }
    ccn_plan_stats st;
    ccn_plan_get_stats(plan, &st);
    while (st.num_caps_deferred > 0) { /* as ccnurbs export: the caps exist above the cap level */
        o.levels = st.levels + 1;
        ccn_plan_destroy(plan);
        if (ccn_plan_create(&cage, &o, &plan, &err)) { fprintf(stderr, "%s\n", err.message); return 2; }
        ccn_plan_get_stats(plan, &st);
    }
    faces F = {0};
    ccn_export_options eo = {0};
    eo.face_fn = grab, eo.face_user = &F;
    if (argc > 2) eo.fill_levels = atoi(argv[2]);
    ccn_export_info info;
    if (ccn_plan_export(plan, NULL, &eo, sink, NULL, &info, &err)) { fprintf(stderr, "%s\n", err.message); return 2; }
    /* the hole: bi-5 or fill faces near the axis; its centre, then everything relative to it */
    char *hole = calloc((size_t)F.n + 1, 1);
    double c[3] = {0, 0, 0};
    int cnt = 0, kind = -1;
    for (int i = 0; i < F.n; i++) {
        face *g = &F.f[i];
        if ((g->kind != CCN_EXPORT_FACE_BI5 && g->kind != CCN_EXPORT_FACE_FILL) || hypot(g->c[0], g->c[1]) > 1.0) continue;
        hole[i] = 1, cnt++, kind = g->kind;
        for (int k = 0; k < 3; k++) c[k] += g->c[k];
    }
    if (!cnt) { printf("none\n"); return 0; }
    for (int i = 0; i < F.n; i++) {
        face *g = &F.f[i];
        for (size_t q = 0; q < (size_t)g->n[0] * g->n[1]; q++)
            for (int k = 0; k < 3; k++) g->P[3 * q + k] -= c[k] / cnt;
    }
    double r0 = 0, kc = 0, kr = 0;
    krange rh = {0, INFINITY, -INFINITY, INFINITY, -INFINITY}, rr = rh;
    for (int i = 0; i < F.n; i++)
        if (hole[i])
            for (size_t q = 0; q < (size_t)F.f[i].n[0] * F.f[i].n[1]; q++) {
                const double *P = F.f[i].P + 3 * q;
                r0 = fmax(r0, sqrt(P[0] * P[0] + P[1] * P[1] + P[2] * P[2]));
            }
    for (int i = 0; i < F.n; i++)
        if (hole[i]) kc = fmax(kc, face_k(&F.f[i], 0, 0, &rh));
    for (int i = 0; i < F.n; i++)
        if (F.f[i].kind == CCN_EXPORT_FACE_REFINED) kr = fmax(kr, face_k(&F.f[i], r0, 2 * r0, &rr));
    double jump = getenv("HOLE_JUMPS") ? hole_jumps(&F, hole) : NAN;
    /* a sign the ring keeps and the hole does not */
    int ksign = (rr.kmin >= 0 && rh.kmin < 0) || (rr.kmaxs <= 0 && rh.kmaxs > 0);
    int hsign = (rr.hmin >= 0 && rh.hmin < 0) || (rr.hmax <= 0 && rh.hmax > 0);
    printf("%s %d %.3g %.3g %.3g %.2f %.2e %.2e ksign %d hsign %d jump %.2f K[%.3g,%.3g] ringK[%.3g,%.3g] H[%.3g,%.3g] ringH[%.3g,%.3g]\n",
           kind == CCN_EXPORT_FACE_BI5 ? "cap" : "fill", cnt, rh.kmin, kc, kr, kr > 0 ? kc / kr : 0.0,
           info.max_g1_deviation, info.max_fill_g1_deviation, ksign, hsign, kc > 0 ? jump / kc : 0.0,
           rh.kmin, rh.kmaxs, rr.kmin, rr.kmaxs, rh.hmin, rh.hmax, rr.hmin, rr.hmax);
    return 0;
}
