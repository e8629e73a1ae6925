/* Regular faces -> bicubic Bézier patches by exact conversion of the non-uniform B-spline.
 *
 * A quad face is a bicubic patch of its 4x4 control net when its corners are regular (the
 * net exists); it is the exact subdivision limit ("strict") when every vertex of the net is
 * regular (interior valence 4, boundary valence 3 or pinned corner; mirrored ghosts across
 * the boundary): then the net refines by knot insertion forever. The net is assembled from
 * the 3x3 grids of the four corners (limit.c); the intervals D_-2..D_2 of each direction
 * come from the ring intervals (D_0 = the face's own).
 *
 * Creases: sharp edges (sharpness >= 1) split the surface into sectors that refine
 * independently, like boundaries (rules/bspline.c). A corner's grid is that of its sector
 * holding the face, mirrored across the sector's sharp edges (ccn__vertex_grid), and a vertex
 * counts as regular for the faces of one sector (ccn__sector_regular): a crease vertex's
 * two-face sector and a corner's one-face sector are, so a face beside an infinitely sharp
 * crease through valence-4 vertices is the bicubic patch whose boundary is the crease curve.
 * Semi-sharp values (still decaying) at a vertex make it irregular.
 *
 * 1-D conversion of the span [t_0, t_1] from P_-1..P_2 (blossoming):
 *   b_0 = f(t_0,t_0,t_0)   limit at t_0 (limit.c)
 *   b_1 = f(t_0,t_0,t_1) = (1-a) P_0 + a P_1,  a = D_-1 / (D_-1 + D_0 + D_1)
 *   b_2 = f(t_0,t_1,t_1) = (1-c) P_0 + c P_1,  c = (D_-1 + D_0) / (D_-1 + D_0 + D_1)
 *   b_3 = f(t_1,t_1,t_1)   limit at t_1
 */
#include "surface/patches.h"

#include "rules/bspline.h"

#include <string.h>

static void span_to_bezier(const double D[5], double C[4][4]) {
    double w[3], dw[3];
    memset(C, 0, sizeof(double) * 16);
    ccn__curve_limit_weights(D[0], D[1], D[2], D[3], w, dw);
    for (int i = 0; i < 3; i++) C[0][i] = w[i];
    double a = D[1] / (D[1] + D[2] + D[3]), c = (D[1] + D[2]) / (D[1] + D[2] + D[3]);
    C[1][1] = 1 - a; C[1][2] = a;
    C[2][1] = 1 - c; C[2][2] = c;
    ccn__curve_limit_weights(D[1], D[2], D[3], D[4], w, dw);
    for (int i = 0; i < 3; i++) C[3][i + 1] = w[i];
}

static int vpoint_regular(const ccn_mesh *m, const ccn__vpoint *p, int pinned) {
    for (int k = 0; k < p->n; k++)
        if (ccn__limit_kind(m, p->v[k], pinned) != CCN_LIMIT_REGULAR) return 0;
    return 1;
}

/* Creases: every vertex of every face of the corners' sectors that hold f (the faces the net
 * is made of; each one's vertices are its real points) regular in that face's sector. */
static int sectors_strict(const ccn_mesh *m, int32_t f, int pinned) {
    for (int32_t h = m->fstart[f]; h < m->fstart[f + 1]; h++) {
        int32_t v = m->hvert[h], first, count, nfan = m->vfan_start[v + 1] - m->vfan_start[v];
        ccn__fan_sector(m, v, m->hfanpos[h], &first, &count);
        for (int32_t i = 0; i < count; i++) {
            int32_t g = m->hface[m->vfan[m->vfan_start[v] + (first + i) % nfan]];
            if (ccn__fsize(m, g) != 4) return 0;
            for (int32_t x = m->fstart[g]; x < m->fstart[g + 1]; x++)
                if (!ccn__sector_regular(m, m->hvert[x], m->hfanpos[x], pinned)) return 0;
        }
    }
    return 1;
}

