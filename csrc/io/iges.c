/* IGES 5.3 writer of the neutral B-rep (cad.h).
 *
 * Why the B-rep entities and not 144 trimmed surfaces: a 144/142 face carries its own
 * boundary curves, so a reader gets independent faces and must sew them (OpenCASCADE's
 * IGES reader does not sew by default). The 5.3 B-rep class shares topology by index: one
 * 502 vertex list, one 504 edge list whose entries are 126 curves between two listed
 * vertices, and per face a 508 loop of (edge list, index, orientation, pcurve) uses, a 510 face
 * on an untrimmed 128 surface, a 514 shell per connected component (form 1 closed, form 2 open) and,
 * when every side is shared, a 186 manifold solid per shell. OpenCASCADE reads each shell with
 * its faces sharing their edges.
 *
 * Layout: directory entry k (1-based) is on lines 2k-1, 2k; entity order: the vertex list,
 * the edge curves (cut to their segment when a side is split), the edge list, per face
 * (128, a planar 126 pcurve per side segment, 508 with one edge use per side segment, 510), the shells (one per connected
 * component), the solids (one per shell, when every side is shared). Every entity except the
 * top ones (the solids, else the shells) is physically dependent (status 00010000), so those
 * are the only roots a reader transfers. The parameter section is built in memory first (the
 * directory needs each entity's first parameter line and line count).
 */
#include "io/cad.h"

#include "base/error.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct { int32_t type, form, pline, nlines, top; } iges_de;

/* Sequence numbers have 7 columns: a section of more lines is not IGES (a test lowers it). */
#ifndef CCN_IGES_MAX_LINES
#define CCN_IGES_MAX_LINES 9999999
#endif

typedef struct {
    char *buf;       /* parameter lines, 80 chars + '\n' each */
    size_t len, cap;
    int32_t nlines;
    char line[72];   /* the current line's data (64 columns used) */
    int col;
    int32_t de;      /* DE pointer of the entity being written */
    int oom;
    int too_long;    /* more than CCN_IGES_MAX_LINES lines: nothing more is written */
} iges_pd;

static int pd_reserve(iges_pd *p, size_t more) {
    if (p->len + more <= p->cap) return 1;
    size_t cap = p->cap ? p->cap : 65536;
    while (cap < p->len + more) cap *= 2;
    char *b = realloc(p->buf, cap);
    if (!b) { p->oom = 1; return 0; }
    p->buf = b;
    p->cap = cap;
    return 1;
}

static void pd_newline(iges_pd *p) {
    char l[128];
    int col = p->col;
    p->col = 0; /* whatever happens, the next token starts a line: p->line never overflows */
    if (p->nlines >= CCN_IGES_MAX_LINES || p->de > CCN_IGES_MAX_LINES) { p->too_long = 1; return; }
    p->nlines++;
    int n = snprintf(l, sizeof l, "%-64.*s %7dP%7d\n", col, p->line, (int)p->de, (int)p->nlines);
    if (n != 81) { p->too_long = 1; return; }
    if (!pd_reserve(p, 81)) return;
    memcpy(p->buf + p->len, l, 81);
    p->len += 81;
}

/* A token and its delimiter (',' or ';'), never split across lines. */
static void pd_token(iges_pd *p, const char *tok, char delim) {
    if (p->oom || p->too_long) return; /* the export fails; stop writing */
    int n = (int)strlen(tok);
    if (p->col + n + 1 > 64) pd_newline(p);
    memcpy(p->line + p->col, tok, (size_t)n);
    p->col += n;
    p->line[p->col++] = delim;
    if (delim == ';') pd_newline(p);
}

static void pd_int(iges_pd *p, long v) {
    char t[24];
    snprintf(t, sizeof t, "%ld", v);
    pd_token(p, t, ',');
}

static void pd_real(iges_pd *p, double x) {
    char t[32];
    pd_token(p, ccn__cad_real(x, t), ',');
}

