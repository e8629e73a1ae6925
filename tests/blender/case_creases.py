"""Creases and every cage an artist has: Suzanne as it comes (with its interior
valence-2 vertices) and a cube with edge creases 0.5 and 1.0 and a vertex crease give, with equal
intervals, scheme Catmull-Clark and cap Refine, the same limit as Blender's own Subdivision
Surface (Use Creases, Use Limit Surface, quality 10) at levels 1-3 (<= 1e-5 of the bounding box,
matched as point sets) — except where Blender's own limit is not the exact one. Blender evaluates
OpenSubdiv's adaptive patch table (isolation = Quality, infinitely sharp patches, Gregory basis
end caps); at a dart (an infinitely sharp crease ending at a vertex) the end cap's corner is the
smooth limit mask applied after Quality levels, 2.3e-5 of the bounding box off the exact limit
on the creased cube. Every comparison also evaluates that patch table independently
(tests/oracle/osd_refine --patch-limit) and checks that it is Blender's result (<= 1e-6: float
precision); where Blender is more than 1e-5 from CCNURBS the test checks that CCNURBS equals the
exact limit (osd_refine --limit, <= 1e-7) and prints the three distances; Quality 1-10 are the
isolation levels 1-10, each closer to the exact limit at the darts. A cube with creases 1.0
(a closed loop round the top face), 0.5 and a vertex crease, where no infinitely sharp crease
ends, equals Subsurf <= 1e-5 (measured 7.2e-8), as does one with semi-sharp creases only. Each side of a crease
gets its own normal; creases follow onto the limit mesh and through Apply; Use Creases off
ignores them; a cage error selects its element."""
import subprocess
import tempfile

from bltest import *  # noqa: F401,F403

from mathutils import Vector, kdtree

TOL = 1e-5             # CCNURBS vs Blender's Subdivision Surface
QUALITY = 10           # Subdivision Surface's Quality = OpenSubdiv's isolation level
PATCH_TOL = 1e-6       # Blender (float) vs its patch table evaluated in double
EXACT_TOL = 1e-7       # CCNURBS vs the exact limit


def set_crease(ob, edge_values, vert_values=()):
    me = ob.data
    ec = np.zeros(len(me.edges))
    for i, c in edge_values:
        ec[i] = c
    ccn.compat.set_edge_creases(me, ec.astype(np.float32))
    if vert_values:
        vc = np.zeros(len(me.vertices))
        for i, c in vert_values:
            vc[i] = c
        ccn.compat.set_vertex_creases(me, vc.astype(np.float32))
    me.update()


def subsurf_positions(ob, levels, quality=QUALITY):
    """Blender's own limit: a copy of ob with Subdivision Surface."""
    cp = ob.copy()
    cp.data = ob.data.copy()
    bpy.context.scene.collection.objects.link(cp)
    for m in list(cp.modifiers):
        cp.modifiers.remove(m)
    m = cp.modifiers.new("Subsurf", 'SUBSURF')
    m.levels = m.render_levels = levels
    m.use_limit_surface = True
    m.quality = quality
    m.use_creases = True
    m.boundary_smooth = 'ALL'
    P = evaluated_positions(cp)
    bpy.data.objects.remove(cp)
    return P


def max_set_distance(A, B):
    t = kdtree.KDTree(len(B))
    for i, p in enumerate(B):
        t.insert(p, i)
    t.balance()
    return max(t.find(p)[2] for p in A) if len(A) else 0.0


OSD = os.path.join(os.path.dirname(CLI), "osd_refine")


