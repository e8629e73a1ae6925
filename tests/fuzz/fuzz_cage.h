/* Cage generator shared by fuzz_mesh.c and fuzz_plan.c: bytes -> a polygon soup (raw), an
 * open quad grid with some quads triangulated or deleted, or a quad fan around one vertex of
 * valence 3..66; then given edges with intervals. Layout: see fuzz_mesh.c. */
#ifndef CCN_FUZZ_CAGE_H
#define CCN_FUZZ_CAGE_H
#include "fuzz_common.h"

typedef struct { const uint8_t *d; size_t n, i; } rd;

static inline uint8_t next(rd *r) { return r->i < r->n ? r->d[r->i++] : 0; }

static inline double next_double(rd *r) {
    uint8_t b[8];
    for (int k = 0; k < 8; k++) b[k] = next(r);
    double x;
    memcpy(&x, b, sizeof x);
    return x;
}

/* An interval: a special value, or a ratio 1e-9 .. 1e9. */
static inline double next_knot(rd *r) {
    uint8_t b = next(r);
    if (b < 128) return fz_special(b);
    return pow(10.0, ((double)b - 192.0) * (9.0 / 64.0));
}

#define MAXV 160
#define MAXF 80
#define MAXFV 400
#define MAXE 48

typedef struct {
    int32_t nv, nf, ne;
    double pos[3 * MAXV];
    int32_t fs[MAXF], fv[MAXFV], ev[2 * MAXE];
    double kn[MAXE];
    double cr[MAXE];   /* edge sharpness */
    double vc[MAXV];   /* vertex sharpness */
} soup;

/* Sharpness from a byte: mostly 0, else semi-sharp 0..12, a few specials (NaN, Inf, -1). */
static inline double next_crease(rd *r) {
    uint8_t b = next(r);
    if (b < 160) return 0.0;
    if (b == 250) return NAN;
    if (b == 251) return INFINITY;
    if (b == 252) return -1.0;
    if (b == 253) return 10.0;
    return (double)(b - 160) * (12.0 / 90.0);
}

static inline void perturb(rd *r, soup *s) {
    for (int32_t v = 0; v < s->nv; v++) {
        uint8_t b = next(r);
        if (b < 24) s->pos[3 * v + (next(r) % 3)] = fz_special(b);
        else s->pos[3 * v + 2] += ((double)b - 140.0) / 256.0;
    }
}

static inline void fz_make_raw(rd *r, soup *s, int raw_doubles) {
    s->nv = next(r) % 48;
    s->nf = next(r) % 24;
    int32_t h = 0;
    for (int32_t f = 0; f < s->nf; f++) {
        int32_t n = next(r) % 10;
        if (h + n > MAXFV) n = 0;
        s->fs[f] = n;
        h += n;
    }
    for (int32_t k = 0; k < h; k++) s->fv[k] = (int32_t)(next(r) % (s->nv + 2)) - 1;
    for (int32_t k = 0; k < 3 * s->nv; k++)
        s->pos[k] = raw_doubles ? next_double(r) : fz_special(next(r));
}

static inline void fz_make_grid(rd *r, soup *s) {
    int nx = 1 + next(r) % 6, ny = 1 + next(r) % 6;
    uint64_t tri = 0, del = 0;
    for (int k = 0; k < 4; k++) tri = tri << 8 | next(r);
    for (int k = 0; k < 2; k++) del = del << 8 | next(r);
    s->nv = (nx + 1) * (ny + 1);
    for (int j = 0; j <= ny; j++)
        for (int i = 0; i <= nx; i++) {
            double *p = s->pos + 3 * (j * (nx + 1) + i);
            p[0] = i; p[1] = j; p[2] = 0.0;
        }
    int32_t f = 0, h = 0;
    for (int j = 0; j < ny; j++)
        for (int i = 0; i < nx; i++) {
            int q = j * nx + i;
            if (q < 16 && ((del >> q) & 1) && ((del >> 15) & 1)) continue; /* delete */
            int32_t v = j * (nx + 1) + i;
            int32_t c[4] = {v, v + 1, v + nx + 2, v + nx + 1};
            if ((tri >> (q % 32)) & 1) { /* two triangles */
                int32_t t[6] = {c[0], c[1], c[2], c[0], c[2], c[3]};
                s->fs[f++] = 3; s->fs[f++] = 3;
                memcpy(s->fv + h, t, sizeof t);
                h += 6;
            } else {
                s->fs[f++] = 4;
                memcpy(s->fv + h, c, sizeof c);
                h += 4;
            }
        }
    s->nf = f;
    perturb(r, s);
}