/* Ends the entity: the last token's ',' becomes ';'. */
static void pd_end(iges_pd *p) {
    if (p->col > 0 && p->line[p->col - 1] == ',') {
        p->line[p->col - 1] = ';';
        pd_newline(p);
    }
}

static void pd_begin(iges_pd *p, iges_de *de, int32_t k, int32_t type, int32_t form) {
    de[k].type = type;
    de[k].form = form;
    de[k].pline = p->nlines + 1;
    p->de = 2 * k + 1;
    pd_int(p, type);
}

static void pd_finish(iges_pd *p, iges_de *de, int32_t k) {
    pd_end(p);
    de[k].nlines = p->nlines + 1 - de[k].pline;
}

/* A B-spline direction's flat knots. */
static void pd_flat_knots(iges_pd *p, const ccn__cad_surface *f, int d) {
    for (int32_t k = 0; k < f->num_knots[d]; k++)
        for (int32_t r = 0; r < f->mults[d][k]; r++) pd_real(p, f->knots[d][k]);
}

static void curve_126(iges_pd *p, const ccn__cad_curve *c, int closed) {
    int32_t n = c->num_poles;
    pd_int(p, n - 1);
    pd_int(p, c->degree);
    pd_int(p, 0);                     /* PROP1: not known to be planar */
    pd_int(p, closed);                /* PROP2 */
    pd_int(p, 1);                     /* PROP3: polynomial */
    pd_int(p, closed && c->periodic); /* PROP4 */
    for (int32_t i = 0; i < n + c->degree + 1; i++) pd_real(p, c->knots[i]);
    for (int32_t i = 0; i < n; i++) pd_real(p, 1.0);
    for (int32_t i = 0; i < 3 * n; i++) pd_real(p, c->poles[i]);
    pd_real(p, c->knots[c->degree]);
    pd_real(p, c->knots[n]);
    pd_real(p, 0); pd_real(p, 0); pd_real(p, 0); /* normal: unused (not planar) */
}

static void surface_128(iges_pd *p, const ccn__cad_surface *f) {
    int32_t nu = f->num_poles[0], nv = f->num_poles[1];
    pd_int(p, nu - 1);
    pd_int(p, nv - 1);
    pd_int(p, f->degree[0]);
    pd_int(p, f->degree[1]);
    pd_int(p, f->periodic[0]); /* PROP1, PROP2: closed */
    pd_int(p, f->periodic[1]);
    pd_int(p, 1);              /* PROP3: polynomial */
    pd_int(p, f->periodic[0]); /* PROP4, PROP5: periodic */
    pd_int(p, f->periodic[1]);
    pd_flat_knots(p, f, 0);
    pd_flat_knots(p, f, 1);
    for (int32_t i = 0; i < nu * nv; i++) pd_real(p, 1.0);
    for (int32_t j = 0; j < nv; j++) /* u index runs fastest */
        for (int32_t i = 0; i < nu; i++)
            for (int k = 0; k < 3; k++) pd_real(p, f->poles[3 * ((size_t)i * nv + j) + k]);
    for (int d = 0; d < 2; d++) {
        double lo, hi;
        ccn__cad_domain(f, d, &lo, &hi);
        pd_real(p, lo);
        pd_real(p, hi);
    }
}

/* The parameter-space curve of segment j of a face: the straight line in the face's (u, v)
 * along the segment, run in the direction the loop uses it (OpenCASCADE's IGES reader takes a
 * use's curves in the use's direction: a pcurve run along the edge curve instead turns the face
 * over where a closed edge's use runs against it, "Faces were incorrectly oriented"), over the
 * parameters [c0, c1] of the edge curve (the uses are one curve up to an affine change, cad.h):
 * a planar degree-1 126, so that a reader needs no projection to place the edge on the face. */
