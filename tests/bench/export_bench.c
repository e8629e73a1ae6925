/* `make bench`: size and time of ccn_plan_export for one cage: STEP and IGES,
 * packed and unpacked, into a counting sink (no disk), min over repeats; the time includes
 * the plan's evaluation that ccn_plan_export does first (printed apart). */
#include "ccnurbs.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double now(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec + 1e-9 * t.tv_nsec;
}

static int count(void *user, const char *data, size_t len) {
    (void)data;
    *(size_t *)user += len;
    return 0;
}

int main(int argc, char **argv) {
    if (argc < 2) { fprintf(stderr, "usage: export_bench in.obj [repeats]\n"); return 2; }
    int reps = argc > 2 ? atoi(argv[2]) : 3;
    FILE *f = fopen(argv[1], "rb");
    if (!f) { fprintf(stderr, "cannot open %s\n", argv[1]); return 2; }
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *text = malloc((size_t)n + 1);
    if (!text || fread(text, 1, (size_t)n, f) != (size_t)n) { fclose(f); return 2; }
    fclose(f);
    ccn_obj *obj;
    ccn_cage cage;
    ccn_plan *plan;
    ccn_error err;
    ccn_options o = {0};
    if (ccn_obj_parse(text, (size_t)n, &obj, &err) || ccn_obj_get_cage(obj, &cage) ||
        ccn_plan_create(&cage, &o, &plan, &err)) { fprintf(stderr, "%s\n", err.message); return 2; }
    ccn_sizes sz;
    ccn_plan_get_sizes(plan, &sz);
    ccn_plan_stats sz_st;
    ccn_plan_get_stats(plan, &sz_st);
    while (sz_st.num_caps_deferred > 0) { /* the caps exist only above the cap level */
        o.levels = sz_st.levels + 1;
        ccn_plan_destroy(plan);
        if (ccn_plan_create(&cage, &o, &plan, &err)) { fprintf(stderr, "%s\n", err.message); return 2; }
        ccn_plan_get_sizes(plan, &sz);
        ccn_plan_get_stats(plan, &sz_st);
    }
    double *pos = malloc(sizeof(double) * 3 * (size_t)sz.num_verts), tev = 1e30;
    ccn_limit_mesh lm = {.positions = pos};
    for (int r = 0; r < reps; r++) {
        double t0 = now();
        if (ccn_plan_evaluate(plan, NULL, &lm, &err)) { fprintf(stderr, "%s\n", err.message); return 2; }
        double t = now() - t0;
        tev = t < tev ? t : tev;
    }
    for (int unpacked = 0; unpacked < 2; unpacked++)
        for (int fmt = 0; fmt < 2; fmt++) {
            ccn_export_options eo;
            memset(&eo, 0, sizeof eo);
            eo.format = fmt;
            eo.flags = unpacked ? CCN_EXPORT_UNPACKED : 0;
            ccn_export_info info;
            double best = 1e30;
            size_t bytes = 0;
            err.status = CCN_OK;
            for (int r = 0; r < reps; r++) {
                bytes = 0;
                double t0 = now();
                if (ccn_plan_export(plan, NULL, &eo, count, &bytes, &info, &err)) break;
                double t = now() - t0;
                best = t < best ? t : best;
            }
            if (err.status == CCN_ERR_ARGUMENT) { /* a format limit: said, the other rows go on */
                printf("export %s %s %s: refused: %s\n", argv[1], fmt ? "IGES" : "STEP", unpacked ? "unpacked" : "packed",
                       err.message);
                continue;
            }
            if (err.status != CCN_OK) { fprintf(stderr, "%s\n", err.message); return 2; }
            printf("export %s %s %s: cage %d faces -> %d faces (%d packs, %d bicubic, %d bi-5, %d refined, %d fill), "
                   "%.2f MB in %.3f s (evaluate %.3f s of it), G1 %.1e rad\n", argv[1], fmt ? "IGES" : "STEP",
                   unpacked ? "unpacked" : "packed", cage.num_faces, (int)info.num_faces, (int)info.num_packs,
                   (int)info.num_bicubic, (int)info.num_bi5, (int)info.num_refined, (int)info.num_fill_faces,
                   (double)bytes / 1e6, best, tev, info.max_g1_deviation);
        }
    free(pos);
    free(text);
    ccn_plan_destroy(plan);
    ccn_obj_destroy(obj);
    return 0;
}