/* Largest fan valence fz_make_fan builds (fuzz_plan lowers it: caps are slow at high n). */
static int fz_fan_max = 66;

static inline void fz_make_fan(rd *r, soup *s) {
    uint8_t b = next(r);
    int k = 3 + b % 64, closed = (b >> 6) & 1;
    if (k > fz_fan_max) k = fz_fan_max; /* clamped: saved inputs keep their meaning */
    int nfaces = closed ? k : k - 1;
    /* center 0, spokes 1..k, corners k+1..2k; quad i = (0, s_i, c_i, s_{i+1}) */
    s->nv = 1 + 2 * k;
    s->pos[0] = s->pos[1] = 0.0; s->pos[2] = 0.3;
    for (int i = 0; i < k; i++) {
        double a = 2 * 3.14159265358979323846 * i / k, a2 = a + 3.14159265358979323846 / k;
        double *p = s->pos + 3 * (1 + i), *q = s->pos + 3 * (1 + k + i);
        p[0] = cos(a); p[1] = sin(a); p[2] = 0.0;
        q[0] = 2 * cos(a2); q[1] = 2 * sin(a2); q[2] = 0.0;
    }
    for (int i = 0; i < nfaces; i++) {
        s->fs[i] = 4;
        s->fv[4 * i + 0] = 0;
        s->fv[4 * i + 1] = 1 + i;
        s->fv[4 * i + 2] = 1 + k + i;
        s->fv[4 * i + 3] = 1 + (i + 1) % k;
    }
    s->nf = nfaces;
    perturb(r, s);
}

static inline void fz_add_edges(rd *r, soup *s) {
    s->ne = next(r) % MAXE;
    int32_t h = 0;
    for (int32_t f = 0; f < s->nf; f++) h += s->fs[f] > 0 ? s->fs[f] : 0;
    for (int32_t i = 0; i < s->ne; i++) {
        uint8_t a = next(r), b = next(r);
        if ((a & 0x80) || h == 0 || s->nf == 0) { /* a raw pair, possibly not an edge */
            s->ev[2 * i] = (int32_t)(a & 0x7f) % (s->nv + 2) - 1;
            s->ev[2 * i + 1] = (int32_t)b % (s->nv + 2) - 1;
        } else { /* corner `a*256+b mod h` of the faces and the next corner of its face */
            int32_t c = (int32_t)((a << 8 | b) % h), f = 0, st = 0;
            while (c >= st + s->fs[f]) { st += s->fs[f] > 0 ? s->fs[f] : 0; f++; }
            int32_t n = s->fs[f], j = c - st;
            s->ev[2 * i] = s->fv[st + j];
            s->ev[2 * i + 1] = s->fv[st + (j + 1) % n];
        }
        s->kn[i] = next_knot(r);
        s->cr[i] = next_crease(r);
    }
    for (int32_t v = 0; v < s->nv && v < MAXV; v++) s->vc[v] = next(r) < 240 ? 0.0 : next_crease(r);
}

/* Builds s from the input: flags & 3 picks the generator, flags & 4 raw doubles. */
static inline void fz_make_cage(rd *r, soup *s, uint8_t flags) {
    memset(s, 0, sizeof *s);
    switch (flags & 3) {
    case 2: fz_make_grid(r, s); break;
    case 3: fz_make_fan(r, s); break;
    default: fz_make_raw(r, s, (flags >> 2) & 1); break;
    }
    fz_add_edges(r, s);
}

static inline int fz_nonfinite(const soup *s) {
    for (int32_t k = 0; k < 3 * s->nv; k++)
        if (!isfinite(s->pos[k]) || fabs(s->pos[k]) > 1e300) return 1; /* both rejected */
    return 0;
}
#endif
