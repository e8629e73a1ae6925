/* Face-varying channels as meshes of values (refine/fvar.h).
 *
 * OpenSubdiv's semantics (vtr/fvarLevel.cpp, fvarRefinement.cpp, far/primvarRefiner.h), read
 * as a mesh: an edge whose two faces give different values at either end is a seam, a
 * boundary of the value mesh (OpenSubdiv: "discontinuous", infinitely sharp); the faces
 * around a vertex between seams form one value vertex. A value vertex whose faces are the
 * vertex's whole fan "matches" and refines by the vertex's own rules (its fan, intervals,
 * creases are the vertex's). Every other one lies on a boundary of the value mesh and gets
 * the boundary (crease) rules there, with the seam edges' intervals, unless the mode pins it
 * (OpenSubdiv's sharp values, an infinitely sharp vertex here):
 *   every mode but NONE: a span of one face (a UV corner);
 *   always: a span whose interior edges include an infinitely sharp one, a value used by two
 *     or more disjoint spans around the vertex, an infinitely sharp vertex;
 *   CORNERS_PLUS1/2: vertices with three or more values (junctions), and both values of a
 *     two-value vertex when either span is pinned for the reasons above; PLUS2 also when
 *     either span has one face;
 *   CORNERS_PLUS2, BOUNDARIES: a vertex with one value and a seam ending at it (a dart);
 *   BOUNDARIES: every value on a seam or on the mesh boundary (edges between: the midpoint);
 *   ALL: everything (bilinear: face points the average, edge points the midpoint).
 * A span with semi-sharp interior edges (or a semi-sharp vertex) is a corner until they
 * decay, then a crease, blended with OpenSubdiv's fractional weight: that is what the crease
 * rules of refine/level.c make of a boundary vertex with a semi-sharp edge. For PLUS1/2, the
 * other value of a two-value vertex follows that rule too (OpenSubdiv's dependent sharpness:
 * ccn__level.partner). The geometry's valence-2 corners: pinned when the vertex mesh pins
 * them; with smooth geometric corners, a corner of one face is pinned by every mode but NONE.
 * Sharp values stay sharp in refinement (vertex points inherit them); points on seams that
 * edges create are creases, except under BOUNDARIES and ALL.
 */
#include "refine/fvar.h"

#include "base/error.h"
#include "rules/crease.h"
#include "topology/mesh.h"

#include <math.h>
#include <string.h>

void ccn__fvar_free(ccn__fvar_level *f) {
    if (!f) return;
    ccn_mesh_destroy(f->m);
    free(f->vvert);
    free(f->corner);
    free(f->partner);
    memset(f, 0, sizeof *f);
}

int32_t ccn__fvar_num_sharp(const ccn__fvar_level *f) {
    int32_t n = 0;
    for (int32_t v = 0; f->m && v < f->m->nv; v++) n += f->corner[v] != 0;
    return n;
}

/* Intervals and sharpness of value mesh fm from its vertex mesh vm (same half-edges). */
static ccn_status sync_from_vertex_mesh(ccn__fvar_level *f, const ccn_mesh *vm, ccn_error *err) {
    ccn_mesh *fm = f->m;
    int all = f->linear == CCN_FVAR_LINEAR_ALL;
    for (int32_t h = 0; h < fm->nh; h++) fm->eknot[fm->hedge[h]] = all ? 1.0 : vm->eknot[vm->hedge[h]];
    fm->knot_scale = all ? 1.0 : vm->knot_scale;
    int need = all || vm->esharp != NULL;
    for (int32_t v = 0; v < fm->nv && !need; v++) need = f->corner[v] != 0;
    free(fm->esharp);
    free(fm->vsharp);
    fm->esharp = NULL;
    fm->vsharp = NULL;
    if (need) {
        if (ccn__mesh_alloc_sharpness(fm))
            return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (face-varying sharpness)");
        for (int32_t h = 0; h < fm->nh; h++)
            fm->esharp[fm->hedge[h]] = all ? CCN_SHARP_INF : vm->esharp ? vm->esharp[vm->hedge[h]] : 0.0f;
        for (int32_t v = 0; v < fm->nv; v++)
            fm->vsharp[v] = all || f->corner[v] ? CCN_SHARP_INF
                          : vm->vsharp ? vm->vsharp[f->vvert[v]] : 0.0f;
    }
    int32_t conflicts = vm->info.num_ring_conflicts, level = vm->info.level;
    ccn__mesh_update_info(fm);
    fm->info.num_ring_conflicts = conflicts;
    fm->info.level = level;
    fm->info.num_rings = vm->info.num_rings;
    return CCN_OK;
}

