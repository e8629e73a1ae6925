/* objdiff: compares two OBJ meshes whose vertex and face order may differ (test oracle).
 *
 *   objdiff [--tol-rel T] [--normals T] [--uv T] [--ignore-loose] a.obj b.obj
 *
 * Needs equal vertex and face counts. Every vertex of a is matched to the nearest vertex of
 * b (k-d tree); the match must be a bijection. The error is max |a_i - b_match(i)| divided
 * by the bounding-box diagonal of a (1 if that is 0). Faces of a, renumbered through the
 * match, must equal the faces of b as a multiset of cyclic sequences (any face order, any
 * rotation, same orientation).
 * Coincident vertices: b-vertices within 1e-12 of the diagonal of each other (e.g. the face
 * points of two faces on the same vertices, as in OpenSubdiv's catmark_val2_back2back) form
 * one group, which position cannot tell apart. The bijection is then checked per group (as
 * many a-vertices matched into it as it has members), faces are compared as cycles of group
 * ids, and a normal is compared with the nearest normal of its group. Without such groups
 * this is the plain check above.
 * Prints one line to stdout ("ok: ..." or "FAIL: ..."). Exit 0 if error <= T (default 1e-9)
 * and faces match, 1 otherwise, 2 on usage/parse errors or count mismatch.
 * Only `v` and `f` lines are read (1-based or negative indices, `a/b/c` tolerated), and
 * with --normals T also `vn` lines: each file needs one `vn` per `v` (the i-th belongs to the
 * i-th vertex, as `ccnurbs limit` and `osd_refine --limit-normals` write them); for every
 * matched pair whose normals are both non-zero the unit normals must differ by <= T (length
 * of the difference); a zero normal (`vn 0 0 0`: undefined there) is skipped and counted.
 * With --uv T also `vt` lines and each face corner's texture index (`f v/vt[/vn]`, every
 * corner of both files needs one): matched faces are compared corner by corner (the corners
 * the face match pairs), the largest component difference divided by the diagonal of the
 * bounding box of a's `vt` values (1 if that is 0) must be <= T. Among faces that are equal as
 * cycles (coincident vertex groups), each face of a is paired with the face of b whose values
 * are nearest.
 * With --ignore-loose, vertices no face uses (and their `vn` lines) are dropped from both files
 * first: a limit mesh has no point for a loose vertex, a refined one may keep it.
 */
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    const char *path;
    int nv, nf;
    double *pos;  /* 3*nv */
    double *nrm;  /* 3*nn */
    int nn;
    int *fsize;   /* nf */
    int *foff;    /* nf */
    int *fverts;  /* sum fsize, 0-based */
    long nfv;
    double *uv;   /* 3*nuv (padded with 0) */
    int nuv;
    int *fuv;     /* per face corner: 0-based texture index, -1 if none */
} Mesh;

static _Noreturn void die(const char *fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    fputs("objdiff: ", stderr);
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
    va_end(ap);
    exit(2);
}

static void *xrealloc(void *p, size_t n) {
    void *q = realloc(p, n ? n : 1);
    if (!q) die("out of memory");
    return q;
}

static char *read_file(const char *path, size_t *len) {
    FILE *f = fopen(path, "rb");
    if (!f) die("cannot open %s: %s", path, strerror(errno));
    size_t cap = 1 << 16, n = 0;
    char *buf = xrealloc(NULL, cap);
    for (;;) {
        if (n + 1 >= cap) buf = xrealloc(buf, cap *= 2);
        size_t got = fread(buf + n, 1, cap - n - 1, f);
        n += got;
        if (got == 0) break;
    }
    if (ferror(f)) die("read error on %s", path);
    fclose(f);
    buf[n] = '\0';
    *len = n;
    return buf;
}

static int is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

