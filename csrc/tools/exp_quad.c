/* ccnurbs experiment charmap: topology helpers. A quad mesh with half-edges indexed, the grid of
 * rings around an EV walked face by face, and refinement that follows the EV. */
#include "exp.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void exp_quad_free(quad_mesh *q) {
    free(q->pos); free(q->fv); free(q->everts); free(q->ostart); free(q->out);
    free(q->eknot); free(q->vestart); free(q->vedges);
    memset(q, 0, sizeof *q);
}

static int quad_index(quad_mesh *q) {
    q->ostart = calloc((size_t)q->nv + 1, sizeof(int32_t));
    q->out = malloc(sizeof(int32_t) * 4 * (size_t)q->nf);
    if (!q->ostart || !q->out) return -1;
    for (int32_t h = 0; h < 4 * q->nf; h++) q->ostart[q->fv[h] + 1]++;
    for (int32_t v = 0; v < q->nv; v++) q->ostart[v + 1] += q->ostart[v];
    int32_t *fill = malloc(sizeof(int32_t) * (size_t)(q->nv ? q->nv : 1));
    if (!fill) return -1;
    memcpy(fill, q->ostart, sizeof(int32_t) * (size_t)q->nv);
    for (int32_t h = 0; h < 4 * q->nf; h++) q->out[fill[q->fv[h]]++] = h;
    free(fill);
    return 0;
}

/* Copies a mesh's positions, faces (must all be quads) and edges, and indexes half-edges. */
int exp_quad_load(const ccn_mesh *m, quad_mesh *q) {
    ccn_mesh_info in;
    ccn_mesh_get_info(m, &in);
    memset(q, 0, sizeof *q);
    if (in.num_face_verts != 4 * in.num_faces) return -1;
    q->nv = in.num_verts;
    q->nf = in.num_faces;
    q->ne = in.num_edges;
    q->pos = malloc(sizeof(double) * 3 * (size_t)q->nv);
    q->fv = malloc(sizeof(int32_t) * 4 * (size_t)q->nf);
    q->everts = malloc(sizeof(int32_t) * 2 * (size_t)q->ne);
    if (!q->pos || !q->fv || !q->everts) return -1;
    ccn_mesh_copy(m, q->pos, NULL, q->fv, q->everts, NULL);
    return quad_index(q);
}

/* exp_quad_load plus the edge intervals and the edges at each vertex. */
int exp_quad_load_knots(const ccn_mesh *m, quad_mesh *q) {
    if (exp_quad_load(m, q)) return -1;
    q->eknot = malloc(sizeof(double) * (size_t)(q->ne ? q->ne : 1));
    q->vestart = calloc((size_t)q->nv + 1, sizeof(int32_t));
    q->vedges = malloc(sizeof(int32_t) * 2 * (size_t)(q->ne ? q->ne : 1));
    int32_t *fill = malloc(sizeof(int32_t) * (size_t)(q->nv ? q->nv : 1));
    if (!q->eknot || !q->vestart || !q->vedges || !fill) {
        free(fill);
        return -1;
    }
    ccn_mesh_copy(m, NULL, NULL, NULL, NULL, q->eknot);
    for (int32_t t = 0; t < 2 * q->ne; t++) q->vestart[q->everts[t] + 1]++;
    for (int32_t v = 0; v < q->nv; v++) q->vestart[v + 1] += q->vestart[v];
    memcpy(fill, q->vestart, sizeof(int32_t) * (size_t)q->nv);
    for (int32_t t = 0; t < 2 * q->ne; t++) q->vedges[fill[q->everts[t]]++] = t / 2;
    free(fill);
    return 0;
}

/* Interval of the edge a-b, or -1 if there is none. */
double exp_edge_knot(const quad_mesh *q, int32_t a, int32_t b) {
    for (int32_t t = q->vestart[a]; t < q->vestart[a + 1]; t++) {
        int32_t e = q->vedges[t];
        if (q->everts[2 * e] + q->everts[2 * e + 1] - a == b) return q->eknot[e];
    }
    return -1;
}

/* Half-edge a -> b as 4 f + k (corner k of face f is a), or -1. */
static int32_t find_half(const quad_mesh *q, int32_t a, int32_t b) {
    for (int32_t t = q->ostart[a]; t < q->ostart[a + 1]; t++) {
        int32_t h = q->out[t];
        if (q->fv[4 * (h / 4) + (h % 4 + 1) % 4] == b) return h;
    }
    return -1;
}

