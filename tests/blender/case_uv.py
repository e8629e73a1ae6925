"""UV maps and attributes on the limit mesh: the CCNURBS modifier's UVs against
Blender's own Subdivision Surface for every UV Smooth option, the UV maps' names and active
flags, point attributes interpolated like the positions, corner attributes (vertex colours) and
edge attributes and UV seams as Subdivision Surface gives them, face attributes copied, Apply.

Subdivision Surface evaluates UVs on OpenSubdiv's face-varying patch table, isolated to its
Quality; CCNURBS gives the exact limit (checked against OpenSubdiv's LimitFaceVarying in
tests/oracle/run_fvar_shapes.sh). At Quality 10 (the patch table's closest) they agree to float
precision at every face corner for every option (<= 1e-5, measured <= 2.4e-7). At lower Quality
they differ at one kind of point only: with UV Smooth "All" (FVAR_LINEAR_NONE) the corners of UV
islands (a vertex with a UV value used by one of its faces only) are smooth corners, where the
patches approximate the limit after Quality levels: measured 6.5e-4 on the cube and 2.6e-4 on
Suzanne at Quality 3 (Subdivision Surface's default), 1.0e-5 and 4.1e-6 at 6, 1.8e-7 at 10, about
4x closer per level. test_smooth_all_quality checks that convergence."""
from bltest import *  # noqa: F401,F403

import time

UV_TOL = 1e-5
QUALITY = 10  # Subdivision Surface's Quality = OpenSubdiv's isolation level: its closest
MODES = ('NONE', 'PRESERVE_CORNERS', 'PRESERVE_CORNERS_AND_JUNCTIONS',
         'PRESERVE_CORNERS_JUNCTIONS_AND_CONCAVE', 'PRESERVE_BOUNDARIES', 'SMOOTH_ALL')


def corner_data(me, layer=None):
    """Per corner: position (vertex), vertex index, UV of the layer (active if None)."""
    n = len(me.loops)
    co = np.empty(3 * len(me.vertices), np.float32)
    me.vertices.foreach_get("co", co)
    lv = np.empty(n, np.int32)
    me.loops.foreach_get("vertex_index", lv)
    uv = np.empty(2 * n, np.float32)
    (me.uv_layers[layer] if layer else me.uv_layers.active).data.foreach_get("uv", uv)
    return co.reshape(-1, 3)[lv], lv, uv.reshape(-1, 2)


def uv_corners(me):
    """Cage vertices with a UV value used by one of their faces only (UV island corners)."""
    n = len(me.loops)
    lv = np.empty(n, np.int32)
    me.loops.foreach_get("vertex_index", lv)
    uv = np.empty(2 * n, np.float32)
    me.uv_layers.active.data.foreach_get("uv", uv)
    key = np.column_stack([lv, uv.reshape(-1, 2).view(np.uint32)]).astype(np.int64)
    u, cnt = np.unique(key, axis=0, return_counts=True)
    return set(u[cnt == 1][:, 0].tolist())


def match_corners(a, b):
    """Each quad corner of limit mesh a to a corner of mesh b (both all quads, same surface):
    the face of b with the nearest centre, then the nearest corner. Returns (index into b's
    corners per a corner, largest position distance)."""
    pa, pb = a[0].reshape(-1, 4, 3), b[0].reshape(-1, 4, 3)
    ca, cb = pa.mean(1), pb.mean(1)
    j = np.empty(len(ca), np.int64)
    for s in range(0, len(ca), 512):  # nearest centre, in chunks
        d = ((ca[s:s + 512, None, :] - cb[None, :, :]) ** 2).sum(-1)
        j[s:s + 512] = d.argmin(1)
    d = ((pa[:, :, None, :] - pb[j][:, None, :, :]) ** 2).sum(-1)  # (F, 4 of a, 4 of b)
    k = d.argmin(2)
    idx = (4 * j[:, None] + k).ravel()
    return idx, float(np.sqrt(d.min(2)).max())