ccn_status ccn__fvar_check(const ccn_mesh *vm, const ccn_fvar_channel *ch, ccn_error *err) {
    if (!ch) return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "face-varying channel is NULL");
    if (ch->width < 1 || ch->width > CCN_FVAR_MAX_WIDTH)
        return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1,
                         "face-varying width must be 1..%d, got %d", CCN_FVAR_MAX_WIDTH, (int)ch->width);
    if (ch->linear < CCN_FVAR_LINEAR_NONE || ch->linear > CCN_FVAR_LINEAR_ALL)
        return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "unknown face-varying linear mode %d",
                         (int)ch->linear);
    if (ch->num_values < 1 || !ch->values || !ch->indices)
        return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1,
                         "face-varying channel needs values and indices (num_values %d)", (int)ch->num_values);
    for (int32_t f = 0; f < vm->nf; f++)
        for (int32_t h = vm->fstart[f]; h < vm->fstart[f + 1]; h++)
            if (ch->indices[h] < 0 || ch->indices[h] >= ch->num_values)
                return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_FACE, f,
                                 "face %d corner %d has face-varying value index %d, out of range [0, %d)",
                                 (int)f, (int)(h - vm->fstart[f]), (int)ch->indices[h], (int)ch->num_values);
    for (int64_t i = 0; i < (int64_t)ch->width * ch->num_values; i++)
        if (!isfinite(ch->values[i]) || fabs(ch->values[i]) > CCN_COORD_MAX)
            return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_VALUE, (int32_t)(i / ch->width),
                             "face-varying value %d has a non-finite component or one beyond +-%g",
                             (int)(i / ch->width), CCN_COORD_MAX);
    return CCN_OK;
}

/* ---- level 0 ------------------------------------------------------------------------ */

/* Per-vertex scratch for the span analysis (valence-sized). */
typedef struct {
    int32_t *run;        /* fan face -> run */
    int32_t *rfirst, *rsize, *rinf, *rsemi, *rid;   /* per run */
    int32_t *uval, *usize, *uinf, *usemi, *uruns;   /* per unique value */
    int32_t *urun;       /* per unique value: its (last) run */
    int32_t *sib;        /* fan face -> sibling (OpenSubdiv's value of the vertex) */
} spans;

static int seam(const ccn_mesh *vm, const int32_t *idx, int32_t h) {
    int32_t t = vm->htwin[h];
    return t >= 0 && (idx[h] != idx[ccn__next(vm, t)] || idx[ccn__next(vm, h)] != idx[t]);
}

static float vm_edge_sharp(const ccn_mesh *vm, int32_t e) {
    return vm->esharp ? vm->esharp[e] : 0.0f;
}

/* Splits v's fan into runs at seams; returns the number of runs (ids from *next). */
static int32_t fan_runs(const ccn_mesh *vm, const int32_t *idx, const uint8_t *cut, int32_t v,
                        spans *s, int32_t *next) {
    int32_t s0 = vm->vfan_start[v], nfan = vm->vfan_start[v + 1] - s0, k0 = 0, nr = 0;
    int bnd = vm->vboundary[v];
    if (!bnd) {
        k0 = -1;
        for (int32_t k = 0; k < nfan && k0 < 0; k++)
            if (cut[vm->hedge[vm->vfan[s0 + k]]]) k0 = k;
        if (k0 < 0) k0 = 0; /* no seam: one run around the vertex */
    }
    for (int32_t j = 0; j < nfan; j++) {
        int32_t k = (k0 + j) % nfan, h = vm->vfan[s0 + k];
        int32_t e = vm->hedge[h]; /* the edge between fan faces k-1 and k */
        if (j == 0 || cut[e]) {
            s->rfirst[nr] = k; s->rsize[nr] = 0; s->rinf[nr] = 0; s->rsemi[nr] = 0;
            s->rid[nr] = (*next)++;
            nr++;
        } else {
            float sh = vm_edge_sharp(vm, e);
            s->rinf[nr - 1] += sh >= CCN_SHARP_INF;
            s->rsemi[nr - 1] += sh > 0.0f && sh < CCN_SHARP_INF;
        }
        s->run[k] = nr - 1;
        s->rsize[nr - 1]++;
    }
    (void)idx;
    return nr;
}

