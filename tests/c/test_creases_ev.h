/* test_creases.c part 5: extraordinary vertices on and next to creases (included once). */

/* A cube of 6 quads; sharp edges given as vertex pairs. */
static const double cube_p[24] = {-1, -1, -1, 1, -1, -1, 1, 1, -1, -1, 1, -1,
                                  -1, -1, 1,  1, -1, 1,  1, 1, 1,  -1, 1, 1};
static const int32_t cube_f[24] = {0, 3, 2, 1, 4, 5, 6, 7, 0, 1, 5, 4, 1, 2, 6, 5, 2, 3, 7, 6, 3, 0, 4, 7};

/* Normal of the finer mesh's face at corner k of coarse face f, d levels finer: output faces
 * are the faces of their level, and the child of quad f at its corner k is quad 4 f + k with
 * the corner's vertex point at its corner 0, so the descendant is face 4^d f + 4^(d-1) k,
 * corner 0; its normal there is (p1 - p0) x (p3 - p0). */
static int fine_normal(const lmesh *fine, int d, int f, int k, double n[3]) {
    long q = ((long)f << (2 * d)) + ((long)k << (2 * (d - 1)));
    if (q >= fine->nf) return -1;
    const double *v = fine->pos + 3 * fine->fv[4 * q], *a = fine->pos + 3 * fine->fv[4 * q + 1],
                 *b = fine->pos + 3 * fine->fv[4 * q + 3];
    double e1[3] = {a[0] - v[0], a[1] - v[1], a[2] - v[2]}, e2[3] = {b[0] - v[0], b[1] - v[1], b[2] - v[2]};
    n[0] = e1[1] * e2[2] - e1[2] * e2[1]; n[1] = e1[2] * e2[0] - e1[0] * e2[2]; n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    unit(n);
    return 0;
}

/* Worst angle between the coarse mesh's corner normals and the finer mesh's face normals at
 * the same corners (restricted to corners at vertices whose faces see several normals, or all). */
static double corner_vs_fine(const lmesh *coarse, const lmesh *fine, int d, int sharp_only) {
    double worst = 0;
    for (int f = 0; f < coarse->nf; f++) {
        for (int k = 0; k < 4; k++) {
            int v = coarse->fv[4 * f + k];
            const double *cn = coarse->cn + 12 * f + 3 * k;
            if (sharp_only && angle(cn, coarse->nrm + 3 * v) < 1e-12) continue;
            double n[3];
            if (fine_normal(fine, d, f, k, n)) return 1e300;
            worst = fmax(worst, angle(cn, n));
        }
    }
    return worst;
}


static void check_ev_case(const char *name, const ccn_cage *c, int expect_caps) {
    /* level 3: above the cap level K = 2 (at K >= L no cap is built, surface/caps.c) */
    ccn_options o = {CCN_SCHEME_EIGEN, CCN_CAP_GUIDED_BI5, 3, CCN_CORNERS_SMOOTH, 1, CCN_CREASE_UNIFORM, CCN_POLY_SELECT, NULL, NULL};
    lmesh a, f4, f5;
    int ok = limit(c, &o, &a) == 0;
    o.cap = CCN_CAP_REFINE;
    o.levels = 4; ok = ok && limit(c, &o, &f4) == 0;
    o.levels = 5; ok = ok && limit(c, &o, &f5) == 0;
    CHECK(ok, "%s: plans", name);
    if (!ok) return;
    int finite = 1;
    for (int i = 0; i < 3 * a.nv; i++) finite &= isfinite(a.pos[i]) && isfinite(a.nrm[i]);
    for (int i = 0; i < 12 * a.nf; i++) finite &= isfinite(a.cn[i]);
    CHECK(finite, "%s: finite", name);
    CHECK(a.st.num_sharp_corners > 0, "%s: %d vertices with several normals", name, a.st.num_sharp_corners);
    /* the smooth EVs get caps (creases at cage level are >= 4 level-K rings away from them,
     * so never in the 3 regular rings a cap needs); the creased ones are refined to the limit */
    CHECK(a.st.num_caps == expect_caps && a.st.num_cap_fallbacks == 0, "%s: %d caps (expected %d), %d fallbacks",
          name, a.st.num_caps, expect_caps, a.st.num_cap_fallbacks);
    /* the level-2 surface (refine cap) against finite differences of levels 4 and 5 */
    lmesh a2;
    o.levels = 2;
    ok = limit(c, &o, &a2) == 0;
    double e4 = ok ? corner_vs_fine(&a2, &f4, 2, 0) : 1e300, e5 = ok ? corner_vs_fine(&a2, &f5, 3, 0) : 1e300;
    double s4 = ok ? corner_vs_fine(&a2, &f4, 2, 1) : 1e300, s5 = ok ? corner_vs_fine(&a2, &f5, 3, 1) : 1e300;
    CHECK(e5 < 0.1 && e5 < 0.75 * e4, "%s: corner normals vs finite differences: level 4 %.3g, level 5 %.3g rad",
          name, e4, e5);
    CHECK(s5 < 0.1 && s5 < 0.75 * s4, "%s: sharp corners vs finite differences: level 4 %.3g, level 5 %.3g rad",
          name, s4, s5);
    printf("#   %s: %d two-sided vertices, %d caps, %d cap fallbacks; corner normals vs finite differences "
           "%.3f (L4) -> %.3f (L5) rad, at sharp corners %.3f -> %.3f\n", name, a.st.num_sharp_corners,
           a.st.num_caps, a.st.num_cap_fallbacks, e4, e5, s4, s5);
    if (ok) lm_free(&a2);
    lm_free(&a); lm_free(&f4); lm_free(&f5);
}

