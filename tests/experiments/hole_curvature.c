/* The closure of a star cage's centre hole in the CAD export, measured on the exported faces
 * (RESULTS.md, "The export's caps and fills beyond the κ range"): which closure the export
 * chose (bi-5 cap or fill faces: the faces of those kinds within 1 of the star's axis), the
 * largest |K| over it against the largest |K| of the exact pieces within twice its reach, and
 * the export's G1 figures. Gaussian curvature by its own Cox-de Boor evaluation and central
 * differences (25 x 25 samples per face, to 0.005 of its sides; poles relative to the hole's
 * centre so that tiny faces keep their digits), independent of the library's.
 *
 *   cc -O2 -Icsrc/include tests/experiments/hole_curvature.c build/libccnurbs.a \
 *      -llapacke -llapack -lm -lpthread -o build/hole_curvature
 *   build/hole_curvature star.obj
 * prints "cap|fill FACES kmin kmax ring_kmax ratio g1 fill_g1". */
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

/* Largest |K| of face g at samples within [rmin, rmax) of the origin (rmax <= 0: all); the
 * smallest K into *kmin. */
static double face_k(const face *g, double rmin, double rmax, double *kmin) {
    double u0 = g->t[0][g->p[0]], u1 = g->t[0][g->n[0]], v0 = g->t[1][g->p[1]], v1 = g->t[1][g->n[1]];
    double hu = 1e-4 * (u1 - u0), hv = 1e-4 * (v1 - v0), km = 0;
    for (int i = 0; i <= 24; i++)
        for (int j = 0; j <= 24; j++) {
            double u = u0 + (u1 - u0) * (0.005 + 0.99 * i / 24), v = v0 + (v1 - v0) * (0.005 + 0.99 * j / 24);
            double p[3][3][3];
            for (int a = -1; a <= 1; a++)
                for (int b = -1; b <= 1; b++) eval(g, u + a * hu, v + b * hv, p[a + 1][b + 1]);
            double d = sqrt(p[1][1][0] * p[1][1][0] + p[1][1][1] * p[1][1][1] + p[1][1][2] * p[1][1][2]);
            if (d < rmin || (rmax > 0 && d >= rmax)) continue;
            double Su[3], Sv[3], Suu[3], Svv[3], Suv[3], n[3];
            for (int k = 0; k < 3; k++) {
                Su[k] = (p[2][1][k] - p[0][1][k]) / (2 * hu), Sv[k] = (p[1][2][k] - p[1][0][k]) / (2 * hv);
                Suu[k] = (p[2][1][k] - 2 * p[1][1][k] + p[0][1][k]) / (hu * hu);
                Svv[k] = (p[1][2][k] - 2 * p[1][1][k] + p[1][0][k]) / (hv * hv);
                Suv[k] = (p[2][2][k] - p[2][0][k] - p[0][2][k] + p[0][0][k]) / (4 * hu * hv);
            }
            n[0] = Su[1] * Sv[2] - Su[2] * Sv[1], n[1] = Su[2] * Sv[0] - Su[0] * Sv[2], n[2] = Su[0] * Sv[1] - Su[1] * Sv[0];
            double l = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]), E = 0, F = 0, G = 0, L = 0, M = 0, N = 0;
            if (!(l > 0)) continue;
            for (int k = 0; k < 3; k++) {
                n[k] /= l;
                E += Su[k] * Su[k], F += Su[k] * Sv[k], G += Sv[k] * Sv[k];
                L += Suu[k] * n[k], M += Suv[k] * n[k], N += Svv[k] * n[k];
            }
            double K = (L * N - M * M) / (E * G - F * F);
            if (!isfinite(K)) continue;
            km = fmax(km, fabs(K));
            *kmin = fmin(*kmin, K);
        }
    return km;
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
    double r0 = 0, kc = 0, kcmin = INFINITY, kr = 0, krmin = INFINITY;
    for (int i = 0; i < F.n; i++)
        if (hole[i])
            for (size_t q = 0; q < (size_t)F.f[i].n[0] * F.f[i].n[1]; q++) {
                const double *P = F.f[i].P + 3 * q;
                r0 = fmax(r0, sqrt(P[0] * P[0] + P[1] * P[1] + P[2] * P[2]));
            }
    for (int i = 0; i < F.n; i++)
        if (hole[i]) kc = fmax(kc, face_k(&F.f[i], 0, 0, &kcmin));
    for (int i = 0; i < F.n; i++)
        if (F.f[i].kind == CCN_EXPORT_FACE_REFINED) kr = fmax(kr, face_k(&F.f[i], r0, 2 * r0, &krmin));
    printf("%s %d %.3g %.3g %.3g %.2f %.2e %.2e\n", kind == CCN_EXPORT_FACE_BI5 ? "cap" : "fill", cnt, kcmin, kc, kr,
           kr > 0 ? kc / kr : 0.0, info.max_g1_deviation, info.max_fill_g1_deviation);
    return 0;
}