/* OpenSubdiv's "siblings" of v: its distinct values in fan order (FVarLevel::
 * completeTopologyFromFaceValues). Its shortcut for the second distinct value compares with
 * the first only, so in the pattern A, B, A, B the second B becomes a value of its own; the
 * tags below count it so, as OpenSubdiv does. Returns the number of siblings; sib[k] per fan
 * face. */
static int32_t siblings(const ccn_mesh *vm, const int32_t *idx, int32_t v, spans *s) {
    int32_t s0 = vm->vfan_start[v], nfan = vm->vfan_start[v + 1] - s0, cnt = 1;
    s->uval[0] = idx[vm->vfan[s0]];
    s->sib[0] = 0;
    for (int32_t k = 1; k < nfan; k++) {
        int32_t val = idx[vm->vfan[s0 + k]];
        if (val == idx[vm->vfan[s0 + k - 1]]) { s->sib[k] = s->sib[k - 1]; continue; }
        s->sib[k] = cnt;
        if (cnt == 1 || (cnt == 2 && s->uval[0] != val)) { s->uval[cnt++] = val; continue; }
        int32_t u = 0;
        while (u < cnt && s->uval[u] != val) u++;
        if (u == cnt) s->uval[cnt++] = val;
        else s->sib[k] = u;
    }
    return cnt;
}

/* OpenSubdiv's tags of v's values (FVarLevel::completeTopologyFromFaceValues, gatherValueSpans):
 * corner flags and partners of v's runs. */
static void tag_vertex(const ccn_mesh *vm, const int32_t *idx, const uint8_t *cut, int32_t v,
                       int linear, int pinned, spans *s, int32_t nr, uint8_t *corner,
                       int32_t *partner, int *has_partner) {
    int32_t nfan = vm->vfan_start[v + 1] - vm->vfan_start[v], n = ccn__valence(vm, v);
    int bnd = vm->vboundary[v];
    float vs = vm->vsharp ? vm->vsharp[v] : 0.0f;
    if (pinned && bnd && n == 2) vs = CCN_SHARP_INF;
    int vinf = vs >= CCN_SHARP_INF, vsemi = vs > 0.0f && !vinf;
    int lin_bnd = linear >= CCN_FVAR_LINEAR_BOUNDARIES;
    int dep = linear == CCN_FVAR_LINEAR_CORNERS_PLUS1 || linear == CCN_FVAR_LINEAR_CORNERS_PLUS2;
    int corners_sharp = linear != CCN_FVAR_LINEAR_NONE;
    int darts = linear == CCN_FVAR_LINEAR_CORNERS_PLUS2 || lin_bnd;
    int anycut = 0;
    for (int32_t k = 0; k < n; k++) anycut |= cut[ccn__fan_edge(vm, v, k)];
    int mismatch = anycut || (bnd && lin_bnd) || (bnd && nfan == 1 && !pinned && corners_sharp);
    if (linear == CCN_FVAR_LINEAR_ALL) mismatch = 1;
    if (!mismatch) { /* the vertex's own rules; a pinned corner is a sharp vertex */
        for (int32_t r = 0; r < nr; r++) corner[s->rid[r]] = (uint8_t)vinf;
        return;
    }
    int32_t nu = siblings(vm, idx, v, s); /* the spans of the siblings */
    for (int32_t u = 0; u < nu; u++) s->usize[u] = s->uinf[u] = s->usemi[u] = s->uruns[u] = 0;
    for (int32_t r = 0; r < nr; r++) {
        int32_t u = s->sib[s->rfirst[r]];
        s->usize[u] += s->rsize[r]; s->uinf[u] += s->rinf[r]; s->usemi[u] += s->rsemi[r];
        s->uruns[u]++;
        s->urun[u] = r;
    }
    int all = lin_bnd || vinf || (dep && nu > 2) || (darts && nu == 1 && !bnd);
    int hasdep = 0;
    if (!all && dep && nu == 2) {
        all = s->uinf[0] || s->uinf[1] || s->uruns[0] > 1 || s->uruns[1] > 1;
        if (linear == CCN_FVAR_LINEAR_CORNERS_PLUS2) all |= s->usize[0] == 1 || s->usize[1] == 1;
        hasdep = (s->usemi[0] > 0) != (s->usemi[1] > 0);
    }
    for (int32_t r = 0; r < nr; r++) {
        int32_t u = s->sib[s->rfirst[r]];
        int sharp = s->uruns[u] > 1 || all || s->uinf[u] > 0 || (s->usize[u] == 1 && corners_sharp);
        corner[s->rid[r]] = (uint8_t)sharp;
        if (!sharp && hasdep && s->usemi[u] == 0 && !vsemi) {
            partner[s->rid[r]] = s->rid[s->urun[1 - u]];
            *has_partner = 1;
        }
    }
}

