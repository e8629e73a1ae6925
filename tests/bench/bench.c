/* Benchmark of the C library: plan creation (topology/interval change) and evaluation
 * (position-only change) for one cage; prints seconds (min over repeats). With the cage's UV
 * map (`vt`) also: the plan with one UV channel against the plan without (creation time,
 * evaluation of positions + UVs against positions alone, heap bytes the plan holds). */
#include "ccnurbs.h"
#include "../c/plan_with.h"

#include <malloc.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <sys/resource.h>

static double now(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec + 1e-9 * t.tv_nsec;
}

/* Heap bytes in use (glibc: small-chunk arena + mmapped chunks). */
static double heap_bytes(void) {
    struct mallinfo2 mi = mallinfo2();
    return (double)mi.uordblks + (double)mi.hblkhd;
}

static char *slurp(const char *path, size_t *len) {
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *b = malloc((size_t)n + 1);
    if (b && fread(b, 1, (size_t)n, f) != (size_t)n) { free(b); b = NULL; }
    fclose(f);
    if (b) { b[n] = 0; *len = (size_t)n; }
    return b;
}

/* The shortest of reps evaluations, each after a move of cage vertex 0; -1 on an error. */
static double min_evaluate(ccn_plan *plan, double *cp, ccn_limit_mesh *lm, int reps) {
    double best = 1e30;
    ccn_error err;
    for (int r = 0; r < reps; r++) {
        cp[0] += 1e-3;
        double t0 = now();
        if (ccn_plan_evaluate(plan, cp, lm, &err)) { fprintf(stderr, "%s\n", err.message); return -1; }
        double t1 = now() - t0;
        best = t1 < best ? t1 : best;
    }
    return best;
}

