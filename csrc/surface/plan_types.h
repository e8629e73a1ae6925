/* The plan: everything that depends on topology, intervals and options (internal data of
 * surface/plan.c, caps.c, tessellate.c, patch_set.c; no code of its own). */
#ifndef CCN_SURFACE_PLAN_TYPES_H
#define CCN_SURFACE_PLAN_TYPES_H

#include "refine/level.h"
#include "topology/halfedge.h"

struct ccn__bi5;
struct ccn__fvchan; /* a face-varying channel (surface/plan_fvar.c) */
struct ccn__edit_region; /* what an interval edit changes (surface/edit_region.c) */

/* One extraordinary vertex filled by the guided bi-5 cap (K&P 2018). */
typedef struct {
    int32_t n;          /* valence */
    int32_t *cnet;      /* 6n+1 level-K vertex indices, SPEC §1.2 order */
    int32_t *ring;      /* 2n+1 level-K 1-ring (centre stencil support) */
    double *l0;         /* 2n+1 limit weights (centre point) */
    double *knots;      /* n spoke intervals at level K */
    const struct ccn__bi5 *op; /* shared per valence, owned by the plan or its ccn_cache */
    double *patches;    /* (3*nsig+1)*n bi-5 patches, 36*3 doubles each */
    int exact_surround; /* 1: arbitrary NU intervals, border = level-(K+1) pieces (bi5.h [R13]) */
    double *pieces;     /* exact_surround: n*4 bi-5 pieces, 36*3 doubles each (evaluate fills) */
    void *taus;         /* non-uniform (some kappa != 1): the n cap taus (double complex[36] each,
                           bi5.h [R11]), computed once at create; NULL otherwise */
    double w;           /* the bi-5 cap's weight in its hole: 1, falling smoothly to 0 as the
                           spoke ratios reach its range (caps.c); against the G1 fill cap where
                           there is one, else against the refined limit. 0: the fill alone (no
                           bi-5 patches) */
    struct ccn__fill_cap *fill; /* the G1 fill cap (surface/fill_cap.h) where w < 1, or NULL */
    double wu;          /* spoke intervals within CCN_CAP_UNIFORM_BAND of equal (not equal): the
                           weight, falling from 1 to 0 across the band, of the uniform operator's
                           cap (uop, upatches on the level-K net, with its bicubic ring faces)
                           blended with this exact-surround one; 0 otherwise (caps.c) */
    const struct ccn__bi5 *uop;
    double *upatches;
} ccn__cap;