def osd_refine(ob, L, *mode):
    """The level-L vertices of tests/oracle/osd_refine for the cage, with Blender's crease
    mapping 10 c^2: `--limit` is the exact limit (refines around each vertex until no
    semi-sharp value is left), `--patch-limit --isolation N` Blender's adaptive patch table."""
    me = ob.data
    with tempfile.TemporaryDirectory() as d:
        path, out = os.path.join(d, "cage.obj"), os.path.join(d, "ref.obj")
        with open(path, "w") as f:
            for v in me.vertices:
                f.write("v %.17g %.17g %.17g\n" % tuple(v.co))
            for p in me.polygons:
                f.write("f " + " ".join(str(i + 1) for i in p.vertices) + "\n")
            ec, vc = ccn.compat.edge_creases(me), ccn.compat.vertex_creases(me)
            for e in me.edges:
                if ec is not None and ec[e.index] > 0:
                    f.write("# crease %d %d %.17g\n" % (e.vertices[0] + 1, e.vertices[1] + 1,
                                                       10 * float(ec[e.index]) ** 2))
            for i, c in enumerate(vc if vc is not None else []):
                if c > 0:
                    f.write("# corner %d %.17g\n" % (i + 1, 10 * float(c) ** 2))
        subprocess.run([OSD, "--levels", str(L)] + list(mode) + [path, out], check=True,
                       capture_output=True)
        return np.array([list(map(float, l.split()[1:4])) for l in open(out) if l.startswith("v ")])


def set_distance(A, B):
    return max(max_set_distance(A, B), max_set_distance(B, A))


def compare_with_subsurf(test, ob, levels=(1, 2, 3)):
    """Returns the worst distance (relative to the bounding box) of CCNURBS to Blender's
    Subdivision Surface, of Blender to OpenSubdiv's patch table (checked <= PATCH_TOL at every
    level), of Blender to the exact limit and of CCNURBS to the exact limit (checked <=
    EXACT_TOL; these two only where CCNURBS is more than TOL from Blender, 0 elsewhere)."""
    add_modifier(ob, scheme='CATMULL_CLARK', cap='REFINE')
    worst = blender_err = patch_err = ours_err = 0.0
    for L in levels:
        ob.ccnurbs.levels = L
        ours = evaluated_positions(ob)
        st = ccn.sync.status(ob, 'VIEW')
        test.assertIsNone(st.error, st.error)
        ref = subsurf_positions(ob, L)
        size = float(np.linalg.norm(ref.max(0) - ref.min(0)))
        test.assertEqual(len(ours), len(ref), "level %d: vertex counts" % L)
        d = set_distance(ours, ref) / size
        worst = max(worst, d)
        patch = osd_refine(ob, L, "--patch-limit", "--isolation", str(QUALITY))
        blender_patch = set_distance(ref, patch) / size
        patch_err = max(patch_err, blender_patch)
        test.assertLessEqual(blender_patch, PATCH_TOL, "level %d: Blender %.3g from OpenSubdiv's "
                             "patch table" % (L, blender_patch))
        if d > TOL:  # Blender's patch approximation? compare both with the exact limit
            ex = osd_refine(ob, L, "--limit")
            ours_ex = set_distance(ours, ex) / size
            blender_ex = set_distance(ref, ex) / size
            blender_err = max(blender_err, blender_ex)
            ours_err = max(ours_err, ours_ex)
            print("measure creases %s L%d: CCNURBS-Blender %.2e, Blender-patch table %.2e, "
                  "Blender-exact %.2e, CCNURBS-exact %.2e" % (ob.name, L, d, blender_patch,
                                                             blender_ex, ours_ex))
            test.assertLessEqual(ours_ex, EXACT_TOL,
                                 "level %d: %.3g from the exact limit" % (L, ours_ex))
    return worst, patch_err, blender_err, ours_err