static void pcurve_126(iges_pd *p, const ccn__cad_model *m, const ccn__cad_topo *t, int32_t j,
                       double c0, double c1) {
    double uv[2][2];
    ccn__cad_segment_ends_uv(m, t, j, 0, uv[0], uv[1]);
    pd_int(p, 1);
    pd_int(p, 1);
    pd_int(p, 1); /* PROP1: planar */
    pd_int(p, 0);
    pd_int(p, 1); /* polynomial */
    pd_int(p, 0);
    pd_real(p, c0); pd_real(p, c0); pd_real(p, c1); pd_real(p, c1);
    pd_real(p, 1.0); pd_real(p, 1.0);
    for (int e = 0; e < 2; e++) { pd_real(p, uv[e][0]); pd_real(p, uv[e][1]); pd_real(p, 0); }
    pd_real(p, c0);
    pd_real(p, c1);
    pd_real(p, 0); pd_real(p, 0); pd_real(p, 1); /* the plane's normal */
}

/* Hollerith string nH... as a token. */
static void holl(char *out, size_t cap, const char *s) { snprintf(out, cap, "%dH%s", (int)strlen(s), s); }

/* "YYYY-MM-DDThh:mm:ss" -> "YYYYMMDD.hhmmss" (IGES 5.3 date); the fixed default otherwise. */
static void iges_date(const char *stamp, char out[16]) {
    char d[15];
    int n = 0;
    for (const char *c = stamp; c && *c && n < 14; c++)
        if (*c >= '0' && *c <= '9') d[n++] = *c;
    if (n != 14) memcpy(d, "20000101000000", 14);
    memcpy(out, d, 8);
    out[8] = '.';
    memcpy(out + 9, d + 8, 6);
    out[15] = '\0';
}

/* Free-format text of the start / global sections as 72-column lines with letter L. */
static void section_lines(ccn__cad_out *o, const char *text, char L, int32_t *count) {
    size_t n = strlen(text);
    for (size_t at = 0; at < n;) {
        size_t k = n - at < 72 ? n - at : 72;
        if (L == 'G' && n - at > 72) /* break after a delimiter where possible */
            for (size_t b = 72; b > 36; b--)
                if (text[at + b - 1] == ',') { k = b; break; }
        ccn__cad_printf(o, "%-72.*s%c%7d\n", (int)k, text + at, L, (int)++*count);
        at += k;
    }
}

