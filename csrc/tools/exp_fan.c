/* ccnurbs experiment: the random cases and the G-ring fan cage (cmd_experiment.c's header
 * comment describes the cage and its numbering). */
#include "exp.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- random cases ------------------------------------------------------------------ */

static uint64_t mix64(uint64_t z) {
    z += 0x9E3779B97F4A7C15ull;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/* Valence and spoke intervals of case offset + idx: a function of (seed, offset + idx) only. */
int exp_case_setup(const exp_args *a, long idx, double *d) {
    if (a->nknots) {
        memcpy(d, a->knots, sizeof(double) * (size_t)a->nknots);
        return a->nknots;
    }
    idx += a->offset;
    int n = a->val[idx % a->nval];
    uint64_t st = mix64(mix64(a->seed) ^ (uint64_t)idx);
    for (int s = 0; s < n; s++) {
        st = mix64(st);
        double u = (double)(st >> 11) * (1.0 / 9007199254740992.0);
        d[s] = a->dist_log ? exp(log(a->lo) * (1.0 - u)) : a->lo + (1.0 - a->lo) * u;
    }
    return n;
}

int exp_valence_slot(const exp_args *a, int n) {
    if (a->nknots) return 0;
    for (int i = 0; i < a->nval; i++)
        if (a->val[i] == n) return i;
    return -1;
}

/* ---- the G-ring fan cage ------------------------------------------------------------ */

int32_t exp_fan_vid(int n, int G, int s, int i, int j) {
    s %= n;
    if (i == 0) return j == 0 ? 0 : exp_fan_vid(n, G, s + 1, j, 0);
    return 1 + (int32_t)s * G * (G + 1) + (int32_t)(i - 1) * (G + 1) + j;
}

void exp_fan_free(fan_cage *c) {
    free(c->pos); free(c->fsize); free(c->fverts); free(c->everts); free(c->edir);
    memset(c, 0, sizeof *c);
}

static void fan_positions(fan_cage *c) {
    int n = c->n, G = c->G;
    memset(c->pos, 0, sizeof(double) * 3 * (size_t)c->nv);
    c->pos[2] = 1.0;
    for (int s = 0; s < n; s++) {
        double a0 = 2 * EXP_PI * s / n, a1 = 2 * EXP_PI * (s + 1) / n;
        for (int i = 1; i <= G; i++)
            for (int j = 0; j <= G; j++) {
                double *p = c->pos + 3 * (size_t)exp_fan_vid(n, G, s, i, j);
                p[0] = i * cos(a0) + j * cos(a1);
                p[1] = i * sin(a0) + j * sin(a1);
            }
    }
}

static void fan_topology(fan_cage *c) {
    int n = c->n, G = c->G;
    int32_t f = 0, e = 0;
    for (int s = 0; s < n; s++) {
        for (int i = 0; i < G; i++)
            for (int j = 0; j < G; j++, f++) {
                int32_t *q = c->fverts + 4 * (size_t)f;
                c->fsize[f] = 4;
                q[0] = exp_fan_vid(n, G, s, i, j);
                q[1] = exp_fan_vid(n, G, s, i + 1, j);
                q[2] = exp_fan_vid(n, G, s, i + 1, j + 1);
                q[3] = exp_fan_vid(n, G, s, i, j + 1);
            }
        for (int j = 0; j <= G; j++) /* parallel to spoke s */
            for (int i = 0; i < G; i++, e++) {
                c->everts[2 * e] = exp_fan_vid(n, G, s, i, j);
                c->everts[2 * e + 1] = exp_fan_vid(n, G, s, i + 1, j);
                c->edir[e] = s;
            }
        for (int i = 1; i <= G; i++) /* parallel to spoke s+1 */
            for (int j = 0; j < G; j++, e++) {
                c->everts[2 * e] = exp_fan_vid(n, G, s, i, j);
                c->everts[2 * e + 1] = exp_fan_vid(n, G, s, i, j + 1);
                c->edir[e] = (s + 1) % n;
            }
    }
}

int exp_fan_build(fan_cage *c, int n, int G) {
    memset(c, 0, sizeof *c);
    c->n = n;
    c->G = G;
    c->nv = 1 + n * G * (G + 1);
    c->nf = n * G * G;
    c->ne = n * (2 * G * G + G);
    c->pos = malloc(sizeof(double) * 3 * (size_t)c->nv);
    c->fsize = malloc(sizeof(int32_t) * (size_t)c->nf);
    c->fverts = malloc(sizeof(int32_t) * 4 * (size_t)c->nf);
    c->everts = malloc(sizeof(int32_t) * 2 * (size_t)c->ne);
    c->edir = malloc(sizeof(int32_t) * (size_t)c->ne);
    if (!c->pos || !c->fsize || !c->fverts || !c->everts || !c->edir) {
        exp_fan_free(c);
        return -1;
    }
    fan_positions(c);
    fan_topology(c);
    return 0;
}

/* The cage with spoke intervals d as a mesh. */
ccn_status exp_fan_mesh(const fan_cage *c, const double *d, ccn_mesh **out, ccn_error *err) {
    double *k = malloc(sizeof(double) * (size_t)c->ne);
    if (!k) {
        err->status = CCN_ERR_MEMORY;
        snprintf(err->message, sizeof err->message, "out of memory");
        return CCN_ERR_MEMORY;
    }
    for (int32_t e = 0; e < c->ne; e++) k[e] = d[c->edir[e]];
    ccn_cage cg = {.num_verts = c->nv, .num_faces = c->nf, .num_edges = c->ne,
                   .positions = c->pos, .face_sizes = c->fsize, .face_verts = c->fverts,
                   .edge_verts = c->everts, .edge_knots = k};
    ccn_status st = ccn_mesh_create(&cg, out, err);
    free(k);
    return st;
}

ccn_status exp_fail_memory(ccn_error *err) {
    err->status = CCN_ERR_MEMORY;
    err->element_kind = CCN_ELEM_NONE;
    err->element = -1;
    snprintf(err->message, sizeof err->message, "out of memory");
    return CCN_ERR_MEMORY;
}