static void parse_obj(const char *path, Mesh *m) {
    size_t len;
    char *text = read_file(path, &len);
    int capv = 0, capf = 0;
    long capfv = 0;
    memset(m, 0, sizeof *m);
    m->path = path;
    long lineno = 0;
    char *p = text;
    while (*p) {
        char *eol = strchr(p, '\n');
        char *next = eol ? eol + 1 : p + strlen(p);
        if (eol) *eol = '\0';
        lineno++;
        while (is_space(*p)) p++;
        if (p[0] == 'v' && p[1] == 't' && is_space(p[2])) {
            if (m->nuv % 1024 == 0) m->uv = xrealloc(m->uv, sizeof(double) * 3 * ((size_t)m->nuv + 1024));
            char *s = p + 2;
            for (int k = 0; k < 3; k++) {
                char *end;
                double x = strtod(s, &end);
                if (end == s) {
                    if (k == 0) die("%s:%ld: bad texture line", path, lineno);
                    x = 0.0;
                } else if (!isfinite(x)) die("%s:%ld: bad texture line", path, lineno);
                m->uv[3 * m->nuv + k] = x;
                s = end;
            }
            m->nuv++;
        } else if (p[0] == 'v' && p[1] == 'n' && is_space(p[2])) {
            if (m->nn % 1024 == 0) m->nrm = xrealloc(m->nrm, sizeof(double) * 3 * ((size_t)m->nn + 1024));
            char *s = p + 2;
            for (int k = 0; k < 3; k++) {
                char *end;
                double x = strtod(s, &end);
                if (end == s || !isfinite(x)) die("%s:%ld: bad normal line", path, lineno);
                m->nrm[3 * m->nn + k] = x;
                s = end;
            }
            m->nn++;
        } else if (p[0] == 'v' && is_space(p[1])) {
            if (m->nv == capv) {
                capv = capv ? 2 * capv : 1024;
                m->pos = xrealloc(m->pos, sizeof(double) * 3 * (size_t)capv);
            }
            char *s = p + 1;
            for (int k = 0; k < 3; k++) {
                char *end;
                double x = strtod(s, &end);
                if (end == s || !isfinite(x)) die("%s:%ld: bad vertex line", path, lineno);
                m->pos[3 * m->nv + k] = x;
                s = end;
            }
            m->nv++;
        } else if (p[0] == 'f' && is_space(p[1])) {
            if (m->nf == capf) {
                capf = capf ? 2 * capf : 1024;
                m->fsize = xrealloc(m->fsize, sizeof(int) * (size_t)capf);
                m->foff = xrealloc(m->foff, sizeof(int) * (size_t)capf);
            }
            char *s = p + 1;
            int n = 0;
            for (;;) {
                while (is_space(*s)) s++;
                if (!*s) break;
                char *end;
                errno = 0;
                long idx = strtol(s, &end, 10);
                if (end == s || errno) die("%s:%ld: bad face index", path, lineno);
                if (idx < 0) idx = m->nv + idx + 1;
                if (idx < 1 || idx > 2000000000L) die("%s:%ld: face index out of range", path, lineno);
                s = end;
                long uv = 0;
                if (*s == '/' && s[1] != '/' && !is_space(s[1]) && s[1]) {
                    char *e2;
                    uv = strtol(s + 1, &e2, 10);
                    if (e2 == s + 1 || uv == 0) die("%s:%ld: bad texture index", path, lineno);
                    if (uv < 0) uv = m->nuv + uv + 1;
                }
                while (*s && !is_space(*s)) s++; /* skip /vt/vn */
                if (m->nfv == capfv) {
                    capfv = capfv ? 2 * capfv : 4096;
                    m->fverts = xrealloc(m->fverts, sizeof(int) * (size_t)capfv);
                    m->fuv = xrealloc(m->fuv, sizeof(int) * (size_t)capfv);
                }
                m->fuv[m->nfv] = (int)uv - 1;
                m->fverts[m->nfv++] = (int)(idx - 1);
                n++;
            }
            if (n < 3) die("%s:%ld: face with fewer than 3 vertices", path, lineno);
            m->fsize[m->nf] = n;
            m->foff[m->nf] = (int)(m->nfv - n);
            m->nf++;
        }
        p = next;
    }
    for (long i = 0; i < m->nfv; i++)
        if (m->fverts[i] >= m->nv) die("%s: face index %ld beyond vertex count %d", path, (long)m->fverts[i] + 1, m->nv);
    free(text);
}

