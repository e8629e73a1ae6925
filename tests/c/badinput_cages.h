/* Cage builders shared by test_badinput.c and test_badinput_plan.c (the bad-input table). */
#ifndef CCN_BADINPUT_CAGES_H
#define CCN_BADINPUT_CAGES_H
#include "ccnurbs.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

static inline ccn_cage cage_of(int32_t nv, int32_t nf, const double *pos, const int32_t *fs,
                               const int32_t *fv) {
    ccn_cage c = {0};
    c.num_verts = nv; c.num_faces = nf; c.positions = pos; c.face_sizes = fs; c.face_verts = fv;
    return c;
}

static const double PI = 3.14159265358979323846;

/* Open (nx x ny) quad grid; vertex (i, j) = j*(nx+1)+i, z a small bump. Arrays malloc'd. */
typedef struct { int32_t nv, nf; double *pos; int32_t *fs, *fv; } soup;

static inline soup grid(int32_t nx, int32_t ny) {
    soup s;
    s.nv = (nx + 1) * (ny + 1);
    s.nf = nx * ny;
    s.pos = malloc(sizeof(double) * 3 * (size_t)s.nv);
    s.fs = malloc(sizeof(int32_t) * (size_t)s.nf);
    s.fv = malloc(sizeof(int32_t) * 4 * (size_t)s.nf);
    for (int32_t j = 0; j <= ny; j++)
        for (int32_t i = 0; i <= nx; i++) {
            double *p = s.pos + 3 * ((size_t)j * (nx + 1) + i);
            p[0] = i; p[1] = j; p[2] = 0.1 * ((i * 7 + j * 3) % 5);
        }
    size_t f = 0;
    for (int32_t j = 0; j < ny; j++)
        for (int32_t i = 0; i < nx; i++, f++) {
            int32_t v = j * (nx + 1) + i;
            s.fs[f] = 4;
            s.fv[4 * f + 0] = v; s.fv[4 * f + 1] = v + 1;
            s.fv[4 * f + 2] = v + nx + 2; s.fv[4 * f + 3] = v + nx + 1;
        }
    return s;
}

/* Closed quad fan: interior vertex 0 of valence k, spokes 1..k, corners k+1..2k. */
static inline soup fan(int32_t k) {
    soup s;
    s.nv = 1 + 2 * k;
    s.nf = k;
    s.pos = malloc(sizeof(double) * 3 * (size_t)s.nv);
    s.fs = malloc(sizeof(int32_t) * (size_t)k);
    s.fv = malloc(sizeof(int32_t) * 4 * (size_t)k);
    s.pos[0] = s.pos[1] = 0; s.pos[2] = 0.5;
    for (int32_t i = 0; i < k; i++) {
        double a = 2 * PI * i / k, a2 = a + PI / k;
        double *p = s.pos + 3 * (1 + i), *q = s.pos + 3 * (1 + k + i);
        p[0] = cos(a); p[1] = sin(a); p[2] = 0;
        q[0] = 2 * cos(a2); q[1] = 2 * sin(a2); q[2] = 0;
        s.fs[i] = 4;
        s.fv[4 * i + 0] = 0; s.fv[4 * i + 1] = 1 + i;
        s.fv[4 * i + 2] = 1 + k + i; s.fv[4 * i + 3] = 1 + (i + 1) % k;
    }
    return s;
}

static inline void soup_free(soup *s) { free(s->pos); free(s->fs); free(s->fv); }

static inline ccn_cage soup_cage(const soup *s) {
    return cage_of(s->nv, s->nf, s->pos, s->fs, s->fv);
}

static const double SQ[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0.2, 0, 1, 0};
static const int32_t SQ_FS[1] = {4}, SQ_FV[4] = {0, 1, 2, 3};

#endif