static ccn_status build_pd(const ccn__cad_model *m, const ccn__cad_topo *t, iges_pd *p,
                           iges_de *de, ccn__cad_curve *c, double *crange) {
    int32_t E = t->num_edges, F = m->num_faces;
    int32_t k_vl = 0, k_el = 1 + E, k_shell = 2 + E + 3 * F + t->num_segs;
#define DEP(k) (2 * (long)(k) + 1)
/* face f: its 128, a 126 pcurve per side segment, the 508 loop, the 510 face */
#define FACE_K(f) (2 + E + 3 * (f) + t->face_seg[f])
#define FACE_510(f) (FACE_K(f) + 2 + t->face_seg[(f) + 1] - t->face_seg[f])
    pd_begin(p, de, k_vl, 502, 1);
    pd_int(p, t->num_verts);
    for (int32_t v = 0; v < 3 * t->num_verts; v++) pd_real(p, t->vert_pos[v]);
    pd_finish(p, de, k_vl);
    for (int32_t e = 0; e < E; e++) {
        pd_begin(p, de, 1 + e, 126, 0);
        ccn__cad_segment_curve(m, t, t->edge_seg[e], c);
        curve_126(p, c, t->edge_vert[2 * e] == t->edge_vert[2 * e + 1]);
        crange[2 * e] = c->knots[c->degree];
        crange[2 * e + 1] = c->knots[c->num_poles];
        pd_finish(p, de, 1 + e);
    }
    pd_begin(p, de, k_el, 504, 1);
    pd_int(p, E);
    for (int32_t e = 0; e < E; e++) {
        pd_int(p, DEP(1 + e));
        pd_int(p, DEP(k_vl));
        pd_int(p, t->edge_vert[2 * e] + 1);
        pd_int(p, DEP(k_vl));
        pd_int(p, t->edge_vert[2 * e + 1] + 1);
    }
    pd_finish(p, de, k_el);
    for (int32_t f = 0; f < F; f++) {
        int32_t ks = FACE_K(f), j0 = t->face_seg[f], nj = t->face_seg[f + 1] - j0;
        pd_begin(p, de, ks, 128, 0);
        surface_128(p, &m->faces[f]);
        pd_finish(p, de, ks);
        for (int32_t j = j0; j < j0 + nj; j++) {
            int32_t e = t->seg_edge[j];
            pd_begin(p, de, ks + 1 + (j - j0), 126, 1);
            pcurve_126(p, m, t, j, crange[2 * e], crange[2 * e + 1]);
            pd_finish(p, de, ks + 1 + (j - j0));
        }
        pd_begin(p, de, ks + 1 + nj, 508, 1);
        pd_int(p, nj);
        for (int32_t j = j0; j < j0 + nj; j++) {
            pd_int(p, 0); /* an edge */
            pd_int(p, DEP(k_el));
            pd_int(p, t->seg_edge[j] + 1);
            pd_int(p, t->seg_sense[j]);
            pd_int(p, 1); /* one parameter-space curve, */
            pd_int(p, 1); /* isoparametric */
            pd_int(p, DEP(ks + 1 + (j - j0)));
        }
        pd_finish(p, de, ks + 1 + nj);
        pd_begin(p, de, ks + 2 + nj, 510, 1);
        pd_int(p, DEP(ks));
        pd_int(p, 1);
        pd_int(p, 1); /* the loop is the outer one */
        pd_int(p, DEP(ks + 1 + nj));
        pd_finish(p, de, ks + 2 + nj);
    }
    /* one 514 per connected component, then (every side shared) a 186 solid per shell; the
     * shells, or the solids, are the file's roots */
    int32_t S = t->num_shells;
    for (int32_t sh = 0; sh < S; sh++) {
        int32_t k = k_shell + sh;
        pd_begin(p, de, k, 514, t->shell_closed[sh] ? 1 : 2);
        pd_int(p, t->shell_start[sh + 1] - t->shell_start[sh]);
        for (int32_t q = t->shell_start[sh]; q < t->shell_start[sh + 1]; q++) {
            pd_int(p, DEP(FACE_510(t->shell_face[q])));
            pd_int(p, 1); /* the face normal is the surface normal Su x Sv */
        }
        pd_finish(p, de, k);
        de[k].top = !t->closed;
    }
    for (int32_t sh = 0; t->closed && sh < S; sh++) {
        int32_t k = k_shell + S + sh;
        pd_begin(p, de, k, 186, 0);
        pd_int(p, DEP(k_shell + sh));
        pd_int(p, 1); /* the shell's face normals point out of the solid */
        pd_int(p, 0); /* no void shells */
        pd_finish(p, de, k);
        de[k].top = 1;
    }
#undef DEP
#undef FACE_K
#undef FACE_510
    return p->oom ? CCN_ERR_MEMORY : p->too_long ? CCN_ERR_ARGUMENT : CCN_OK;
}