ccn_status ccn__fvar_build(const ccn_mesh *vm, const int32_t *idx, int linear, int pinned,
                           ccn__fvar_level *out, int32_t **value_of, ccn_error *err) {
    memset(out, 0, sizeof *out);
    *value_of = NULL;
    out->linear = linear;
    int32_t nh = vm->nh, maxn = 2;
    for (int32_t v = 0; v < vm->nv; v++)
        if (vm->vfan_start[v + 1] > vm->vfan_start[v] && ccn__valence(vm, v) > maxn) maxn = ccn__valence(vm, v);
    uint8_t *cut = calloc((size_t)(vm->ne ? vm->ne : 1), 1);
    int32_t *hv = malloc(sizeof(int32_t) * (size_t)nh);
    int32_t *sbuf = malloc(sizeof(int32_t) * 13 * (size_t)maxn);
    int32_t *vvert = malloc(sizeof(int32_t) * (size_t)nh), *vof = malloc(sizeof(int32_t) * (size_t)nh);
    uint8_t *corner = calloc((size_t)nh, 1);
    int32_t *partner = malloc(sizeof(int32_t) * (size_t)nh);
    double *zero = calloc(3 * (size_t)nh, sizeof(double));
    int32_t *fsz = malloc(sizeof(int32_t) * (size_t)vm->nf);
    ccn_status st = CCN_OK;
    if (!cut || !hv || !sbuf || !vvert || !vof || !corner || !partner || !zero || !fsz) {
        st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (face-varying channel)");
        goto done;
    }
    for (int32_t h = 0; h < nh; h++)
        if (seam(vm, idx, h) && !cut[vm->hedge[h]]) { cut[vm->hedge[h]] = 1; out->num_seams++; }
    spans s = {sbuf, sbuf + maxn, sbuf + 2 * maxn, sbuf + 3 * maxn, sbuf + 4 * maxn, sbuf + 5 * maxn,
               sbuf + 6 * maxn, sbuf + 7 * maxn, sbuf + 8 * maxn, sbuf + 9 * maxn, sbuf + 10 * maxn,
               sbuf + 11 * maxn, sbuf + 12 * maxn};
    int32_t nvf = 0;
    int has_partner = 0;
    for (int32_t h = 0; h < nh; h++) partner[h] = -1;
    for (int32_t v = 0; v < vm->nv; v++) {
        int32_t s0 = vm->vfan_start[v], nfan = vm->vfan_start[v + 1] - s0;
        if (nfan == 0) continue;
        int32_t first = nvf, nr = fan_runs(vm, idx, cut, v, &s, &nvf);
        for (int32_t k = 0; k < nfan; k++) {
            int32_t h = vm->vfan[s0 + k];
            hv[h] = s.rid[s.run[k]];
        }
        for (int32_t r = 0; r < nr; r++) {
            vvert[first + r] = v;
            vof[first + r] = idx[vm->vfan[s0 + s.rfirst[r]]];
        }
        tag_vertex(vm, idx, cut, v, linear, pinned, &s, nr, corner, partner, &has_partner);
    }
    for (int32_t f = 0; f < vm->nf; f++) fsz[f] = ccn__fsize(vm, f);
    ccn_cage c = {nvf, vm->nf, 0, zero, fsz, hv, NULL, NULL, NULL, NULL};
    if ((st = ccn_mesh_create(&c, &out->m, err))) {
        st = ccn__fail(err, CCN_ERR_INTERNAL, CCN_ELEM_NONE, -1, "face-varying topology is invalid");
        goto done;
    }
    out->vvert = vvert; vvert = NULL;
    out->corner = corner; corner = NULL;
    if (has_partner) { out->partner = partner; partner = NULL; }
    *value_of = vof; vof = NULL;
    st = sync_from_vertex_mesh(out, vm, err);
done:
    free(cut); free(hv); free(sbuf); free(vvert); free(vof); free(corner); free(partner);
    free(zero); free(fsz);
    if (st) { ccn__fvar_free(out); free(*value_of); *value_of = NULL; }
    return st;
}