/* ---- k-d tree over the vertices of b (implicit, balanced, median splits) ---- */
typedef struct {
    const double *pos;
    int *idx;     /* permutation of points */
    char *axis;   /* split axis at node (stored at the median slot) */
} KdTree;

static void kd_select(KdTree *t, int lo, int hi, int k, int ax) {
    /* quickselect on idx[lo..hi) so that idx[k] is the k-th by coordinate ax */
    while (hi - lo > 1) {
        int mid = lo + (hi - lo) / 2;
        double a = t->pos[3 * t->idx[lo] + ax], b = t->pos[3 * t->idx[mid] + ax],
               c = t->pos[3 * t->idx[hi - 1] + ax];
        double piv = (a < b) ? ((b < c) ? b : (a < c ? c : a)) : ((a < c) ? a : (b < c ? c : b));
        int i = lo, j = hi - 1;
        while (i <= j) {
            while (t->pos[3 * t->idx[i] + ax] < piv) i++;
            while (t->pos[3 * t->idx[j] + ax] > piv) j--;
            if (i <= j) {
                int tmp = t->idx[i];
                t->idx[i] = t->idx[j];
                t->idx[j] = tmp;
                i++;
                j--;
            }
        }
        if (k <= j) hi = j + 1;
        else if (k >= i) lo = i;
        else return;
    }
}

static void kd_build(KdTree *t, int lo, int hi) {
    while (hi - lo > 1) {
        double mn[3], mx[3];
        for (int k = 0; k < 3; k++) mn[k] = mx[k] = t->pos[3 * t->idx[lo] + k];
        for (int i = lo + 1; i < hi; i++)
            for (int k = 0; k < 3; k++) {
                double x = t->pos[3 * t->idx[i] + k];
                if (x < mn[k]) mn[k] = x;
                if (x > mx[k]) mx[k] = x;
            }
        int ax = 0;
        for (int k = 1; k < 3; k++)
            if (mx[k] - mn[k] > mx[ax] - mn[ax]) ax = k;
        int mid = lo + (hi - lo) / 2;
        kd_select(t, lo, hi, mid, ax);
        t->axis[mid] = (char)ax;
        kd_build(t, lo, mid);
        lo = mid + 1;
    }
    if (hi - lo == 1) t->axis[lo] = 0;
}

static void kd_nearest(const KdTree *t, int lo, int hi, const double *q, int *best, double *bestd2) {
    while (hi > lo) {
        int mid = lo + (hi - lo) / 2;
        const double *p = t->pos + 3 * t->idx[mid];
        double dx = q[0] - p[0], dy = q[1] - p[1], dz = q[2] - p[2];
        double d2 = dx * dx + dy * dy + dz * dz;
        if (d2 < *bestd2 || (d2 == *bestd2 && t->idx[mid] < *best)) {
            *bestd2 = d2;
            *best = t->idx[mid];
        }
        if (hi - lo == 1) return;
        int ax = t->axis[mid];
        double diff = q[ax] - p[ax];
        int nlo, nhi, flo, fhi; /* near and far halves */
        if (diff < 0) { nlo = lo; nhi = mid; flo = mid + 1; fhi = hi; }
        else { nlo = mid + 1; nhi = hi; flo = lo; fhi = mid; }
        kd_nearest(t, nlo, nhi, q, best, bestd2);
        if (diff * diff > *bestd2) return;
        lo = flo;
        hi = fhi;
    }
}

/* Every point of the tree within squared distance r2 of q: out[(*n)++] (caller sizes out). */
static void kd_radius(const KdTree *t, int lo, int hi, const double *q, double r2, int *out, int *n) {
    while (hi > lo) {
        int mid = lo + (hi - lo) / 2;
        const double *p = t->pos + 3 * t->idx[mid];
        double dx = q[0] - p[0], dy = q[1] - p[1], dz = q[2] - p[2];
        if (dx * dx + dy * dy + dz * dz <= r2) out[(*n)++] = t->idx[mid];
        if (hi - lo == 1) return;
        int ax = t->axis[mid];
        double diff = q[ax] - p[ax];
        if (diff <= 0 || diff * diff <= r2) kd_radius(t, lo, mid, q, r2, out, n);
        if (diff >= 0 || diff * diff <= r2) { lo = mid + 1; continue; }
        return;
    }
}