int ccn__bicubic_net(const ccn_mesh *m, int32_t f, int pinned, int strict, ccn__vpoint net[4][4],
                     double Cu[4][4], double Cv[4][4]) {
    if (ccn__fsize(m, f) != 4) return 0;
    int32_t h0 = m->fstart[f];
    for (int k = 0; k < 4; k++)
        if (!ccn__sector_regular(m, m->hvert[h0 + k], m->hfanpos[h0 + k], pinned)) return 0;
    if (strict && m->esharp && !sectors_strict(m, f, pinned)) return 0;
    ccn__vgrid g[4];
    for (int k = 0; k < 4; k++)
        ccn__vertex_grid(m, m->hvert[h0 + k], m->hfanpos[h0 + k], pinned, &g[k]);
    /* net[i+1][j+1] = point (i,j), i along v0->v1, j along v0->v3 */
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++) {
            net[a][b] = g[0].p[a][b];                 /* corner v0 at (0,0) */
            net[3 - a][3 - b] = g[2].p[a][b];         /* v2 at (1,1), rotated 180 deg */
        }
    net[3][0] = g[1].p[0][0]; /* v1 at (1,0): local (a,b) -> (1-b, a) */
    net[0][3] = g[3].p[0][0]; /* v3 at (0,1): local (a,b) -> (b, 1-a) */
    for (int i = 0; strict && !m->esharp && i < 4; i++)
        for (int j = 0; j < 4; j++)
            if (!vpoint_regular(m, &net[i][j], pinned)) return 0;
    double Du[5] = {g[0].du[0], g[0].du[1], g[0].du[2], g[0].du[3], g[2].du[0]};
    double Dv[5] = {g[0].dv[0], g[0].dv[1], g[0].dv[2], g[0].dv[3], g[2].dv[0]};
    span_to_bezier(Du, Cu);
    span_to_bezier(Dv, Cv);
    return 1;
}

static void vpoint_pos(const double *pos, const ccn__vpoint *p, double out[3]) {
    out[0] = out[1] = out[2] = 0;
    for (int k = 0; k < p->n; k++)
        for (int i = 0; i < 3; i++) out[i] += p->w[k] * pos[3 * (size_t)p->v[k] + i];
}

int ccn__bicubic_patch(const ccn_mesh *m, int32_t f, int pinned, int strict, double bez[4][4][3]) {
    ccn__vpoint net[4][4];
    double Cu[4][4], Cv[4][4], P[4][4][3], T[4][4][3];
    if (!ccn__bicubic_net(m, f, pinned, strict, net, Cu, Cv)) return 0;
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++) vpoint_pos(m->pos, &net[i][j], P[i][j]);
    memset(T, 0, sizeof T);
    for (int r = 0; r < 4; r++) /* T = Cu * P */
        for (int i = 0; i < 4; i++)
            for (int j = 0; j < 4; j++)
                for (int k = 0; k < 3; k++) T[r][j][k] += Cu[r][i] * P[i][j][k];
    memset(bez, 0, sizeof(double) * 48);
    for (int r = 0; r < 4; r++) /* bez = T * Cv^T */
        for (int c = 0; c < 4; c++)
            for (int j = 0; j < 4; j++)
                for (int k = 0; k < 3; k++) bez[r][c][k] += Cv[c][j] * T[r][j][k];
    return 1;
}

/* de Casteljau in both directions with first derivatives. */
void ccn__bezier_eval(const double *b, int deg, double u, double v, double pos[3],
                      double du[3], double dv[3]) {
    double row[6][3], drow[6][3], tmp[6][3];
    int n = deg + 1;
    for (int i = 0; i < n; i++) { /* reduce along v for each i (b[i][j], j along v) */
        for (int j = 0; j < n; j++) memcpy(tmp[j], b + 3 * (size_t)(i * n + j), sizeof tmp[j]);
        for (int r = 1; r < deg; r++)
            for (int j = 0; j < n - r; j++)
                for (int k = 0; k < 3; k++) tmp[j][k] = (1 - v) * tmp[j][k] + v * tmp[j + 1][k];
        for (int k = 0; k < 3; k++) {
            drow[i][k] = deg * (tmp[1][k] - tmp[0][k]);
            row[i][k] = (1 - v) * tmp[0][k] + v * tmp[1][k];
        }
    }
    for (int r = 1; r < deg; r++)
        for (int i = 0; i < n - r; i++)
            for (int k = 0; k < 3; k++) {
                row[i][k] = (1 - u) * row[i][k] + u * row[i + 1][k];
                drow[i][k] = (1 - u) * drow[i][k] + u * drow[i + 1][k];
            }
    for (int k = 0; k < 3; k++) {
        du[k] = deg * (row[1][k] - row[0][k]);
        pos[k] = (1 - u) * row[0][k] + u * row[1][k];
        dv[k] = (1 - u) * drow[0][k] + u * drow[1][k];
    }
}