static void test_crease_evs(void) {
    /* cube: the top square creased (four crease EVs of valence 3), one vertical edge too (a
     * corner at its top, a dart at its bottom) */
    int32_t fs[6] = {4, 4, 4, 4, 4, 4};
    int32_t ev[10] = {4, 5, 5, 6, 6, 7, 7, 4, 0, 4};
    double cr[5] = {10, 10, 10, 10, 10};
    ccn_cage cube = {8, 6, 5, cube_p, fs, cube_f, ev, NULL, cr, NULL};
    check_ev_case("cube, creased top and one vertical edge", &cube, 3);
    /* semi-sharp version with a vertex crease */
    double cr2[5] = {2.5, 2.5, 1.5, 2.5, 0.5}, vc[8] = {0, 0, 0, 0, 0, 0, 3, 0};
    ccn_cage cube2 = {8, 6, 5, cube_p, fs, cube_f, ev, NULL, cr2, vc};
    ccn_options o = {CCN_SCHEME_EIGEN, CCN_CAP_REFINE, 2, CCN_CORNERS_SMOOTH, 1, CCN_CREASE_UNIFORM, CCN_POLY_SELECT, NULL, NULL};
    lmesh a, b;
    int ok = limit(&cube2, &o, &a) == 0;
    o.levels = 3;
    ok = ok && limit(&cube2, &o, &b) == 0;
    CHECK(ok, "semi-sharp cube plans");
    if (ok) { /* exact: level 2's limit points are level 3's */
        double size = bbox(b.pos, b.nv), e = 0;
        for (int v = 0; v < a.nv; v++) {
            double best = 1e300;
            for (int w = 0; w < b.nv; w++) best = fmin(best, dist(a.pos + 3 * v, b.pos + 3 * w));
            e = fmax(e, best);
        }
        CHECK(e <= TOL_POS * size, "semi-sharp cube: level-2 limit points off level 3's by %.3g", e);
        lm_free(&a); lm_free(&b);
    }
    /* a star of 5 and one of 3 quads per spoke pair around an interior vertex, creased along two
     * spokes: a valence-5 / valence-3 crease vertex (tests/data/fan5.obj, fan3.obj) */
    const char *files[2] = {"tests/data/fan5.obj", "tests/data/fan3.obj"};
    for (int i = 0; i < 2; i++) {
        size_t len = 0;
        char *t = tl_slurp(files[i], &len);
        ccn_obj *obj = NULL;
        ccn_error err;
        CHECK(t && ccn_obj_parse(t, len, &obj, &err) == CCN_OK, "%s", files[i]);
        free(t);
        if (!obj) continue;
        ccn_cage c;
        ccn_obj_get_cage(obj, &c);
        /* vertex 0 is the centre; its spokes go to the vertices sharing an edge with it */
        int32_t sp[2 * 8], ns = 0;
        for (int f = 0, off = 0; f < c.num_faces; off += c.face_sizes[f], f++)
            for (int k = 0; k < c.face_sizes[f]; k++)
                if (c.face_verts[off + k] == 0 && ns < 8) {
                    sp[2 * ns] = 0;
                    sp[2 * ns + 1] = c.face_verts[off + (k + 1) % c.face_sizes[f]];
                    ns++;
                }
        int32_t ev2[4] = {sp[0], sp[1], sp[4], sp[5]}; /* spokes 0 and 2 */
        double cr3[2] = {10, 10};
        c.num_edges = 2; c.edge_verts = ev2; c.edge_knots = NULL; c.edge_creases = cr3;
        check_ev_case(files[i], &c, 0);
        ccn_obj_destroy(obj);
    }
}