static int uf_find(int *parent, int x) {
    while (parent[x] != x) {
        parent[x] = parent[parent[x]];
        x = parent[x];
    }
    return x;
}

/* ---- faces as canonical cyclic sequences ---- */
typedef struct {
    int n;
    const int *v; /* canonical rotation, n entries */
    int idx, r;   /* the face's index and the corner the canonical rotation starts at */
} Face;

static int face_cmp(const void *x, const void *y) {
    const Face *a = x, *b = y;
    if (a->n != b->n) return a->n < b->n ? -1 : 1;
    for (int i = 0; i < a->n; i++)
        if (a->v[i] != b->v[i]) return a->v[i] < b->v[i] ? -1 : 1;
    return 0;
}

/* Writes each face (vertex ids through map, then through group, if given) at its
 * lexicographically smallest rotation (the smallest id first when ids are distinct). */
static Face *canon_faces(const Mesh *m, const int *map, const int *group, int **store) {
    Face *f = xrealloc(NULL, sizeof(Face) * (size_t)m->nf);
    int *s = xrealloc(NULL, sizeof(int) * (size_t)m->nfv);
    for (int i = 0; i < m->nf; i++) {
        int n = m->fsize[i], off = m->foff[i], r = 0;
        const int *src = m->fverts + off;
        int *ids = s + off;
        for (int k = 0; k < n; k++) {
            int v = map ? map[src[k]] : src[k];
            ids[k] = group ? group[v] : v;
        }
        for (int c = 1; c < n; c++) {
            for (int k = 0; k < n; k++) {
                int x = ids[(c + k) % n], y = ids[(r + k) % n];
                if (x != y) {
                    if (x < y) r = c;
                    break;
                }
            }
        }
        int tmp[64], *rot = n <= 64 ? tmp : xrealloc(NULL, sizeof(int) * (size_t)n);
        for (int k = 0; k < n; k++) rot[k] = ids[(r + k) % n];
        memcpy(ids, rot, sizeof(int) * (size_t)n);
        if (rot != tmp) free(rot);
        f[i].n = n;
        f[i].v = s + off;
        f[i].idx = i;
        f[i].r = r;
    }
    *store = s;
    return f;
}

/* Largest component difference of the corner values of face fa of a and fb of b. */
static double face_uv_diff(const Mesh *a, const Face *fa, const Mesh *b, const Face *fb) {
    double d = 0.0;
    for (int k = 0; k < fa->n; k++) {
        int ta = a->fuv[a->foff[fa->idx] + (fa->r + k) % fa->n];
        int tb = b->fuv[b->foff[fb->idx] + (fb->r + k) % fb->n];
        for (int c = 0; c < 3; c++) {
            double x = fabs(a->uv[3 * ta + c] - b->uv[3 * tb + c]);
            if (!(x <= d)) d = x;
        }
    }
    return d;
}

static void check_uvs(const Mesh *m) {
    for (long i = 0; i < m->nfv; i++)
        if (m->fuv[i] < 0 || m->fuv[i] >= m->nuv)
            die("%s: --uv needs a texture index in [1, %d] at every face corner (corner %ld has %d)",
                m->path, m->nuv, i + 1, m->fuv[i] + 1);
}

/* Unit vector of n (3 doubles) into u; returns 0 for a zero vector. */
/* Drops the vertices no face uses (and their normals), renumbering the faces. */
static void drop_loose(Mesh *m) {
    int *to = xrealloc(NULL, sizeof(int) * (size_t)(m->nv ? m->nv : 1));
    for (int i = 0; i < m->nv; i++) to[i] = -1;
    for (long k = 0; k < m->nfv; k++) to[m->fverts[k]] = 0;
    int n = 0;
    for (int i = 0; i < m->nv; i++) {
        if (to[i] < 0) continue;
        to[i] = n;
        memmove(m->pos + 3 * n, m->pos + 3 * i, sizeof(double) * 3);
        if (m->nn == m->nv) memmove(m->nrm + 3 * n, m->nrm + 3 * i, sizeof(double) * 3);
        n++;
    }
    for (long k = 0; k < m->nfv; k++) m->fverts[k] = to[m->fverts[k]];
    if (m->nn == m->nv) m->nn = n;
    m->nv = n;
    free(to);
}