int main(int argc, char **argv) {
    if (argc < 3) { fprintf(stderr, "usage: bench in.obj levels [cap: bi5|refine] [repeats] [ev_polyhedron] [threads] [cached]\n"); return 2; }
    int levels = atoi(argv[2]), reps = argc > 4 ? atoi(argv[4]) : 5;
    ccn_options o = {0};
    o.levels = levels;
    o.ev_polyhedron = argc > 5 ? atoi(argv[5]) : CCN_POLY_SELECT;
    o.cap = argc > 3 && strcmp(argv[3], "refine") == 0 ? CCN_CAP_REFINE : CCN_CAP_GUIDED_BI5;
    o.threads = argc > 6 ? atoi(argv[6]) : 0;
    size_t len;
    char *text = slurp(argv[1], &len);
    ccn_obj *obj;
    ccn_error err;
    if (!text || ccn_obj_parse(text, len, &obj, &err)) { fprintf(stderr, "cannot read %s\n", argv[1]); return 2; }
    ccn_cage cage;
    ccn_obj_get_cage(obj, &cage);
    double tplan = 1e30, teval = 1e30, tfirst = 0;
    ccn_plan *plan = NULL;
    ccn_cache *cache = NULL; /* "cached": one ccn_cache for every plan (a session's rebuilds) */
    if (argc > 7 && strcmp(argv[7], "cached") == 0 && ccn_cache_create(&cache, &err)) return 2;
    for (int r = 0; r < reps; r++) {
        double t0 = now();
        if (plan_cached(&cage, &o, cache, &plan, &err)) { fprintf(stderr, "%s\n", err.message); return 2; }
        double t1 = now() - t0;
        if (r == 0) tfirst = t1;
        tplan = t1 < tplan ? t1 : tplan;
        if (r + 1 < reps) ccn_plan_destroy(plan);
    }
    ccn_sizes s;
    ccn_plan_get_sizes(plan, &s);
    ccn_plan_stats s_st;
    ccn_plan_get_stats(plan, &s_st);
    double *pos = malloc(sizeof(double) * 3 * s.num_verts), *nrm = malloc(sizeof(double) * 3 * s.num_verts);
    double *cp = malloc(sizeof(double) * 3 * cage.num_verts);
    memcpy(cp, cage.positions, sizeof(double) * 3 * cage.num_verts);
    ccn_limit_mesh lm = {.positions = pos, .normals = nrm};
    teval = min_evaluate(plan, cp, &lm, 3 * reps);
    /* the same with principal curvatures (the add-on's analysis) */
    double *curv = malloc(sizeof(double) * 2 * s.num_verts);
    ccn_limit_mesh lmc = {.positions = pos, .normals = nrm, .curvatures = curv};
    double tcurv = min_evaluate(plan, cp, &lmc, 3 * reps);
    free(curv);
    if (teval < 0 || tcurv < 0) return 2;
    struct rusage ru; /* one plan alive at a time so far: its peak, with the cage and outputs */
    getrusage(RUSAGE_SELF, &ru);
    double tref = 1e30;
    ccn_mesh *cm = NULL;
    if (ccn_mesh_create(&cage, &cm, &err)) { fprintf(stderr, "%s\n", err.message); return 2; }
    for (int r = 0; r < reps; r++) {
        ccn_mesh *out = NULL;
        double t0 = now();
        if (ccn_refine(cm, levels, &o, &out, &err)) { fprintf(stderr, "%s\n", err.message); return 2; }
        double t1 = now() - t0;
        tref = t1 < tref ? t1 : tref;
        ccn_mesh_destroy(out);
    }
    ccn_mesh_destroy(cm);
    printf("ccn curvature %s L%d: evaluate %.4f s, with curvature %.4f s (%.2fx)\n", argv[1], levels,
           teval, tcurv, tcurv / teval);
    printf("ccn %s L%d %s: cage %d faces -> %d verts; plan %.4f s, evaluate %.4f s, refine %.4f s; "
           "caps %d, cap fallbacks %d, EVs verified %d, outside G1 %d; peak RSS %ld kB; first plan %.4f s%s\n",
           argv[1], levels, o.cap == CCN_CAP_REFINE ? "refine" : "bi5", cage.num_faces, s.num_verts,
           tplan, teval, tref, s_st.num_caps, s_st.num_cap_fallbacks, s_st.num_ev_verified, s_st.num_ev_outside_g1, ru.ru_maxrss, tfirst,
           cache ? " (one ccn_cache)" : "");
    /* an interval edit: one ring's interval changed (the cage's first edge, alternately 3 and
     * 1.5 times its interval), the plan made again and evaluated (the add-on's rebuild), by a
     * new plan and by ccn_plan_create with options.previous from the plan before */
    {
        int32_t ne = cage.num_edges > 0 ? cage.num_edges : 1;
        int32_t *ev = malloc(sizeof(int32_t) * 2 * (size_t)ne);
        double *ek = malloc(sizeof(double) * (size_t)ne);
        if (cage.num_edges > 0) {
            memcpy(ev, cage.edge_verts, sizeof(int32_t) * 2 * (size_t)ne);
            for (int32_t i = 0; i < ne; i++) ek[i] = cage.edge_knots ? cage.edge_knots[i] : 1.0;
        } else {
            ev[0] = cage.face_verts[0]; ev[1] = cage.face_verts[1]; ek[0] = 1.0;
        }
        ccn_cage ec = cage;
        ec.num_edges = ne; ec.edge_verts = ev; ec.edge_knots = ek;
        double base = ek[0] > 0 ? ek[0] : 1.0, tnew = 1e30, trec = 1e30, tchg = 1e30;
        /* lm holds the plan before's output (the same positions): way 2 keeps what the edit
         * did not change (ccn_plan_evaluate_changed), as the add-on does */
        for (int way = 0; way < 3; way++)
            for (int r = 0; r < 2 * reps + 1; r++) {
                ek[0] = base * (r % 2 ? 3.0 : 1.5);
                ccn_plan *q = NULL;
                double t0 = now();
                ccn_status st = way ? plan_recreate(plan, &ec, &o, cache, &q, &err)
                                    : plan_cached(&ec, &o, cache, &q, &err);
                if (st || (way == 2 ? ccn_plan_evaluate_changed(q, NULL, &lm, &err)
                                    : ccn_plan_evaluate(q, NULL, &lm, &err))) {
                    fprintf(stderr, "%s\n", err.message);
                    return 2;
                }
                double t1 = now() - t0;
                if (!way) ccn_plan_destroy(plan); /* ccn_plan_create with options.previous consumed it */
                plan = q;
                if (r == 0) continue; /* the first: from the cage's own intervals */
                double *t = way == 2 ? &tchg : way ? &trec : &tnew;
                *t = t1 < *t ? t1 : *t;
            }
        printf("ccn edit %s L%d: one ring's interval changed, plan + evaluate: new plan %.4f s, "
               "recreated %.4f s, recreated + changed values only %.4f s\n", argv[1], levels, tnew, trec, tchg);
        free(ev); free(ek);
    }
    ccn_plan_destroy(plan);
    ccn_cache_destroy(cache);
    ccn_fvar_channel uv;
    ccn_obj_get_fvar(obj, &uv);
    const char *mode = getenv("CCN_BENCH_FVAR"); /* ccn_fvar_linear, default CORNERS_ONLY */
    uv.linear = mode ? atoi(mode) : CCN_FVAR_LINEAR_CORNERS_ONLY;
    if (uv.num_values) { /* the same plan with one UV channel */
        double tp0 = 1e30, tp1 = 1e30, te0 = 1e30, te1 = 1e30, m0 = 0, m1 = 0;
        ccn_fvar_sizes fs = {0};
        double *uvo = NULL;
        for (int r = 0; r < reps; r++) {
            double h0 = heap_bytes(), t0 = now();
            ccn_plan *p = NULL;
            int32_t ch;
            if (ccn_plan_create(&cage, &o, &p, &err)) { fprintf(stderr, "%s\n", err.message); return 2; }
            double t1 = now(), h1 = heap_bytes();
            if (ccn_plan_add_fvar(p, &uv, &ch, &err)) { fprintf(stderr, "%s\n", err.message); return 2; }
            double t2 = now(), h2 = heap_bytes();
            tp0 = t1 - t0 < tp0 ? t1 - t0 : tp0;
            tp1 = t2 - t0 < tp1 ? t2 - t0 : tp1;
            m0 = h1 - h0;
            m1 = h2 - h0;
            ccn_plan_get_fvar_sizes(p, ch, &fs);
            if (!uvo) uvo = malloc(sizeof(double) * (size_t)fs.width * (size_t)fs.num_values);
            for (int k = 0; k < 3; k++) {
                cp[0] += 1e-3;
                double e0 = now();
                if (ccn_plan_evaluate(p, cp, &lm, &err)) { fprintf(stderr, "%s\n", err.message); return 2; }
                double e1 = now();
                if (ccn_plan_evaluate_fvar(p, ch, NULL, uvo, NULL, &err)) { fprintf(stderr, "%s\n", err.message); return 2; }
                double e2 = now();
                te0 = e1 - e0 < te0 ? e1 - e0 : te0;
                te1 = e2 - e0 < te1 ? e2 - e0 : te1;
            }
            ccn_plan_destroy(p);
        }
        printf("ccn uv %s L%d: %d values, %d seam edges -> %d limit values; plan %.4f s, with uv %.4f s; "
               "evaluate %.4f s, with uv %.4f s; memory %.1f MB, with uv %.1f MB\n",
               argv[1], levels, (int)uv.num_values, (int)fs.num_seam_edges, (int)fs.num_values, tp0, tp1,
               te0, te1, m0 / 1e6, m1 / 1e6);
        free(uvo);
    }
    ccn_obj_destroy(obj);
    free(text); free(pos); free(nrm); free(cp);
    return 0;
}
