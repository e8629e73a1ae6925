/* The border data of a vertex's fill (surface/fill_border.h). */
#include "surface/fill_border.h"

#include "surface/patches.h"

#include <string.h>

/* The Bezier grid b (4x4x3, b[i][j] i along the face's first half-edge) re-framed to start at
 * corner r (r quarter turns: (u,v) -> (1 - v', u') each). */
static void rotate(double b[4][4][3], int32_t r) {
    double t[4][4][3];
    for (; r > 0; r--) {
        for (int i = 0; i < 4; i++)
            for (int j = 0; j < 4; j++) memcpy(t[i][j], b[3 - j][i], sizeof t[i][j]);
        memcpy(b, t, sizeof t);
    }
}

/* Aligned cells (packs.c's convention): a base half-edge b of face hface[b] runs along +u. */
static int32_t step_u(const ccn_mesh *m, int32_t b) {
    if (b < 0) return -1;
    int32_t x = ccn__next(m, b), t = m->htwin[x];
    return t < 0 || ccn__edge_sharp(m, m->hedge[x]) ? -1 : ccn__next(m, t); /* not across a crease */
}
static int32_t step_v(const ccn_mesh *m, int32_t b) {
    if (b < 0) return -1;
    int32_t x = ccn__next(m, ccn__next(m, b));
    return ccn__edge_sharp(m, m->hedge[x]) ? -1 : m->htwin[x];
}

int ccn__fill_cell_patch(const ccn_mesh *m, int32_t b, int pinned, double out[4][4][3]) {
    if (b < 0) return 0;
    int32_t f = m->hface[b];
    if (!ccn__bicubic_patch(m, f, pinned, 0, out)) return 0;
    rotate(out, b - m->fstart[f]);
    return 1;
}

/* Poles Q0..Q4 of the 2-span uniform clamped cubic (knots 0000 1 2222) equal to the C2 pair of
 * Bezier pieces a0..a3, a3..a6 (a[k] at stride 3 doubles). */
static void two_span(const double a[7][3], double Q[5][3]) {
    for (int d = 0; d < 3; d++) {
        Q[0][d] = a[0][d];
        Q[1][d] = a[1][d];
        Q[2][d] = 0.5 * ((2 * a[2][d] - a[1][d]) + (2 * a[4][d] - a[5][d]));
        Q[3][d] = a[5][d];
        Q[4][d] = a[6][d];
    }
}

void ccn__fill_sector_block(const ccn_mesh *m, int32_t h, ccn__fill_block *k) {
    k->g = h;
    k->A = step_u(m, h);
    k->B = step_v(m, h);
    k->D = step_v(m, k->A);
    k->N1 = step_u(m, k->A);
    k->N2 = step_u(m, k->D);
    k->M1 = step_v(m, k->B);
    k->M2 = step_v(m, k->D);
}

void ccn__fill_side_poles(const double P[4][4][3], const double Q[4][4][3], int along_u, int layer,
                          double out[5][3]) {
    double a[7][3];
    for (int k = 0; k < 7; k++) {
        const double (*c)[4][3] = k < 3 ? P : Q;
        int q = k < 3 ? k : k - 3;
        const double *s = along_u ? c[q][0] : c[0][q], *t = along_u ? c[q][1] : c[1][q];
        for (int d = 0; d < 3; d++) a[k][d] = layer ? 2 * s[d] - t[d] : s[d];
    }
    two_span((const double(*)[3])a, out);
}


void ccn__fill_sector_border(const double nb[4][4][4][3], double c[5][5][3]) {
    double S[5][3], L[5][3];
    int cnt[5][5];
    memset(cnt, 0, sizeof cnt);
    for (int pass = 0; pass < 2; pass++) { /* u-side from N1, N2; v-side from M1, M2 */
        const double (*a)[4][3] = nb[pass ? 2 : 0];
        const double (*b)[4][3] = nb[pass ? 3 : 1];
        ccn__fill_side_poles(a, b, pass, 0, S);
        ccn__fill_side_poles(a, b, pass, 1, L);
        for (int q = 0; q < 5; q++)
            for (int lay = 0; lay < 2; lay++) {
                int i = pass ? q : 4 - lay, j = pass ? 4 - lay : q;
                for (int d = 0; d < 3; d++) c[i][j][d] += lay ? L[q][d] : S[q][d];
                cnt[i][j]++;
            }
    }
    for (int i = 0; i < 5; i++) /* the far corner comes from both sides: their mean */
        for (int j = 0; j < 5; j++)
            for (int d = 0; d < 3 && cnt[i][j] > 1; d++) c[i][j][d] /= cnt[i][j];
    for (int j = 1; j < 3; j++) /* inner layers: linear continuations of the outer two */
        for (int d = 0; d < 3; d++) {
            c[2][j][d] = 2 * c[3][j][d] - c[4][j][d];
            c[j][2][d] = 2 * c[j][3][d] - c[j][4][d];
        }
    for (int d = 0; d < 3; d++) {
        c[2][2][d] = 0.5 * ((2 * c[3][2][d] - c[4][2][d]) + (2 * c[2][3][d] - c[2][4][d]));
        c[1][1][d] = 0.5 * ((2 * c[2][1][d] - c[3][1][d]) + (2 * c[1][2][d] - c[1][3][d]));
    }
}