static int unit(const double *n, double *u) {
    double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (!(len > 0)) return 0;
    for (int k = 0; k < 3; k++) u[k] = n[k] / len;
    return 1;
}

int main(int argc, char **argv) {
    double tol = 1e-9, ntol = -1.0, utol = -1.0;
    int loose = 0;
    const char *pa = NULL, *pb = NULL;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--tol-rel") && i + 1 < argc) {
            char *end;
            tol = strtod(argv[++i], &end);
            if (*end || !(tol >= 0)) die("bad --tol-rel '%s'", argv[i]);
        } else if (!strcmp(argv[i], "--uv") && i + 1 < argc) {
            char *end;
            utol = strtod(argv[++i], &end);
            if (*end || !(utol >= 0)) die("bad --uv '%s'", argv[i]);
        } else if (!strcmp(argv[i], "--normals") && i + 1 < argc) {
            char *end;
            ntol = strtod(argv[++i], &end);
            if (*end || !(ntol >= 0)) die("bad --normals '%s'", argv[i]);
        } else if (!strcmp(argv[i], "--ignore-loose")) {
            loose = 1;
        } else if (argv[i][0] == '-' && argv[i][1]) {
            die("usage: objdiff [--tol-rel T] [--normals T] a.obj b.obj (unknown option %s)", argv[i]);
        } else if (!pa) pa = argv[i];
        else if (!pb) pb = argv[i];
        else die("usage: objdiff [--tol-rel T] [--normals T] a.obj b.obj");
    }
    if (!pa || !pb) die("usage: objdiff [--tol-rel T] [--normals T] a.obj b.obj");

    Mesh a, b;
    parse_obj(pa, &a);
    parse_obj(pb, &b);
    if (loose) drop_loose(&a), drop_loose(&b);
    if (ntol >= 0 && (a.nn != a.nv || b.nn != b.nv)) {
        printf("FAIL: --normals needs one vn per v: %s has %d v %d vn, %s has %d v %d vn\n", pa, a.nv,
               a.nn, pb, b.nv, b.nn);
        return 2;
    }
    if (a.nv != b.nv || a.nf != b.nf) {
        fprintf(stderr, "objdiff: count mismatch: %s has %d verts %d faces, %s has %d verts %d faces\n",
                pa, a.nv, a.nf, pb, b.nv, b.nf);
        printf("FAIL: count mismatch: %d/%d verts, %d/%d faces\n", a.nv, b.nv, a.nf, b.nf);
        return 2;
    }
    if (a.nv == 0) {
        printf("ok: empty meshes\n");
        return 0;
    }

    /* bounding-box diagonal of a */
    double mn[3], mx[3];
    for (int k = 0; k < 3; k++) mn[k] = mx[k] = a.pos[k];
    for (int i = 1; i < a.nv; i++)
        for (int k = 0; k < 3; k++) {
            double x = a.pos[3 * i + k];
            if (x < mn[k]) mn[k] = x;
            if (x > mx[k]) mx[k] = x;
        }
    double diag = sqrt((mx[0] - mn[0]) * (mx[0] - mn[0]) + (mx[1] - mn[1]) * (mx[1] - mn[1]) +
                       (mx[2] - mn[2]) * (mx[2] - mn[2]));
    if (!(diag > 0)) diag = 1.0;

    KdTree t;
    t.pos = b.pos;
    t.idx = xrealloc(NULL, sizeof(int) * (size_t)b.nv);
    t.axis = xrealloc(NULL, (size_t)b.nv);
    for (int i = 0; i < b.nv; i++) t.idx[i] = i;
    kd_build(&t, 0, b.nv);

    /* groups of coincident b-vertices (union-find; the root is the smallest index) */
    int *group = xrealloc(NULL, sizeof(int) * (size_t)b.nv);
    int *gsize = calloc((size_t)b.nv, sizeof(int));
    int *gnext = xrealloc(NULL, sizeof(int) * (size_t)b.nv); /* next member of the group, -1 */
    int *near = xrealloc(NULL, sizeof(int) * (size_t)b.nv);
    if (!gsize) die("out of memory");
    for (int j = 0; j < b.nv; j++) group[j] = j;
    const double cr = 1e-12 * diag;
    for (int j = 0; j < b.nv; j++) {
        int nn = 0;
        kd_radius(&t, 0, b.nv, b.pos + 3 * j, cr * cr, near, &nn);
        for (int k = 0; k < nn; k++) {
            int x = uf_find(group, j), y = uf_find(group, near[k]);
            if (x < y) group[y] = x;
            else if (y < x) group[x] = y;
        }
    }
    int ngroups = 0; /* groups with more than one member */
    for (int j = b.nv - 1; j >= 0; j--) {
        group[j] = uf_find(group, j);
        gnext[j] = -1;
    }
    {
        int *last = xrealloc(NULL, sizeof(int) * (size_t)b.nv);
        for (int j = 0; j < b.nv; j++) last[j] = -1;
        for (int j = 0; j < b.nv; j++) {
            int g = group[j];
            if (gsize[g]++ == 1) ngroups++;
            if (last[g] >= 0) gnext[last[g]] = j;
            last[g] = j;
        }
        free(last);
    }
    free(near);

    int *map = xrealloc(NULL, sizeof(int) * (size_t)a.nv);
    int *used = calloc((size_t)b.nv, sizeof(int));
    if (!used) die("out of memory");
    double worst = -1.0;
    int worst_i = 0, dup = 0, first_dup = -1;
    for (int i = 0; i < a.nv; i++) {
        int best = -1;
        double bestd2 = INFINITY;
        kd_nearest(&t, 0, b.nv, a.pos + 3 * i, &best, &bestd2);
        map[i] = best;
        if (++used[group[best]] > gsize[group[best]]) {
            dup++;
            if (first_dup < 0) first_dup = i;
        }
        double d = sqrt(bestd2);
        if (d > worst) {
            worst = d;
            worst_i = i;
        }
    }
    double rel = worst / diag;

    /* faces */
    int *sa, *sb;
    Face *fa = canon_faces(&a, map, group, &sa), *fb = canon_faces(&b, NULL, group, &sb);
    qsort(fa, (size_t)a.nf, sizeof(Face), face_cmp);
    qsort(fb, (size_t)b.nf, sizeof(Face), face_cmp);
    int missing = 0, ia = 0, ib = 0;
    const Face *first_missing = NULL;
    double uworst = 0.0;
    int uworst_f = -1;
    if (utol >= 0) { check_uvs(&a); check_uvs(&b); }
    while (ia < a.nf && ib < b.nf) {
        int c = face_cmp(&fa[ia], &fb[ib]);
        if (c == 0 && utol >= 0) { /* a run of equal faces: pair by nearest values */
            int ea = ia, eb = ib;
            while (ea < a.nf && face_cmp(&fa[ea], &fa[ia]) == 0) ea++;
            while (eb < b.nf && face_cmp(&fb[eb], &fb[ib]) == 0) eb++;
            char *taken = calloc((size_t)(eb - ib), 1);
            if (!taken) die("out of memory");
            for (int x = ia; x < ea; x++) {
                int best = -1;
                double bd = INFINITY;
                for (int y = ib; y < eb; y++) {
                    if (taken[y - ib]) continue;
                    double d = face_uv_diff(&a, &fa[x], &b, &fb[y]);
                    if (best < 0 || d < bd) { best = y; bd = d; }
                }
                if (best < 0) { if (!first_missing) first_missing = &fa[x]; missing++; continue; }
                taken[best - ib] = 1;
                if (bd > uworst || uworst_f < 0) { uworst = bd; uworst_f = fa[x].idx; }
            }
            free(taken);
            ia = ea;
            ib = eb;
        } else if (c == 0) { ia++; ib++; }
        else if (c < 0) { if (!first_missing) first_missing = &fa[ia]; missing++; ia++; }
        else ib++;
    }
    if (ia < a.nf && !first_missing) first_missing = &fa[ia];
    missing += a.nf - ia;

    /* normals of matched vertices */
    int ncmp = 0, nskip = 0, nworst_i = -1;
    double nworst = 0.0;
    char ntext[160] = "";
    if (ntol >= 0) {
        for (int i = 0; i < a.nv; i++) {
            double ua[3], ub[3], d = INFINITY;
            int zero = !unit(a.nrm + 3 * i, ua);
            for (int j = group[map[i]]; j >= 0 && !zero; j = gnext[j]) {
                if (!unit(b.nrm + 3 * j, ub)) { zero = 1; break; }
                double dj = sqrt((ua[0] - ub[0]) * (ua[0] - ub[0]) + (ua[1] - ub[1]) * (ua[1] - ub[1]) +
                                 (ua[2] - ub[2]) * (ua[2] - ub[2]));
                if (dj < d) d = dj;
            }
            if (zero) { nskip++; continue; }
            ncmp++;
            if (d > nworst || nworst_i < 0) { nworst = d; nworst_i = i; }
        }
        snprintf(ntext, sizeof ntext, ", normals %d compared (%d zero, skipped), max_diff %.3g", ncmp,
                 nskip, nworst);
    }
    double udiag = 1.0;
    if (utol >= 0 && a.nuv > 0) {
        double lo[3], hi[3];
        for (int k = 0; k < 3; k++) lo[k] = hi[k] = a.uv[k];
        for (int i = 1; i < a.nuv; i++)
            for (int k = 0; k < 3; k++) {
                if (a.uv[3 * i + k] < lo[k]) lo[k] = a.uv[3 * i + k];
                if (a.uv[3 * i + k] > hi[k]) hi[k] = a.uv[3 * i + k];
            }
        double d = sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                        (hi[2] - lo[2]) * (hi[2] - lo[2]));
        if (d > 0) udiag = d;
    }
    double urel = uworst / udiag;
    if (utol >= 0) {
        size_t l = strlen(ntext);
        snprintf(ntext + l, sizeof ntext - l, ", uv max_rel %.3g", urel);
    }
    if (ngroups) {
        size_t l = strlen(ntext);
        snprintf(ntext + l, sizeof ntext - l, ", %d coincident vertex group(s)", ngroups);
    }
    int nok = ntol < 0 || nworst <= ntol;
    int uok = utol < 0 || urel <= utol;
    int ok = rel <= tol && dup == 0 && missing == 0 && nok && uok;
    if (ok) {
        printf("ok: %d verts, %d faces, max_rel %.3g%s\n", a.nv, a.nf, rel, ntext);
        return 0;
    }
    const double *p = a.pos + 3 * worst_i, *q = b.pos + 3 * map[worst_i];
    printf("FAIL: %d verts, %d faces, max_rel %.3g%s", a.nv, a.nf, rel, ntext);
    if (!(rel <= tol))
        printf(" > tol %.3g at a-vertex %d (%.17g %.17g %.17g) vs b-vertex %d (%.17g %.17g %.17g)",
               tol, worst_i + 1, p[0], p[1], p[2], map[worst_i] + 1, q[0], q[1], q[2]);
    if (!nok) {
        const double *na = a.nrm + 3 * nworst_i, *nb = b.nrm + 3 * map[nworst_i];
        printf("; normal > tol %.3g at a-vertex %d (%.17g %.17g %.17g) vs b-vertex %d (%.17g %.17g %.17g)",
               ntol, nworst_i + 1, na[0], na[1], na[2], map[nworst_i] + 1, nb[0], nb[1], nb[2]);
    }
    if (!uok) printf("; uv > tol %.3g at a-face %d", utol, uworst_f + 1);
    if (dup) printf("; not a bijection: %d b-vertices (or group members) matched more than once (a-vertex %d)", dup, first_dup + 1);
    if (missing) {
        printf("; %d of %d faces of a not in b (e.g. b-vertices", missing, a.nf);
        for (int k = 0; k < first_missing->n; k++) printf(" %d", first_missing->v[k] + 1);
        printf(")");
    }
    printf("\n");
    return 1;
}
