/* The builder of a face-varying channel's composed stencils (internal; surface/fvar_compose.c
 * builds it, surface/fvar_probe.c probes it). */
#ifndef CCN_SURFACE_FVAR_BUILDER_H
#define CCN_SURFACE_FVAR_BUILDER_H

#include "refine/fvar.h"
#include "surface/fvar_direct.h"

/* The points of one level that the probes compute: those the composed outputs read. */
typedef struct { int32_t nf, ne, nv, *f, *e, *v; } ccn__fvar_probe_list;

/* The channel's refinement, kept while its stencils are composed (and after, for a channel
 * evaluated through its levels: ccn__fvar_stencils.levels). */
typedef struct ccn__fvar_builder {
    int32_t L;
    ccn__fvar_level *lev;     /* L + 1 levels */
    ccn__level *prep;         /* L prepared levels */
    ccn__level sub;           /* level L -> L+1 around near[] (has_sub) */
    int has_sub, bilinear;
    int32_t nnear, *near;
    int32_t *st_start, *st_v; /* CSR per level-L value vertex; index >= nvL: an (L+1) point */
    double *st_w;
    double *posS;             /* level-(L+1) points, 3 * (nf + ne + nv) of level L */
    int32_t *value_of;        /* level-0 value vertex -> cage value */
    int32_t *fo;              /* level-L value vertex -> the cage face it lies on */
    int32_t *ab;              /* its grid point there, a + (b << 16) (quad cage faces) */
    uint8_t *direct;          /* level-L value vertex: weights written down (surface/fvar_direct.c) */
    ccn__fvar_direct dir;
    ccn__fvar_probe_list *pl;           /* L levels' points the probes need (NULL: all) */
    int32_t nouts, *outs;     /* the outputs composed by probing */
    /* every output written down: levels 1..L as numbering only (numbered()) */
    int numbered_only;
    int32_t nvL, nsharpL;     /* level L's value vertices, those kept sharp */
    int32_t *hvL, *firstL;    /* level L: value vertex per corner; each one's first fan corner */
    /* Level-1 blocks (surface/fvar_direct.c on level 1): a probed output in a level-1 face whose
     * 4 x 4 block is regular there has the bicubic patch of those level-1 points as its limit,
     * so the probes read it off level 1 (no limit stencil, nothing finer computed for it). */
    ccn__fvar_direct dir1;
    int32_t *d1;              /* level-L value vertex: its level-1 table, -1 none */
    int32_t *d1ab;            /* its grid point in that level-1 face, a + (b << 16) */
    int32_t nd1, side1, *d1verts; /* tables: 16 level-1 value vertices each (P_ij at i + 4 j) */
    double *d1N;              /* tables: 8 * side1 basis values each (fvar_direct_table) */
    uint8_t *skip;            /* level-L value vertex: no limit stencil (direct, or d1 >= 0) */
} ccn__fvar_builder;

#endif