struct ccn_plan {
    ccn_options opts;
    int threads;
    int32_t L, R, K;        /* output level, levels built (max(L, K)), cap level (-1: none) */
    int32_t caps_deferred;  /* cap EVs left without caps because no cap level is below L */
    ccn_mesh **lev;         /* R+1 meshes: lev[0] is the cage */
    ccn__level *prep;       /* R prepared levels */
    /* level L+1, needed only around irregular vertices: either lev[L+1] (R > L) or computed
     * partially into posS from level L by `sub` around the vertices in near[] */
    ccn__level sub;
    int has_sub;
    double *posS;
    int32_t nnear, *near;
    int32_t ncage;
    double *cage_pos;       /* the caller's cage positions (evaluate works on a normalised copy) */
    double centre[3], scale; /* normalisation of the last evaluate */
    /* output mesh = level L without isolated vertices */
    int32_t nout_v, nout_f;
    int32_t *vmapL;         /* level-L vertex -> output vertex (-1: isolated) */
    int32_t *out_vL;        /* output vertex -> level-L vertex */
    int32_t *out_fv, *out_origin;
    int32_t *out_eorigin;   /* 4 * nout_f: cage edge under each face corner's outgoing edge */
    int32_t nout_e, *out_ev, *out_ce; /* output edges: 2 * nout_e vertices, 4 * nout_f per corner */
    /* limit stencils, CSR; index < lev[L]->nv: a level-L vertex, else (index - lev[L]->nv)
     * is a level-(L+1) point (face points, edge points, vertex points) */
    int32_t *st_start, *st_v;
    double *st_wp, *st_wu, *st_wv;
    /* st_w[o] >= 0: output o's own weights start at st_wp/st_wu/st_wv + st_w[o] (its row's
     * length); < 0: they are the shared weight set -1 - st_w[o], 27 doubles in ws (wp, wu, wv
     * of up to 9 entries): the regular outputs' 3 x 3 stencils, each distinct one once (with
     * uniform intervals, or inside a cage face at level >= 2, they are all alike) */
    int32_t *st_w;
    double *ws;
    int32_t nws;
    int32_t st_nown;        /* entries of st_wp / st_wu / st_wv (the rows with their own weights) */
    /* curvature (surface/curvature.c), made by the first evaluation that asks for curvatures
     * (NULL until then). Where a row's curvature stencil has the row's own points, its second
     * derivative weights S_uu, S_uv, S_vv are kept aligned with the row (its wu, wv are S_u,
     * S_v: the same grid), and the stencil pass computes positions, normals and curvatures
     * together: curv_ws 27 doubles per shared weight set (curv_set[k] 1: made), curv_wuu /
     * curv_wuv / curv_wvv st_nown entries for the rows with their own weights. curv_mode per
     * output: CCN__CURV_FLAG (NaN, or a cap's patch gives it), _ROW (the aligned weights),
     * _OWN / _OWN_CHILD (a stencil of other points, made per evaluation: curv_other lists
     * them). */
    uint8_t *curv_mode, *curv_set;
    double *curv_ws, *curv_wuu, *curv_wuv, *curv_wvv;
    int32_t ncurv_other, *curv_other;
    /* sharp features: output vertices whose faces see more than one tangent plane (creases,
     * corners). Their sectors' tangent stencils (indices as st_v), CSR; each output face
     * corner names its sector (-1: the vertex normal). The vertex normal of such a vertex is
     * the normalised sum of its sectors' normals. */
    int32_t nsv, *sv_out, *sv_sec;  /* sv_sec: nsv + 1 offsets into the sectors */
    int32_t nsec, *sec_start, *sec_v;
    double *sec_wu, *sec_wv;
    int32_t *corner_sec;            /* 4 * nout_f, NULL when nsv = 0 */
    double *sec_nrm;                /* evaluate's scratch: 3 * nsec */
    /* caps */
    int32_t ncap;
    ccn__cap *caps;
    struct ccn__bi5 **ops;  /* one per valence used, nops entries */
    int32_t *op_n;          /* valence of each op */
    int32_t nops;
    double *cap_net;        /* evaluate's c-net buffer (largest cap) */
    int32_t nhv;            /* output vertices evaluated on a cap */
    int32_t *hv_out, *hv_cap, *hv_sector;
    double *hv_uv;
    /* ring around each cap: level-K faces touching the hole, evaluated as the bicubic patch
     * of their level-K net (the spline the cap joins C2), not as the subdivision limit;
     * not for exact_surround caps, whose surround is the limit itself */
    int32_t nrf, *rf_face;  /* distinct faces */
    int32_t *rf_cap;        /* the cap of each (the weight of its bicubic patch: 1, or the cap's wu) */
    uint8_t *rf_on;         /* per face: bit j set where its corner j is on the cap's 1-ring */
    double *rf_bez;         /* 48 doubles per face, filled by evaluate */
    int32_t nbv;            /* output vertices on those faces */
    int32_t *bv_out, *bv_rf;
    double *bv_uv;
    ccn_sizes sizes;
    ccn_plan_stats stats;
    /* face-varying channels (surface/plan_fvar.c) */
    int32_t nfv;
    struct ccn__fvchan **fv;
    /* per-vertex data (ccn_plan_evaluate_vertex_data): scratch positions of levels 0..L (and
     * L+1 when built) and of the level-(L+1) subset, allocated on first use */
    double *vd_buf;
    ccn__ev_cache *ev_cache; /* eigen polyhedron choices, shared by every level and limit */
    ccn_cache *op_cache;     /* the caller's bi-5 operators (options.cache), or NULL:
                                then ops holds the plan's own */
    /* during ccn_plan_create with options.previous only (NULL otherwise): the earlier plan, of the same cage
     * topology, creases and options, consumed by the call: its level topology and output mesh
     * arrays are taken over (moved, not copied), its unchanged limit stencils, rule weights and
     * cap taus copied; destroyed at the end */
    struct ccn_plan *hint;
    /* 1 after a successful ccn_plan_evaluate: the levels' points are those of lev[0]->pos
     * (normalised by centre, scale) */
    int evaluated;
    /* the output arrays the last evaluation wrote (its ccn_limit_mesh's positions, normals,
     * corner_normals): a plan recreated from this one evaluates only what the edit changed
     * when it is given these same arrays again, and everything otherwise */
    const double *last_out[3];
    /* made with options.previous from an evaluated earlier plan, used and dropped by the next
     * evaluation: the earlier plan's level points (moved into lev[]) and what the edit changed */
    struct ccn__edit_region *region;
};

enum { CCN__CURV_FLAG = 0, CCN__CURV_ROW = 1, CCN__CURV_OWN = 2, CCN__CURV_OWN_CHILD = 3 };

/* Row o's three weight arrays in a table of own rows (own[t] + st_w[o]) and shared sets (27
 * doubles per set in sets: 9 per array): the position weights wp, wu, wv (st_wp.., ws) or the
 * curvature weights wuu, wuv, wvv aligned with them (curv_wuu.., curv_ws). */
static inline void ccn__plan_row_table(const ccn_plan *p, int32_t o, const double *const own[3],
                                       const double *sets, const double **w0, const double **w1,
                                       const double **w2) {
    int32_t w = p->st_w[o];
    if (w >= 0) {
        *w0 = own[0] + w; *w1 = own[1] + w; *w2 = own[2] + w;
    } else {
        const double *s = sets + 27 * (size_t)(-1 - w);
        *w0 = s; *w1 = s + 9; *w2 = s + 18;
    }
}

/* The weights of output o's stencil row (see ccn_plan.st_w); entry k of the row is index
 * st_v[st_start[o] + k]. */
static inline void ccn__plan_row_weights(const ccn_plan *p, int32_t o, const double **wp,
                                         const double **wu, const double **wv) {
    const double *own[3] = {p->st_wp, p->st_wu, p->st_wv};
    ccn__plan_row_table(p, o, own, p->ws, wp, wu, wv);
}

/* The second-derivative weights of output o's stencil row, aligned with its entries
 * (curv_mode[o] == CCN__CURV_ROW). */
static inline void ccn__plan_row_curv_weights(const ccn_plan *p, int32_t o, const double **wuu,
                                              const double **wuv, const double **wvv) {
    const double *own[3] = {p->curv_wuu, p->curv_wuv, p->curv_wvv};
    ccn__plan_row_table(p, o, own, p->curv_ws, wuu, wuv, wvv);
}

#endif