ccn_status ccn__iges_write(const ccn__cad_model *m, ccn__cad_write_fn fn, void *user,
                           ccn_error *err) {
    if (!fn) return ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1, "write callback is NULL");
    ccn__cad_topo t;
    ccn_status st = ccn__cad_topo_build(m, &t, err);
    if (st) return st;
    int32_t maxp = 0;
    double maxc = 0;
    for (int32_t f = 0; f < m->num_faces; f++) {
        const ccn__cad_surface *s = &m->faces[f];
        int32_t cap = ccn__cad_curve_capacity(s);
        maxp = cap > maxp ? cap : maxp;
        for (size_t i = 0; i < 3 * (size_t)s->num_poles[0] * (size_t)s->num_poles[1]; i++)
            maxc = s->poles[i] > maxc ? s->poles[i] : -s->poles[i] > maxc ? -s->poles[i] : maxc;
    }
    int32_t nde = 2 + t.num_edges + 3 * m->num_faces + t.num_segs + (t.closed ? 2 : 1) * t.num_shells;
    iges_de *de = calloc((size_t)nde, sizeof *de);
    double *crange = malloc(sizeof(double) * 2 * ((size_t)t.num_edges + 1));
    double *pts = malloc(sizeof(double) * (4 * (size_t)maxp + CCN_CAD_MAX_DEGREE + 1));
    ccn__cad_curve c = {0, 0, pts + 3 * (size_t)maxp, pts, 0}; /* poles, then knots */
    iges_pd *p = calloc(1, sizeof *p);
    ccn__cad_out *o = malloc(sizeof *o);
    ccn_status bs = de && pts && p && o && crange ? build_pd(m, &t, p, de, &c, crange) : CCN_ERR_MEMORY;
    if (bs == CCN_OK && 2 * (int64_t)nde > CCN_IGES_MAX_LINES) bs = CCN_ERR_ARGUMENT;
    if (bs == CCN_ERR_ARGUMENT) {
        st = ccn__fail(err, CCN_ERR_ARGUMENT, CCN_ELEM_NONE, -1,
                       "the IGES file of this surface (%d faces) needs a section of more than %d lines, "
                       "which its 7-digit sequence numbers cannot count: export STEP, or the packed "
                       "export, or a coarser surface",
                       (int)m->num_faces, (int)CCN_IGES_MAX_LINES);
        goto done;
    }
    if (bs != CCN_OK) {
        st = ccn__fail(err, CCN_ERR_MEMORY, CCN_ELEM_NONE, -1, "out of memory");
        goto done;
    }
    ccn__cad_out_init(o, fn, user);
    int32_t ns = 0, ng = 0;
    const char *name = m->name ? m->name : "ccnurbs";
    char text[2048], date[16], h[4][256], r1[32], r2[32];
    snprintf(text, sizeof text, "%s: exact limit surface written by ccnurbs %d.%d", name,
             CCN_VERSION_MAJOR, CCN_VERSION_MINOR);
    section_lines(o, text, 'S', &ns);
    iges_date(m->timestamp, date);
    holl(h[0], sizeof h[0], name);
    snprintf(h[1], sizeof h[1], "7Hccnurbs");
    snprintf(h[2], sizeof h[2], "3H%d.%d", CCN_VERSION_MAJOR, CCN_VERSION_MINOR);
    holl(h[3], sizeof h[3], date);
    snprintf(text, sizeof text,
             "1H,,1H;,%s,%s,%s,%s,32,38,6,308,15,%s,1.,2,2HMM,1,1.,%s,%s,%s,,,11,0,%s;", h[0], h[0],
             h[1], h[2], h[0], h[3], ccn__cad_real(t.tolerance, r1), ccn__cad_real(maxc, r2), h[3]);
    section_lines(o, text, 'G', &ng);
    for (int32_t k = 0; k < nde; k++) {
        const char *status = de[k].top ? "00000000" : "00010000";
        ccn__cad_printf(o, "%8d%8d%8d%8d%8d%8d%8d%8d%8sD%7d\n", (int)de[k].type, (int)de[k].pline, 0, 0, 0, 0,
                        0, 0, status, (int)(2 * k + 1));
        ccn__cad_printf(o, "%8d%8d%8d%8d%8d%8s%8s%8s%8dD%7d\n", (int)de[k].type, 0, 0, (int)de[k].nlines,
                        (int)de[k].form, "", "", "", 0, (int)(2 * k + 2));
    }
    ccn__cad_write(o, p->buf, p->len);
    ccn__cad_printf(o, "S%7dG%7dD%7dP%7d%40sT%7d\n", (int)ns, (int)ng, (int)(2 * nde), (int)p->nlines, "", 1);
    if (ccn__cad_flush(o))
        st = ccn__fail(err, CCN_ERR_IO, CCN_ELEM_NONE, -1, "writing the IGES file failed");
done:
    if (p) free(p->buf);
    free(p); free(de); free(pts); free(o); free(crange);
    ccn__cad_topo_free(&t);
    return st;
}