static int32_t corner(const quad_mesh *q, int32_t h, int k) {
    return q->fv[4 * (h / 4) + (h % 4 + k) % 4];
}

static int32_t find_edge(const quad_mesh *q, int32_t a, int32_t b) {
    for (int32_t e = 0; e < q->ne; e++)
        if ((q->everts[2 * e] == a && q->everts[2 * e + 1] == b) ||
            (q->everts[2 * e] == b && q->everts[2 * e + 1] == a))
            return e;
    return -1;
}

/* Walks sector s's G x G grid from V = P[0][0] and P[1][0] = s0; P is (G+1)^2, P[i*(G+1)+j].
 * Column 0 through the faces' bottom edges P[0][j] -> P[1][j], columns i >= 1 through their
 * left edges P[i][j+1] -> P[i][j]. Returns 0, or -1 if the topology is not a quad grid. */
static int walk_sector(const quad_mesh *q, int32_t ev, int32_t s0, int G, int32_t *P) {
    int W = G + 1;
    for (int t = 0; t < W * W; t++) P[t] = -1;
    P[0] = ev;
    P[W] = s0;
    for (int i = 0; i < G; i++)
        for (int j = 0; j < G; j++) {
            int32_t h = i == 0 ? find_half(q, P[j], P[W + j])
                               : find_half(q, P[i * W + j + 1], P[i * W + j]);
            if (h < 0) return -1;
            int32_t a = corner(q, h, 2), b = corner(q, h, 3);
            int32_t *pa = i == 0 ? &P[W + j + 1] : &P[(i + 1) * W + j];
            int32_t *pb = i == 0 ? &P[j + 1] : &P[(i + 1) * W + j + 1];
            if ((*pa >= 0 && *pa != a) || (*pb >= 0 && *pb != b)) return -1;
            *pa = a;
            *pb = b;
        }
    return 0;
}

/* The G-ring grid of valence-n EV `ev` whose spoke-0 neighbour is s0, in exp_fan_vid order. */
int exp_ring_grid(const quad_mesh *q, int32_t ev, int32_t s0, int n, int G, int32_t *idx) {
    int W = G + 1;
    int32_t *P = malloc(sizeof(int32_t) * (size_t)(n + 1) * (size_t)(W * W));
    if (!P) return -1;
    int32_t spoke = s0, rc = 0;
    for (int s = 0; s <= n && !rc; s++) {
        int32_t *Ps = P + (size_t)s * W * W;
        rc = walk_sector(q, ev, spoke, s < n ? G : 1, Ps);
        if (rc || s == n) break;
        spoke = Ps[1];
        for (int i = 1; i <= G; i++)
            for (int j = 0; j <= G; j++) idx[exp_fan_vid(n, G, s, i, j)] = Ps[i * W + j];
    }
    /* sector s's spoke s+1 must be sector s+1's spoke (so sector n is sector 0 again) */
    for (int s = 0; s < n && !rc; s++)
        for (int j = 1; j <= G; j++)
            if (P[(size_t)s * W * W + j] != idx[exp_fan_vid(n, G, s + 1, j, 0)]) rc = -1;
    idx[0] = ev;
    free(P);
    return rc;
}

/* Refines m one level with `scheme`, following the EV and its spoke-0 neighbour: in the refined
 * mesh they are the vertex point of ev (nf + ne + ev) and the edge point of edge (ev, s0). */
ccn_status exp_track_refine(const ccn_mesh *m, ccn_scheme scheme, int poly, int32_t *ev, int32_t *s0,
                            ccn_mesh **out, ccn_error *err) {
    quad_mesh q;
    if (exp_quad_load(m, &q)) {
        exp_quad_free(&q);
        return exp_fail_memory(err);
    }
    int32_t e = find_edge(&q, *ev, *s0);
    int32_t nf = q.nf, ne = q.ne;
    exp_quad_free(&q);
    if (e < 0) {
        err->status = CCN_ERR_INTERNAL;
        snprintf(err->message, sizeof err->message, "EV spoke edge not found");
        return CCN_ERR_INTERNAL;
    }
    ccn_options o = {.scheme = scheme, .threads = 1, .ev_polyhedron = poly}; /* cases run in parallel */
    ccn_status st = ccn_refine(m, 1, &o, out, err);
    if (st) return st;
    *ev = nf + ne + *ev;
    *s0 = nf + e;
    return CCN_OK;
}