def setup(kind):
    if kind == "cube":
        bpy.ops.mesh.primitive_cube_add(size=2)  # Blender's unwrap: a cross with seams
    elif kind == "cylinder64":  # two 64-gon caps, each its own UV disk (evaluated by levels)
        bpy.ops.mesh.primitive_cylinder_add(vertices=64)
    else:
        bpy.ops.mesh.primitive_monkey_add()      # Suzanne: several islands, triangles
    return bpy.context.object


class TestUVs(AddonTestCase):
    def compare_with_subsurf(self, kind, levels, mode, second_map=False, quality=QUALITY,
                             nudge=False):
        """Checks every face corner's UVs against Subdivision Surface's at `quality` (<= UV_TOL;
        with SMOOTH_ALL at lower Quality only the corners away from UV island corners) and
        returns the worst difference (away from island corners, at them)."""
        ob = setup(kind)
        if second_map:
            src = ob.data.uv_layers.active
            n = len(ob.data.loops)
            uv = np.empty(2 * n, np.float32)
            src.data.foreach_get("uv", uv)
            extra = ob.data.uv_layers.new(name="Scaled")
            extra.data.foreach_set("uv", (0.5 * uv + 0.25).astype(np.float32))
            extra.active_render = True
            ob.data.uv_layers.active_index = 0
        if nudge:  # one corner of each vertex whose corners share a UV: one float step off
            me = ob.data
            n = len(me.loops)
            uv = np.empty(2 * n, np.float32)
            me.uv_layers.active.data.foreach_get("uv", uv)
            uv = uv.reshape(-1, 2)
            lv = np.empty(n, np.int32)
            me.loops.foreach_get("vertex_index", lv)
            seen = {}
            for c in range(n):
                key = (int(lv[c]), float(uv[c, 0]), float(uv[c, 1]))
                if key in seen and seen[key] == 1:
                    uv[c, 0] = np.nextafter(uv[c, 0], np.float32(2))
                seen[key] = seen.get(key, 0) + 1
            me.uv_layers.active.data.foreach_set("uv", uv.ravel())
        ref = ob.copy()
        ref.data = ob.data.copy()
        bpy.context.collection.objects.link(ref)
        sub = ref.modifiers.new("Subdivision", 'SUBSURF')
        sub.levels, sub.uv_smooth, sub.boundary_smooth = levels, mode, 'ALL'
        sub.quality = quality
        add_modifier(ob, levels=levels, scheme='CATMULL_CLARK', cap='REFINE', uv_smooth=mode)
        dg = update()
        a, b = ob.evaluated_get(dg).data, ref.evaluated_get(dg).data
        names = [u.name for u in ob.data.uv_layers]
        self.assertEqual([u.name for u in a.uv_layers], names)
        self.assertEqual(a.uv_layers.active.name, ob.data.uv_layers.active.name)
        self.assertEqual([u.active_render for u in a.uv_layers],
                         [u.active_render for u in ob.data.uv_layers])
        corners = uv_corners(ob.data) if mode == 'SMOOTH_ALL' else set()
        worst = worst_corner = 0.0
        nexcluded = 0
        for name in names:
            ca, cb = corner_data(a, name), corner_data(b, name)
            idx, pos_err = match_corners(ca, cb)
            self.assertLess(pos_err, 1e-3, "limit surfaces differ: %g" % pos_err)
            err = np.abs(ca[2] - cb[2][idx]).max(1)
            # Subdivision Surface numbers the cage's own vertices first
            at_corner = np.isin(cb[1][idx], list(corners)) if corners else np.zeros(len(err), bool)
            nexcluded += int(at_corner.sum())
            worst = max(worst, float(err[~at_corner].max()))
            if at_corner.any():
                worst_corner = max(worst_corner, float(err[at_corner].max()))
        self.assertLessEqual(worst, UV_TOL, "%s L%d %s Q%d: UVs differ from Subdivision Surface "
                             "by %g" % (kind, levels, mode, quality, worst))
        if quality == QUALITY:
            self.assertLessEqual(worst_corner, UV_TOL, "%s L%d %s Q%d: UVs at UV island corners "
                                 "differ from Subdivision Surface by %g"
                                 % (kind, levels, mode, quality, worst_corner))
        print("measure uv %s L%d Q%d %-40s %d map(s): %.2e per face corner%s" % (
            kind, levels, quality, mode, len(names), worst, "" if not corners else
            "; %d corners at UV island corners: %.2e" % (nexcluded, worst_corner)))
        return worst, worst_corner

    def test_uvs_match_subdivision_surface(self):
        for kind in ("cube", "suzanne"):
            for levels in (1, 2):
                for mode in MODES:
                    with self.subTest(kind=kind, levels=levels, mode=mode):
                        reset_scene()
                        self.compare_with_subsurf(kind, levels, mode,
                                                  second_map=(kind == "cube" and levels == 1))

    def test_uvs_one_float_step_apart_are_one(self):
        """Blender's Unwrap leaves the UVs of a vertex's corners one float step apart; Subdivision
        Surface connects UVs within 1e-4 (no seam there), and so does the modifier."""
        for kind in ("cube", "suzanne"):
            with self.subTest(kind=kind):
                reset_scene()
                self.compare_with_subsurf(kind, 2, 'PRESERVE_BOUNDARIES', nudge=True)

    def test_high_valence_cylinder_uvs(self):
        """A 64-sided cylinder (its cap disks' centres have 64 UV neighbours: more probe colours
        than the library composes, so it evaluates them through the channel's levels): the
        default UV Smooth (Keep Boundaries) equals Subdivision Surface's at level 1, Quality 3
        (one mode, at a small size: Blender's own evaluation of a 128-sided one takes about 8 s
        a mode; tests/oracle/run_fvar_shapes.sh checks all six modes against OpenSubdiv)."""
        reset_scene()
        t0 = time.perf_counter()
        self.compare_with_subsurf("cylinder64", 1, 'PRESERVE_BOUNDARIES', quality=3)
        print("measure uv cylinder64 L1 PRESERVE_BOUNDARIES: both evaluated in %.2f s"
              % (time.perf_counter() - t0))

    def test_smooth_all_quality(self):
        """UV Smooth "All" at Subdivision Surface's Quality 3..10: away from UV island corners
        equal at every Quality; at the island corners (smooth corners of the UV map) the patch
        table approaches the exact limit with each isolation level (at least 2x per level until
        float precision, 1e-6) and equals it at 10."""
        for kind in ("cube", "suzanne"):
            prev, row = None, []
            for q in range(3, QUALITY + 1):
                with self.subTest(kind=kind, quality=q):
                    reset_scene()
                    _, c = self.compare_with_subsurf(kind, 1, 'SMOOTH_ALL', quality=q)
                    row.append("Q%d %.1e" % (q, c))
                    if prev is not None:
                        self.assertTrue(c <= 0.5 * prev or c <= 1e-6,
                                        "%s Q%d: %.3g at UV island corners, Q%d %.3g"
                                        % (kind, q, c, q - 1, prev))
                    prev = c
            print("measure uv %s L1 SMOOTH_ALL at UV island corners by Quality: %s"
                  % (kind, ", ".join(row)))

    def test_uv_smooth_setting(self):
        """Subdivision Surface's identifiers, names and default: what a new Subdivision Surface
        modifier gets (measured on 3.4, 4.5 and 5.0: Keep Boundaries, not Keep Corners)."""
        ours = bpy.types.Object.bl_rna.properties["ccnurbs"].fixed_type.properties["uv_smooth"]
        theirs = bpy.types.SubsurfModifier.bl_rna.properties["uv_smooth"]
        self.assertEqual([(e.identifier, e.name) for e in ours.enum_items],
                         [(e.identifier, e.name) for e in theirs.enum_items])
        ob = setup("cube")
        bpy.ops.object.modifier_add(type='SUBSURF')
        new = ob.modifiers[-1].uv_smooth
        ob.modifiers.remove(ob.modifiers[-1])
        self.assertEqual(ours.default, new)
        add_modifier(ob)
        self.assertEqual(ob.ccnurbs.uv_smooth, new)

    def test_corner_attributes_match_subdivision_surface(self):
        """Corner attributes other than UV maps (vertex colours painted or imported per face
        corner: float and byte colours, floats, vectors) equal Subdivision Surface's at every
        face corner (bilinear inside each cage face, byte colours in their stored values) at
        levels 1-2 on the cube and on Suzanne (triangles); painting (new values, same corners)
        reaches the limit without a new plan; Apply keeps them."""
        rng = np.random.default_rng(7)
        for kind in ("cube", "suzanne"):
            for levels in (1, 2):
                with self.subTest(kind=kind, levels=levels):
                    reset_scene()
                    ob = setup(kind)
                    me = ob.data
                    n = len(me.loops)
                    data = {"paint": ('FLOAT_COLOR', 'color', 4), "Col": ('BYTE_COLOR', 'color_srgb', 4),
                            "wear": ('FLOAT', 'value', 1), "flow": ('FLOAT_VECTOR', 'vector', 3)}
                    for name, (t, prop, k) in data.items():
                        me.attributes.new(name, t, 'CORNER').data.foreach_set(
                            prop, rng.random(n * k).astype(np.float32))
                    ref = ob.copy()
                    ref.data = me.copy()
                    bpy.context.collection.objects.link(ref)
                    sub = ref.modifiers.new("Subdivision", 'SUBSURF')
                    sub.levels, sub.quality = levels, QUALITY
                    add_modifier(ob, levels=levels, scheme='CATMULL_CLARK', cap='REFINE')
                    dg = update()
                    a, b = ob.evaluated_get(dg).data, ref.evaluated_get(dg).data
                    idx, pos_err = match_corners(corner_data(a), corner_data(b))
                    self.assertLess(pos_err, 1e-3, "limit surfaces differ: %g" % pos_err)
                    worst = 0.0
                    for name, (t, prop, k) in data.items():
                        va, vb = (np.empty(len(m.loops) * k, np.float32) for m in (a, b))
                        self.assertEqual(a.attributes[name].domain, 'CORNER')
                        self.assertEqual(a.attributes[name].data_type, t)
                        a.attributes[name].data.foreach_get(prop, va)
                        b.attributes[name].data.foreach_get(prop, vb)
                        tol = 1.01 / 255 if t == 'BYTE_COLOR' else 1e-5  # bytes: rounding
                        err = float(np.abs(va.reshape(-1, k) - vb.reshape(-1, k)[idx]).max())
                        self.assertLessEqual(err, tol, "%s %s L%d: %g" % (kind, name, levels, err))
                        worst = max(worst, err if t != 'BYTE_COLOR' else 0.0)
                    print("measure corner attributes %s L%d vs Subdivision Surface: %.2e (floats), "
                          "byte colours within a byte step" % (kind, levels, worst))
        # painting: new values, the same plan; then Apply keeps the attribute
        plans = dict(ccn.sync.stats)
        me = ob.data
        me.attributes["wear"].data.foreach_set("value", np.full(len(me.loops), 0.25, np.float32))
        me.update()
        a = ob.evaluated_get(update()).data
        w = np.empty(len(a.loops), np.float32)
        a.attributes["wear"].data.foreach_get("value", w)
        self.assertLess(float(np.abs(w - 0.25).max()), 1e-6)
        self.assertEqual(ccn.sync.stats["rebuilds"], plans["rebuilds"], "painting rebuilt the mesh")
        bpy.context.view_layer.objects.active = ob
        bpy.ops.object.modifier_apply(modifier=ccn.modifier.get_modifier(ob).name)
        self.assertEqual(ob.data.attributes["wear"].domain, 'CORNER')
        self.assertEqual(len(ob.data.attributes["wear"].data), len(ob.data.loops))

    def test_edge_attributes_and_seams_match_subdivision_surface(self):
        """UV seams and edge attributes (a float, an integer, a boolean) reach the limit edges
        that lie on cage edges, as on Subdivision Surface's result (matched by edge midpoint),
        and none reaches the edges inside cage faces; removing the seams clears them."""
        rng = np.random.default_rng(3)
        ob = setup("cube")
        me = ob.data
        ne = len(me.edges)
        seam = np.zeros(ne, bool)
        seam[[0, 3, 5, 9]] = True
        me.edges.foreach_set("use_seam", seam)
        data = {"wear_edge": ('FLOAT', rng.random(ne).astype(np.float32)),
                "edge_id": ('INT', np.arange(1, ne + 1, dtype=np.int32)),
                "cut": ('BOOLEAN', rng.random(ne) > 0.5)}
        for name, (t, v) in data.items():
            me.attributes.new(name, t, 'EDGE').data.foreach_set("value", v)
        me.update()
        ref = ob.copy()
        ref.data = me.copy()
        bpy.context.collection.objects.link(ref)
        sub = ref.modifiers.new("Subdivision", 'SUBSURF')
        sub.levels, sub.quality = 2, QUALITY
        add_modifier(ob, levels=2, scheme='CATMULL_CLARK', cap='REFINE')
        dg = update()
        a, b = ob.evaluated_get(dg).data, ref.evaluated_get(dg).data

        def midpoints(m):
            co = cagelib.mesh_positions(m)
            ev = np.empty(2 * len(m.edges), np.int32)
            m.edges.foreach_get("vertices", ev)
            return co[ev.reshape(-1, 2)].mean(1)
        ma, mb = midpoints(a), midpoints(b)
        self.assertEqual(len(ma), len(mb))
        j = np.array([int(np.argmin(((mb - p) ** 2).sum(1))) for p in ma])
        self.assertLess(float(np.sqrt(((mb[j] - ma) ** 2).sum(1)).max()), 1e-4)
        sa, sb = np.zeros(len(a.edges), bool), np.zeros(len(b.edges), bool)
        a.edges.foreach_get("use_seam", sa)
        b.edges.foreach_get("use_seam", sb)
        self.assertEqual(int(sa.sum()), 4 * 4, "each seam edge is 4 limit edges at level 2")
        self.assertTrue(np.array_equal(sa, sb[j]), "seams differ from Subdivision Surface's")
        for name, (t, v) in data.items():
            va = np.empty(len(a.edges), v.dtype)
            a.attributes[name].data.foreach_get("value", va)
            self.assertEqual(a.attributes[name].domain, 'EDGE')
            self.assertEqual(int(np.count_nonzero(va)), 4 * int(np.count_nonzero(v)), name)
            if name in b.attributes:  # Subdivision Surface carries generic edge attributes too
                vb = np.empty(len(b.edges), v.dtype)
                b.attributes[name].data.foreach_get("value", vb)
                self.assertTrue(np.array_equal(va, vb[j]), "%s differs from Subdivision Surface's" % name)
            print("measure edge attribute %s: %d limit edges carry it%s" % (
                name, int(np.count_nonzero(va)), ", equal to Subdivision Surface's"
                if name in b.attributes else ""))
        me.edges.foreach_set("use_seam", np.zeros(ne, bool))
        me.update()
        a = ob.evaluated_get(update()).data
        sa = np.zeros(len(a.edges), bool)
        a.edges.foreach_get("use_seam", sa)
        self.assertFalse(sa.any(), "seams removed from the cage stay on the limit")

    def test_uv_edit_updates(self):
        """A UV change alone (no vertex moved) reaches the limit; a move keeps the UVs."""
        ob = setup("cube")
        add_modifier(ob, levels=1, scheme='CATMULL_CLARK', cap='REFINE')
        a = ob.evaluated_get(update()).data
        before = corner_data(a)[2].copy()
        me = ob.data
        uv = np.empty(2 * len(me.loops), np.float32)
        me.uv_layers.active.data.foreach_get("uv", uv)
        me.uv_layers.active.data.foreach_set("uv", (uv * 0.5).astype(np.float32))
        me.update()
        after = corner_data(ob.evaluated_get(update()).data)[2]
        self.assertLess(np.abs(after - 0.5 * before).max(), 1e-6)
        co = cagelib.mesh_positions(me)
        me.vertices.foreach_set("co", (co * 1.5).astype(np.float32).ravel())
        me.update()
        moved = corner_data(ob.evaluated_get(update()).data)[2]
        self.assertLess(np.abs(moved - after).max(), 1e-7)

    def test_interval_edit_keeps_uvs(self):
        """An interval edit (the plan made from the one before, its UV channels added again)
        gives the UVs and positions of a modifier added to a copy with those intervals, and the
        UVs follow the intervals (inside a UV chart they use the ring intervals)."""
        ob = setup("cube")
        add_modifier(ob, levels=2)
        before = corner_data(ob.evaluated_get(update()).data)[2].copy()
        me = ob.data
        att = me.attributes.get("knot_interval") or me.attributes.new("knot_interval", 'FLOAT', 'EDGE')
        k = np.ones(len(me.edges), np.float32)
        k[0] = 3.0
        att.data.foreach_set("value", k)
        me.update()
        edited = corner_data(ob.evaluated_get(update()).data)
        self.assertGreater(np.abs(edited[2] - before).max(), 1e-4, "the interval did not reach the UVs")
        twin = bpy.data.objects.new("Twin", me.copy())
        twin.matrix_world = ob.matrix_world
        bpy.context.collection.objects.link(twin)
        add_modifier(twin, levels=2)
        fresh = corner_data(twin.evaluated_get(update()).data)
        self.assertLess(np.abs(edited[0] - fresh[0]).max(), 1e-6, "positions differ from a new modifier")
        self.assertLess(np.abs(edited[2] - fresh[2]).max(), 1e-7, "UVs differ from a new modifier")

    def test_attributes_and_apply(self):
        """Point attributes interpolate like the positions (an affine function of the positions
        gives the same function of the limit positions), face attributes come from the cage
        face (as the material index does), and Apply keeps UV maps and attributes."""
        ob = setup("cube")
        me = ob.data
        extra = me.uv_layers.new(name="Second")
        extra.active_render = True
        me.uv_layers.active_index = 0
        co = cagelib.mesh_positions(me).astype(np.float32)
        nv, nf = len(me.vertices), len(me.polygons)
        me.attributes.new("height", 'FLOAT', 'POINT').data.foreach_set("value", 2 * co[:, 2] - 1)
        me.attributes.new("rest", 'FLOAT_VECTOR', 'POINT').data.foreach_set("vector", co.ravel())
        col = np.column_stack([0.5 + 0.25 * co, np.ones(nv)]).astype(np.float32)
        me.attributes.new("tint", 'FLOAT_COLOR', 'POINT').data.foreach_set("color", col.ravel())
        fid = np.arange(nf, dtype=np.int32)
        me.attributes.new("face_id", 'INT', 'FACE').data.foreach_set("value", fid)
        for i in range(nf):
            me.materials.append(bpy.data.materials.new("M%d" % i))
        me.polygons.foreach_set("material_index", fid)
        me.update()
        add_modifier(ob, levels=2, scheme='CATMULL_CLARK', cap='REFINE')
        for applied in (False, True):
            if applied:
                bpy.context.view_layer.objects.active = ob
                bpy.ops.object.modifier_apply(modifier=ccn.modifier.get_modifier(ob).name)
                lm = ob.data
            else:
                lm = ob.evaluated_get(update()).data
            P = cagelib.mesh_positions(lm)
            n = len(lm.vertices)
            h = np.empty(n, np.float32)
            lm.attributes["height"].data.foreach_get("value", h)
            r = np.empty(3 * n, np.float32)
            lm.attributes["rest"].data.foreach_get("vector", r)
            t = np.empty(4 * n, np.float32)
            lm.attributes["tint"].data.foreach_get("color", t)
            self.assertLess(np.abs(h - (2 * P[:, 2] - 1)).max(), 1e-5)
            self.assertLess(np.abs(r.reshape(-1, 3) - P).max(), 1e-5)
            self.assertLess(np.abs(t.reshape(-1, 4)[:, :3] - (0.5 + 0.25 * P)).max(), 1e-5)
            f = np.empty(len(lm.polygons), np.int32)
            lm.attributes["face_id"].data.foreach_get("value", f)
            m = np.empty(len(lm.polygons), np.int32)
            lm.polygons.foreach_get("material_index", m)
            self.assertTrue(np.array_equal(f, m), "face attribute is not the cage face's")
            self.assertEqual([u.name for u in lm.uv_layers], ["UVMap", "Second"])
            self.assertEqual(lm.uv_layers.active.name, "UVMap")
            self.assertEqual([u.active_render for u in lm.uv_layers], [False, True])
        self.assertIsNone(ccn.modifier.get_modifier(ob))
