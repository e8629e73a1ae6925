/* ccnurbs experiment maxima: refines the blending function of the EV and counts its face-local
 * maxima (SPEC A11). */
#include "exp.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#define EXP_ZMIN 1e-12     /* z <= this: outside the support */

/* Candidates (z > EXP_ZMIN) and the support statistics. */
static void support_stats(const double *pos, int32_t nv, unsigned char *flag, max_result *r) {
    for (int32_t v = 0; v < nv; v++) {
        double z = pos[3 * v + 2];
        r->nonfinite += !isfinite(z);
        flag[v] = z > EXP_ZMIN;
        if (!flag[v]) continue;
        r->support++;
        r->zsum += z;
        if (z > r->zmax) r->zmax = z;
    }
}

/* A face-local maximum is the unique argmax of every face around it: clears all other corners. */
static void clear_non_argmax(const double *pos, int32_t nf, const int32_t *fs, const int32_t *fv,
                             unsigned char *flag) {
    for (int32_t f = 0, k = 0; f < nf; k += fs[f], f++) {
        int32_t best = 0, tie = 0;
        for (int32_t a = 1; a < fs[f]; a++) {
            double za = pos[3 * fv[k + a] + 2], zb = pos[3 * fv[k + best] + 2];
            if (za > zb) { best = a; tie = 0; }
            else if (!(za < zb)) tie = 1; /* equal to the best so far (or NaN) */
        }
        for (int32_t a = 0; a < fs[f]; a++)
            if (a != best || tie) flag[fv[k + a]] = 0;
    }
}

/* Counts vertices whose z exceeds that of every vertex sharing a face with them (SPEC A11). */
static ccn_status count_maxima(const ccn_mesh *m, max_result *r, ccn_error *err) {
    ccn_mesh_info in;
    ccn_mesh_get_info(m, &in);
    double *pos = malloc(sizeof(double) * 3 * (size_t)in.num_verts);
    int32_t *fs = malloc(sizeof(int32_t) * (size_t)in.num_faces);
    int32_t *fv = malloc(sizeof(int32_t) * (size_t)in.num_face_verts);
    unsigned char *flag = malloc((size_t)in.num_verts);
    if (!pos || !fs || !fv || !flag) {
        free(pos); free(fs); free(fv); free(flag);
        return exp_fail_memory(err);
    }
    ccn_mesh_copy(m, pos, fs, fv, NULL, NULL);
    r->maxima = r->nonfinite = 0;
    r->support = 0;
    r->zsum = r->zmax = 0;
    r->fallbacks = in.num_ev_fallbacks;
    support_stats(pos, in.num_verts, flag, r);
    clear_non_argmax(pos, in.num_faces, fs, fv, flag);
    for (int32_t v = 0; v < in.num_verts; v++) {
        r->maxima += flag[v];
        if (flag[v] && r->show)
            printf("maximum: vertex %d x %.9g y %.9g z %.17g\n", (int)v, pos[3 * v],
                   pos[3 * v + 1], pos[3 * v + 2]);
    }
    free(pos); free(fs); free(fv); free(flag);
    return CCN_OK;
}

/* --start level1: the cage refined once (any scheme: NURSS), then z = 1 at the EV's vertex
 * point and 0 elsewhere (x, y kept); refining it applies the scheme's EV rules at every level. */
static ccn_status start_level1(const double *d, const fan_cage *c, ccn_mesh **out, ccn_error *err) {
    ccn_mesh *m0 = NULL;
    ccn_options o = {.scheme = CCN_SCHEME_NURSS, .threads = 1};
    ccn_status st = exp_fan_mesh(c, d, &m0, err);
    if (!st) st = ccn_refine(m0, 1, &o, out, err);
    ccn_mesh_destroy(m0);
    if (st) return st;
    ccn_mesh_info in;
    ccn_mesh_get_info(*out, &in);
    double *pos = malloc(sizeof(double) * 3 * (size_t)in.num_verts);
    if (!pos) return exp_fail_memory(err);
    ccn_mesh_copy(*out, pos, NULL, NULL, NULL, NULL);
    for (int32_t v = 0; v < in.num_verts; v++) pos[3 * v + 2] = 0.0;
    pos[3 * ((size_t)c->nf + (size_t)c->ne) + 2] = 1.0; /* vertex point of cage vertex 0 */
    st = ccn_mesh_set_positions(*out, pos, err);
    free(pos);
    return st;
}

static ccn_status refine_in_place(ccn_mesh **cur, int k, const exp_args *a, ccn_error *err) {
    ccn_mesh *next = NULL;
    ccn_options o = {.scheme = a->scheme, .threads = 1, .ev_polyhedron = a->poly}; /* cases run in parallel */
    ccn_status st = ccn_refine(*cur, k, &o, &next, err);
    ccn_mesh_destroy(*cur);
    *cur = next;
    return st;
}

/* Levels L+1 .. persist of a case with != 1 maximum at level L (cur is at level L). */
static ccn_status maxima_later(ccn_mesh **cur, const exp_args *a, max_result *r, ccn_error *err) {
    ccn_status st = CCN_OK;
    for (int l = a->levels; l < a->persist && !st && r->nlater < EXP_MAX_LATER; l++) {
        max_result t = {0};
        st = refine_in_place(cur, 1, a, err);
        if (!st) st = count_maxima(*cur, &t, err);
        if (!st) r->later[r->nlater++] = (signed char)(t.maxima > 127 ? 127 : t.maxima);
    }
    return st;
}

/* Refines the fan with intervals d a->levels levels and counts maxima at the last level, or at
 * every level 1..levels into per_level[] when per_level is not NULL; a case with != 1 maximum
 * is followed up to level a->persist. */
ccn_status exp_maxima_case(const fan_cage *c, const double *d, const exp_args *a,
                           int *per_level, max_result *r, ccn_error *err) {
    ccn_mesh *cur = NULL;
    ccn_status st = a->start ? start_level1(d, c, &cur, err) : exp_fan_mesh(c, d, &cur, err);
    int step = per_level ? 1 : a->levels;
    for (int l = 0; l < a->levels && !st; l += step) {
        st = refine_in_place(&cur, step, a, err);
        if (!st && (per_level || l + step == a->levels)) st = count_maxima(cur, r, err);
        if (!st && per_level) per_level[l] = r->maxima;
    }
    if (!st && r->maxima != 1) st = maxima_later(&cur, a, r, err);
    ccn_mesh_destroy(cur);
    return st;
}