class TestCreases(AddonTestCase):
    def test_suzanne_equals_subsurf(self):
        bpy.ops.mesh.primitive_monkey_add()
        ob = bpy.context.object
        n2 = sum(1 for v in ob.data.vertices if len([e for e in ob.data.edges if v.index in e.vertices]) == 2)
        self.assertGreater(n2, 0, "Suzanne has interior valence-2 vertices")
        d, p, _, _ = compare_with_subsurf(self, ob)
        self.assertLessEqual(d, TOL)
        print("measure creases: Suzanne (%d valence-2 vertices) vs Subdivision Surface, levels "
              "1-3: %.2e of size (Blender vs OpenSubdiv's patch table: %.2e)" % (n2, d, p))

    def test_creased_cube_equals_subsurf(self):
        ob = cube()
        me = ob.data
        # two creased edges (0.5 and 1.0) and one vertex crease
        set_crease(ob, [(0, 0.5), (1, 1.0), (5, 1.0)], [(3, 0.7)])
        d, p, b, e = compare_with_subsurf(self, ob)
        print("measure creases: cube with creases 0.5 / 1.0 and a vertex crease vs Subdivision "
              "Surface, levels 1-3: %.2e of size; Blender vs OpenSubdiv's patch table %.2e, "
              "Blender vs the exact limit %.2e (at the darts), CCNURBS vs the exact limit %.2e"
              % (d, p, b, e))
        # semi-sharp creases and the vertex crease alone: no dart is left at level 10, so
        # Blender's patch table is exact there and equals CCNURBS
        ob2 = cube("Semi")
        set_crease(ob2, [(0, 0.5), (2, 0.8)], [(3, 0.7)])
        d2, p2, _, _ = compare_with_subsurf(self, ob2)
        self.assertLessEqual(d2, TOL)
        print("measure creases: cube with semi-sharp creases only: %.2e of size (Blender vs "
              "OpenSubdiv's patch table: %.2e)" % (d2, p2))
        # creases 1.0 and 0.5 and a vertex crease where no infinitely sharp crease ends (the
        # 1.0 edges close a loop round the top face): Blender's patch table is exact there too
        ob3 = cube("Loop")
        top = [e.index for e in ob3.data.edges
               if all(ob3.data.vertices[i].co.z > 0 for i in e.vertices)]
        side = [e.index for e in ob3.data.edges
                if ob3.data.vertices[e.vertices[0]].co.z != ob3.data.vertices[e.vertices[1]].co.z]
        low = [v.index for v in ob3.data.vertices if v.co.z < 0]
        self.assertEqual((len(top), len(side), len(low)), (4, 4, 4))
        set_crease(ob3, [(i, 1.0) for i in top] + [(side[0], 0.5)], [(low[2], 0.7)])
        d3, p3, _, _ = compare_with_subsurf(self, ob3)
        self.assertLessEqual(d3, TOL)
        print("measure creases: cube with a loop of creases 1.0, a crease 0.5 and a vertex crease "
              "(no dart): %.2e of size (Blender vs OpenSubdiv's patch table: %.2e)" % (d3, p3))
        st = ccn.sync.status(ob, 'VIEW')
        self.assertGreater(st.sizes.get("num_sharp_edges", 0), 0)
        self.assertGreater(st.sizes.get("num_sharp_corners", 0), 0)
        self.assertEqual(len(me.edges), 12)

    def test_subsurf_quality_is_the_patch_isolation_level(self):
        # Quality q is OpenSubdiv's isolation level: at every q Blender is the patch table of
        # isolation q, which comes closer to the exact limit at the darts with each level
        ob = cube()
        set_crease(ob, [(0, 0.5), (1, 1.0), (5, 1.0)], [(3, 0.7)])
        ex = osd_refine(ob, 2, "--limit")
        row, prev = [], 1.0
        for q in range(1, 11):
            ref = subsurf_positions(ob, 2, q)
            size = float(np.linalg.norm(ref.max(0) - ref.min(0)))
            patch = osd_refine(ob, 2, "--patch-limit", "--isolation", str(q))
            d = set_distance(ref, patch) / size
            self.assertLessEqual(d, PATCH_TOL,
                                 "quality %d: Blender %.3g from the patch table" % (q, d))
            e = set_distance(ref, ex) / size
            if q >= 5:
                self.assertLess(e, prev, "quality %d: no closer to the exact limit" % q)
            prev = e
            row.append("q%d %.2e" % (q, e))
        print("measure creases: creased cube level 2, Blender = patch table of isolation q (<= %g); "
              "Blender vs the exact limit: %s" % (PATCH_TOL, ", ".join(row)))

    def test_sides_of_a_crease_have_their_own_normals(self):
        ob = cube()
        set_crease(ob, [(e.index, 1.0) for e in ob.data.edges])  # every edge infinitely sharp
        add_modifier(ob, levels=2)
        dg = update()
        me = ob.evaluated_get(dg).data
        N = ccn.compat.corner_normals(me)
        P = cagelib.mesh_positions(me)
        # a fully creased cube's limit is the cage's faces: every corner normal is its face's
        fn = np.empty(3 * len(me.polygons), np.float32)
        me.polygons.foreach_get("normal", fn)
        fn = fn.reshape(-1, 3)
        loops_face = np.repeat(np.arange(len(me.polygons)), 4)
        worst = float(np.max(np.linalg.norm(N - fn[loops_face], axis=1)))
        self.assertLess(worst, 1e-5, "corner normals vs flat faces: %.3g" % worst)
        self.assertLess(float(np.max(np.abs(np.abs(P) - 1).min(axis=1))), 1e-6, "points on the cube")

    def test_creases_follow_onto_the_limit_and_apply(self):
        ob = cube()
        set_crease(ob, [(0, 1.0), (3, 0.4)])
        add_modifier(ob, levels=2)
        me = ob.evaluated_get(update()).data
        c = ccn.compat.edge_creases(me)
        self.assertIsNotNone(c)
        self.assertEqual(int(np.sum(np.isclose(c, 1.0))), 4, "edge 0's four child edges")
        self.assertEqual(int(np.sum(np.isclose(c, 0.4))), 4, "edge 3's four child edges")
        self.assertEqual(int(np.sum(c > 0)), 8)
        bpy.context.view_layer.objects.active = ob
        bpy.ops.object.modifier_apply(modifier=ccn.modifier.MOD_NAME)
        c2 = ccn.compat.edge_creases(ob.data)
        self.assertEqual(int(np.sum(c2 > 0)), 8, "creases survive Apply")

    def test_use_creases_off_ignores_them(self):
        a = cube("A")
        set_crease(a, [(0, 1.0), (1, 1.0)])
        add_modifier(a, levels=2)
        Pa = evaluated_positions(a)
        b = cube("B")
        add_modifier(b, levels=2)
        Pb = evaluated_positions(b)
        self.assertGreater(float(np.max(np.abs(Pa - Pb))), 1e-3, "creases change the surface")
        a.ccnurbs.use_creases = False
        Pa = evaluated_positions(a)
        self.assertLess(float(np.max(np.abs(Pa - Pb))), 1e-6, "Use Creases off: as without creases")

    def test_non_manifold_cages_equal_subsurf(self):
        """Non-manifold cages as Subdivision Surface (OpenSubdiv) reads them: an edge with three
        faces, a bowtie vertex, a face wound against its neighbours, and Suzanne triangulated
        (Ctrl+T makes edges with three faces next to its valence-2 vertices)."""
        Vf = np.array([(0, 0, 0), (1, 0, 0), (1, 1, 0.2), (0, 1, 0), (1, -1, 0), (0, -1, 0.3),
                       (2, 1, 0), (2, 0, 0.1), (-1, 1, 0), (-1, 0, 0)], float)
        cages = {
            "ThreeFaces": (np.array([(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (1, -1, 0),
                                     (0, -1, 0), (1, 0, 1), (0, 0, 1)], float),
                           [(0, 1, 2, 3), (1, 0, 5, 4), (0, 1, 6, 7)]),
            "Bowtie": (np.array([(0, 0, 0), (1, 0, 0), (1, 1, 0.3), (0, 1, 0), (-1, 0, 0.2),
                                 (-1, -1, 0), (0, -1, 0)], float),
                       [(0, 1, 2, 3), (0, 4, 5, 6)]),
            # (4, 5, 0, 1) uses edge 0-1 in the direction face 0 does
            "Flipped": (Vf, [(0, 1, 2, 3), (1, 7, 6, 2), (0, 3, 8, 9), (4, 5, 0, 1)]),
        }
        for name, (P, F) in cages.items():
            with self.subTest(name):
                ob = load_cage(name, V=P, F=F, K={})
                d, p, b, e = compare_with_subsurf(self, ob)
                self.assertLessEqual(d, TOL)
                print("measure creases: non-manifold %s vs Subdivision Surface, levels 1-3: "
                      "%.2e of size" % (name, d))
        bpy.ops.mesh.primitive_monkey_add()
        ob = bpy.context.object
        ob.modifiers.new("Triangulate", 'TRIANGULATE')
        bpy.ops.object.modifier_apply(modifier="Triangulate")
        d, p, b, e = compare_with_subsurf(self, ob, levels=(1, 2))
        self.assertLessEqual(d, TOL)
        print("measure creases: Suzanne triangulated (non-manifold edges) vs Subdivision Surface, "
              "levels 1-2: %.2e of size" % d)

    def test_error_select_button(self):
        # a vertex with a non-finite coordinate is named, explained and selected
        V = np.array([(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (2, 0, 0), (2, 1, 0)], float)
        F = [(0, 1, 2, 3), (1, 4, 5, 2)]
        ob = load_cage("NaNVertex", V=V, F=F, K={})
        co = np.zeros(3 * len(V), np.float32)
        ob.data.vertices.foreach_get("co", co)
        co[3 * 4 + 2] = np.nan
        ob.data.vertices.foreach_set("co", co)
        ob.data.update()
        add_modifier(ob)
        st = ccn.sync.status(ob, 'VIEW')
        self.assertIsNotNone(st.error)
        self.assertIn("vertex 4 has a non-finite coordinate", st.error)
        self.assertTrue(ccn.errors.advice(st))
        self.assertIsNotNone(ccn.errors.selectable(st))
        bpy.context.view_layer.objects.active = ob
        text = labels(draw_panel(ccn.ui.DATA_PT_ccnurbs_modifier))
        self.assertIn("Move this vertex to a finite position", text)
        res = bpy.ops.object.ccnurbs_select_error()
        self.assertEqual(res, {'FINISHED'})
        self.assertEqual(ob.mode, 'EDIT')
        bpy.ops.object.mode_set(mode='OBJECT')
        self.assertEqual([v.index for v in ob.data.vertices if v.select], [4])

    def test_loose_geometry_as_in_subsurf(self):
        """Loose vertices and edges as Subdivision Surface carries them: a chain of two loose
        edges from a cube corner (Subsurf makes the corner infinitely sharp and smooths the
        chain as a cubic B-spline), a loose edge between two cube vertices, an isolated vertex;
        with and without Use Creases, levels 1 and 2: the same vertices and edge count."""
        bpy.ops.mesh.primitive_cube_add()
        ob = bpy.context.object
        bm = bmesh.new()
        bm.from_mesh(ob.data)
        bm.verts.ensure_lookup_table()
        v0 = bm.verts[0]
        a = bm.verts.new(v0.co + Vector((-1.0, -1.0, -1.0)))
        b = bm.verts.new(v0.co + Vector((-2.0, -1.5, -1.0)))
        bm.edges.new((v0, a))
        bm.edges.new((a, b))
        far = max(bm.verts[:8], key=lambda v: (v.co - v0.co).length)
        bm.edges.new((v0, far))  # through the cube: both ends on faces
        bm.verts.new((5.0, 5.0, 5.0))  # an isolated vertex
        bm.to_mesh(ob.data)
        bm.free()
        corner = np.array(ob.data.vertices[0].co[:], np.float32)
        add_modifier(ob, scheme='CATMULL_CLARK', cap='REFINE', levels=2)
        for use_creases in (True, False):
            for L in (1, 2):
                ob.ccnurbs.use_creases = use_creases
                ob.ccnurbs.levels = L
                me_ours = ob.evaluated_get(update()).data
                ours = cagelib.mesh_positions(me_ours)
                self.assertIsNone(ccn.sync.status(ob).error)
                self.assertTrue((ours == corner).all(axis=1).any(), "the corner moved")
                cp = ob.copy()
                cp.data = ob.data.copy()
                bpy.context.scene.collection.objects.link(cp)
                cp.modifiers.remove(ccn.modifier.get_modifier(cp))
                cp.ccnurbs.role = 'NONE'
                m = cp.modifiers.new("Subsurf", 'SUBSURF')
                m.levels, m.use_limit_surface, m.quality = L, True, QUALITY
                m.use_creases = use_creases
                me = cp.evaluated_get(update()).data
                ref = cagelib.mesh_positions(me)
                n_edges = len(me.edges)
                bpy.data.objects.remove(cp)
                size = float(np.linalg.norm(ref.max(0) - ref.min(0)))
                self.assertEqual(len(ours), len(ref), "vertex count, level %d" % L)
                self.assertEqual(len(me_ours.edges), n_edges, "edge count, level %d" % L)
                d = set_distance(ours, ref) / size
                self.assertLessEqual(d, TOL, "use_creases %s, level %d" % (use_creases, L))
        print("measure creases: cube with loose edges and vertices vs Subdivision Surface, "
              "levels 1-2: %.2e of size" % d)