/* ---- refinement ----------------------------------------------------------------------- */

ccn_status ccn__fvar_prepare(ccn__level *c, const ccn__fvar_level *f, int scheme,
                             int crease_method, int32_t ev_poly, ccn__ev_cache *cache,
                             ccn_error *err) {
    ccn_status st = ccn__level_prepare_ev(c, f->m, scheme, 0, crease_method, ev_poly, cache, err);
    if (!st) c->partner = f->partner;
    return st;
}

ccn_status ccn__fvar_child(const ccn__fvar_level *f, const ccn__level *c, const ccn_mesh *vm,
                           const ccn_mesh *vchild, ccn__fvar_level *out, ccn_error *err) {
    memset(out, 0, sizeof *out);
    out->linear = f->linear;
    const ccn_mesh *m = f->m;
    ccn_status st = ccn__level_topology(c, &out->m, err);
    if (st) return st;
    int32_t nv = out->m->nv, nf = m->nf, ne = m->ne;
    out->vvert = malloc(sizeof(int32_t) * (size_t)nv);
    out->corner = calloc((size_t)nv, 1);
    if (f->partner) out->partner = malloc(sizeof(int32_t) * (size_t)nv);
    if (!out->vvert || !out->corner || (f->partner && !out->partner)) {
        ccn__fvar_free(out);
        return ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory (face-varying level)");
    }
    int all = f->linear == CCN_FVAR_LINEAR_ALL, bnd = f->linear == CCN_FVAR_LINEAR_BOUNDARIES;
    for (int32_t i = 0; i < nf; i++) out->vvert[i] = i;
    for (int32_t h = 0; h < m->nh; h++) {
        int32_t e = m->hedge[h];
        out->vvert[nf + e] = nf + vm->hedge[h];
        out->corner[nf + e] = (uint8_t)(all || (bnd && m->htwin[h] < 0));
    }
    for (int32_t v = 0; v < m->nv; v++) {
        out->vvert[nf + ne + v] = nf + vm->ne + f->vvert[v];
        out->corner[nf + ne + v] = f->corner[v];
    }
    if (all) memset(out->corner, 1, (size_t)nv);
    if (out->partner) {
        for (int32_t i = 0; i < nf + ne; i++) out->partner[i] = -1;
        for (int32_t v = 0; v < m->nv; v++)
            out->partner[nf + ne + v] = f->partner[v] >= 0 ? nf + ne + f->partner[v] : -1;
    }
    st = sync_from_vertex_mesh(out, vchild, err);
    if (st) ccn__fvar_free(out);
    return st;
}
