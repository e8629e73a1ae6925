"""The modifier on a plain cage: equals `ccnurbs limit`, live updates, render levels, errors,
save/reload without the add-on, panels, remove."""
import contextlib

from bltest import *  # noqa: F401,F403

import case_creases


class TestModifier(AddonTestCase):
    def test_matches_cli_settings(self):
        cases = [dict(scheme='EIGEN', cap='GUIDED_BI5', boundary_smooth='ALL', levels=2),
                 dict(scheme='NURSS', cap='REFINE', boundary_smooth='PRESERVE_CORNERS', levels=3),
                 dict(scheme='CATMULL_CLARK', cap='GUIDED_BI5', boundary_smooth='ALL', levels=1)]
        ob = load_cage("Fig16", os.path.join(DATA, "fig16_v6.obj"))
        add_modifier(ob)
        for c in cases:
            with self.subTest(**c):
                for k, v in c.items():
                    setattr(ob.ccnurbs, k, v)
                self.assertMatchesCLI(ob)

    def test_structure(self):
        ob = load_cage("Fan5", os.path.join(DATA, "fan5.obj"))
        mats = [bpy.data.materials.new("A"), bpy.data.materials.new("B")]
        for m in mats:
            ob.data.materials.append(m)
        mi = np.zeros(len(ob.data.polygons), np.int32)
        mi[:5] = 1
        ob.data.polygons.foreach_set("material_index", mi)
        add_modifier(ob)
        ev = ob.evaluated_get(update()).data
        self.assertEqual([m.original for m in ev.materials], mats, "materials on the limit")
        emi = np.empty(len(ev.polygons), np.int32)
        ev.polygons.foreach_get("material_index", emi)
        self.assertEqual(int((emi == 1).sum()), 5 * 16, "each cage quad → 16 faces at level 2")
        mod = ob.modifiers["CCNURBS"]
        self.assertEqual(mod.type, 'NODES')
        self.assertEqual(ob.modifiers[0], mod)
        s = ob.ccnurbs
        self.assertEqual((s.levels, s.render_levels, s.scheme, s.cap, s.boundary_smooth),
                         (2, 3, 'EIGEN', 'GUIDED_BI5', 'ALL'))
        for p in ccn.modifier.proxies(ob):
            self.assertEqual(len(p.users_collection), 0, "proxy must not be in a scene")
        self.assertNotIn(ccn.modifier.proxy(ob, 'VIEW'), list(bpy.context.scene.objects))
        # the limit mesh as written (its edges given by the library on 4.0+): Blender's own
        # check finds nothing to fix, and its edges are those of its faces
        pm = ccn.modifier.proxy(ob, 'VIEW').data
        self.assertIs(pm.copy().validate(verbose=True), False, "the limit mesh needed fixing")
        corner_edges = np.empty(len(pm.loops), np.int32)
        pm.loops.foreach_get("edge_index", corner_edges)
        lv = np.empty(len(pm.loops), np.int32)
        pm.loops.foreach_get("vertex_index", lv)
        ev = np.empty(2 * len(pm.edges), np.int32)
        pm.edges.foreach_get("vertices", ev)
        nxt = lv.reshape(-1, 4)[:, [1, 2, 3, 0]].ravel()
        pairs = np.sort(np.column_stack([lv, nxt]), 1)
        self.assertEqual(len(pm.edges), len(np.unique(pairs, axis=0)))
        np.testing.assert_array_equal(np.sort(ev.reshape(-1, 2)[corner_edges], 1), pairs)

    def test_closed_cage_with_ngons(self):
        ob = add_modifier(load_cage("Prism", os.path.join(DATA, "ngon_prism.obj")), levels=2)
        self.assertMatchesCLI(ob)

    def test_live_updates(self):
        ob = load_cage("Fan5", os.path.join(DATA, "fan5.obj"))
        me = ob.data
        cagelib.set_knots(me, {k: 1.0 for k in cagelib.edge_keys(me)})
        add_modifier(ob)
        self.assertMatchesCLI(ob)
        proxy_me = ccn.modifier.proxy(ob, 'VIEW').data
        loops_before = np.empty(len(proxy_me.loops), np.int32)
        proxy_me.loops.foreach_get("vertex_index", loops_before)
        st = dict(ccn.sync.stats)

        # move a vertex: one position update, same proxy topology, bounded handler calls
        me.vertices[0].co.z += 0.7
        me.update()
        self.assertMatchesCLI(ob)
        d = {k: ccn.sync.stats[k] - st[k] for k in st}
        self.assertEqual(d["position_updates"], 1, d)
        self.assertEqual(d["rebuilds"], 0, d)
        self.assertLessEqual(d["handler_calls"], 3, d)
        loops_after = np.empty(len(proxy_me.loops), np.int32)
        ccn.modifier.proxy(ob, 'VIEW').data.loops.foreach_get("vertex_index", loops_after)
        self.assertIs(ccn.modifier.proxy(ob, 'VIEW').data, proxy_me)
        np.testing.assert_array_equal(loops_before, loops_after)

        # nothing changed: further updates do nothing (no loop)
        st = dict(ccn.sync.stats)
        for _ in range(3):
            update()
        self.assertEqual(ccn.sync.stats["syncs"], st["syncs"])
        # what a proxy write looks like to the depsgraph (the cage is re-evaluated because its
        # modifier reads the proxy): the handler runs, sees the same content key, writes nothing
        st = dict(ccn.sync.stats)
        ccn.modifier.proxy(ob, 'VIEW').data.update()
        ccn.modifier.proxy(ob, 'RENDER').data.update()
        update()
        d = {k: ccn.sync.stats[k] - st[k] for k in st}
        self.assertGreaterEqual(d["handler_calls"], 1, d)
        self.assertGreaterEqual(d["skipped"], 1, d)
        self.assertEqual(d["syncs"], 0, d)

        # change an interval (ring of the first spoke) → a new plan with the new intervals;
        # the limit mesh keeps its faces, so the proxy is updated in place, not rebuilt
        st = dict(ccn.sync.stats)
        k = cagelib.get_knots(me)
        k[0] = 6.0
        me.attributes["knot_interval"].data.foreach_set("value", k)
        me.update()
        self.assertMatchesCLI(ob)
        d = {k: ccn.sync.stats[k] - st[k] for k in st}
        self.assertEqual(d["syncs"], 1, d)
        self.assertEqual(d["rebuilds"], 0, d)
        self.assertEqual(d["position_updates"], 1, d)
        self.assertIs(ccn.modifier.proxy(ob, 'VIEW').data, proxy_me)
        ccn.modifier.proxy(ob, 'VIEW').data.loops.foreach_get("vertex_index", loops_after)
        np.testing.assert_array_equal(loops_before, loops_after)
        # more interval edits, each plan made from the one before (options.previous): a new
        # largest interval, a small one, the largest back to 1: each equals `ccnurbs limit`,
        # and each wrote only what it changed into the outputs of the plan before
        # (ccn_plan_evaluate_changed: the previous edit's outputs are the plan's own arrays)
        st = dict(ccn.sync.stats)
        for e, v in ((5, 9.0), (3, 0.25), (0, 1.0)):
            k[e] = v
            me.attributes["knot_interval"].data.foreach_set("value", k)
            me.update()
            self.assertMatchesCLI(ob)
        self.assertEqual(ccn.sync.stats["changed_only"] - st["changed_only"], 3)

        # levels → new vertex count
        n2 = len(evaluated_positions(ob))
        ob.ccnurbs.levels = 3
        self.assertGreater(len(self.assertMatchesCLI(ob)), n2)

    @contextlib.contextmanager
    def deferring(self):
        """What an interactive session defers (exact normals before 4.5, the analysis) is
        deferred here too; write_pending_normals() is the pause's timer."""
        h = ccn.handlers
        h.DEFER_IN_BACKGROUND[0] = True
        try:
            yield h
        finally:
            h.DEFER_IN_BACKGROUND[0] = False
            ccn.state.clear_field("pending_normals", False)

    def edit_twice(self, ob, check):
        """Two edits in a row (the second while the first is still pending), check() after each."""
        for step in range(2):
            ob.data.vertices[step].co.z += 0.3
            ob.data.update()
            update()
            check()

    def test_exact_normals_after_editing_pauses(self):
        """Blender < 4.5 (encoded custom normals, 5x the rest of an update): while editing the
        limit has Blender's own normals and its exact normals follow once editing pauses (the
        handlers' timer; here called directly, scripts do not defer). 4.5+: exact at once."""
        ob = load_cage("Fig16", os.path.join(DATA, "fig16_v6.obj"))
        add_modifier(ob, levels=2)

        def check():
            key = ccn.modifier.proxy(ob, 'VIEW').data.get(ccn.proxies.KEY_PROP)
            if ccn.compat.FREE_NORMALS:
                self.assertMatchesCLI(ob)
                self.assertEqual(ccn.sync.pending_normals(), [])
                self.assertFalse(key.endswith(ccn.sync.PENDING), key)
                return
            self.assertMatchesCLI(ob, normals=False)  # positions exact at once
            self.assertEqual(ccn.sync.pending_normals(), [ob])
            self.assertTrue(key.endswith(ccn.sync.PENDING), key)
            me = ccn.modifier.proxy(ob, 'VIEW').data
            # < 4.1: custom normals are shown only with auto smooth, which is turned off;
            # 4.1-4.4 have no cheap way to drop them (the last exact ones stay shown until
            # the pending ones are written, below)
            if hasattr(me, "use_auto_smooth"):
                self.assertIs(me.use_auto_smooth, False, "custom normals still shown")

        with self.deferring() as h:
            self.edit_twice(ob, check)
            st = dict(ccn.sync.stats)
            h.write_pending_normals()
            update()
            self.assertMatchesCLI(ob)  # the exact normals
            self.assertEqual(ccn.sync.pending_normals(), [])
            key = ccn.modifier.proxy(ob, 'VIEW').data.get(ccn.proxies.KEY_PROP)
            self.assertFalse(key.endswith(ccn.sync.PENDING), key)
            self.assertLessEqual(ccn.sync.stats["syncs"] - st["syncs"],
                                 0 if ccn.compat.FREE_NORMALS else 1)
            for _ in range(2):  # and then nothing more to do
                update()
            self.assertEqual(ccn.sync.stats["syncs"] - st["syncs"],
                             0 if ccn.compat.FREE_NORMALS else 1)

    def test_edit_mode_updates(self):
        ob = add_modifier(grid(4))
        bpy.ops.object.mode_set(mode='EDIT')
        bm = bmesh.from_edit_mesh(ob.data)
        bm.verts.ensure_lookup_table()
        bm.verts[12].co.z = 1.5
        bmesh.update_edit_mesh(ob.data)
        P = evaluated_positions(ob)  # still in edit mode
        self.assertGreater(P[:, 2].max(), 0.5, "edit-mode move did not update the limit")
        edit_select_edges(ob, [0])
        bpy.ops.mesh.ccnurbs_set_knot_interval(value=5.0)
        P2 = evaluated_positions(ob)
        self.assertGreater(np.abs(P2 - P).max(), 1e-4, "edit-mode interval did not update")
        bpy.ops.object.mode_set(mode='OBJECT')
        R, _ = reference(ob)
        np.testing.assert_allclose(P2, R, atol=POS_TOL)

    def test_topology_key_memo_never_stale(self):
        """The memo returns the last keys only when every hashed input is equal: each change
        (an interval, a crease, a face, a material, a vertex count, a setting) gives the keys
        a fresh hash gives."""
        ob = grid(3, "Memo")
        cage = ccn.cage.read_mesh(ob.data)
        memo = {}
        first = cage.topology_keys(2, "x", creases=True, memo=memo)
        self.assertEqual(first, cage.topology_keys(2, "x", creases=True))
        again = ccn.cage.read_mesh(ob.data)  # new arrays, same values: the memo answers
        self.assertEqual(again.topology_keys(2, "x", creases=True, memo=memo), first)
        changes = {
            "knots": lambda c: setattr(c, "knots", np.full(c.num_edges, 2.0)),
            "creases": lambda c: setattr(c, "edge_creases", np.full(c.num_edges, 0.5)),
            "faces": lambda c: setattr(c, "face_verts", np.roll(c.face_verts, 1)),
            "materials": lambda c: setattr(c, "material_index", c.material_index + 1),
            "vertices": lambda c: setattr(c, "positions", np.zeros((c.num_verts + 1, 3))),
        }
        for what, change in changes.items():
            with self.subTest(change=what):
                c = ccn.cage.read_mesh(ob.data)
                change(c)
                m = dict(memo)
                got = c.topology_keys(2, "x", creases=True, memo=m)
                self.assertEqual(got, c.topology_keys(2, "x", creases=True))
                self.assertNotEqual(got, first)
        m = dict(memo)
        self.assertNotEqual(cage.topology_keys(3, "x", creases=True, memo=m), first)

    def test_edit_mode_moves_run_no_hygiene(self):
        """A move in Edit Mode changes no data-block count: no hygiene pass, no mesh created
        or removed (each would rebuild the depsgraph relations on every update). 4.x reads the
        edit mesh through the scratch mesh (3.4 does not need it)."""
        ob = add_modifier(grid(4, "EditCost"))
        bpy.ops.object.mode_set(mode='EDIT')
        bm = bmesh.from_edit_mesh(ob.data)
        bm.verts.ensure_lookup_table()
        hyg = ccn.handlers.hygiene
        real, calls = hyg.collect, []

        def counting():
            calls.append(1)
            return real()
        try:
            for r in range(4):
                if r == 1:
                    hyg.collect = counting  # after the first edit-mode update
                    meshes = len(bpy.data.meshes)
                bm.verts[12].co.z = 0.25 * (r + 1)
                bmesh.update_edit_mesh(ob.data)
                P = evaluated_positions(ob)
                self.assertGreater(P[:, 2].max(), 0.05 * (r + 1))
        finally:
            hyg.collect = real
            bpy.ops.object.mode_set(mode='OBJECT')
        self.assertEqual(calls, [], "edit-mode moves ran the hygiene pass")
        self.assertEqual(len(bpy.data.meshes), meshes)

    @staticmethod
    def _probe_render(ob, idname, during=None):
        """Renders one frame with a probe engine; returns what the engine saw of ob's own
        geometry: {"verts": count, "positions": array}. during: a context manager the render
        runs inside (e.g. to capture the console)."""
        seen = {}

        class ProbeEngine(bpy.types.RenderEngine):
            bl_idname = idname
            bl_label = "probe"

            def render(self, depsgraph):
                for inst in depsgraph.object_instances:
                    if inst.object.original.name == ob.name and not inst.is_instance:
                        seen["verts"] = len(inst.object.data.vertices)
                        seen["positions"] = cagelib.mesh_positions(inst.object.data)
                r = self.begin_result(0, 0, 4, 4)
                self.end_result(r)

        import contextlib
        bpy.utils.register_class(ProbeEngine)
        try:
            scene = bpy.context.scene
            cam = bpy.data.objects.new("Cam", bpy.data.cameras.new("Cam"))
            scene.collection.objects.link(cam)
            scene.camera = cam
            scene.render.engine = ProbeEngine.bl_idname
            scene.render.resolution_x = scene.render.resolution_y = 4
            with during if during is not None else contextlib.nullcontext():
                bpy.ops.render.render()
        finally:
            bpy.utils.unregister_class(ProbeEngine)
        return seen

    def test_render_uses_render_levels(self):
        ob = add_modifier(load_cage("Fan5", os.path.join(DATA, "fan5.obj")), levels=1,
                          render_levels=3)
        n_view = len(evaluated_positions(ob))
        seen = self._probe_render(ob, "CCNURBS_TEST_PROBE")
        R, _ = reference(ob, levels=3)
        self.assertIn("verts", seen, "render did not see the cage")
        self.assertEqual(seen["verts"], len(R))
        np.testing.assert_allclose(seen["positions"], R, atol=POS_TOL)
        self.assertEqual(len(evaluated_positions(ob)), n_view, "viewport result not restored")
        self.assertMatchesCLI(ob, normals=False)

    def test_refused_render_levels_are_said(self):
        """Render levels that would not fit in memory are refused; the render then shows the
        viewport limit and reports it as an error (the console line Blender prints for its own
        errors; in the UI also a popup when the render ends), not silently."""
        import contextlib
        import io
        ob = add_modifier(load_cage("Fan5R", os.path.join(DATA, "fan5.obj")), levels=1,
                          render_levels=10)
        n_view = len(evaluated_positions(ob))
        out = io.StringIO()
        free = ccn.memory.free_bytes
        ccn.memory.free_bytes = lambda: 50 * 2 ** 20
        try:
            seen = self._probe_render(ob, "CCNURBS_TEST_PROBE2", contextlib.redirect_stdout(out))
        finally:
            ccn.memory.free_bytes = free
        self.assertEqual(seen.get("verts"), n_view, "the render shows the viewport limit")
        self.assertIn("Error: CCNURBS: Fan5R: Render levels 10 not rendered", out.getvalue())
        self.assertIn("rendering the viewport limit", out.getvalue())
        # headless: no window for the popup; the timer that shows it returns quietly
        self.assertFalse(ccn.handlers._render_errors, "errors kept after a headless render")
        ccn.handlers._render_errors.append("probe")
        self.assertIsNone(ccn.handlers._show_render_errors())
        self.assertFalse(ccn.handlers._render_errors)

    def test_curvature_analysis_equals_the_cli(self):
        """Analysis > Curvature writes the exact principal curvatures as point attributes
        (curvature_gaussian, curvature_mean, equal to `ccnurbs limit --curvature` of the same
        cage), flags where they are undefined, colours the chosen one (the active colour
        attribute), and Off removes them."""
        ob = add_modifier(load_cage("Curv", os.path.join(DATA, "fig16_v6.obj")), levels=2)
        names = ccn.analysis.NAMES
        self.assertFalse(any(n in ob.evaluated_get(update()).data.attributes for n in names),
                         "analysis attributes while it is off")
        for mode in ('MEAN', 'GAUSSIAN', 'MAX'):
            ob.ccnurbs.curvature = mode
            me = ob.evaluated_get(update()).data
            for n in names:
                self.assertIn(n, me.attributes, "%s: no attribute %s" % (mode, n))
            got = {}
            for n in names[:2]:
                a = np.empty(len(me.vertices), np.float32)
                me.attributes[n].data.foreach_get("value", a)
                got[n] = a.astype(np.float64)
            flag = np.empty(len(me.vertices), bool)
            me.attributes[names[2]].data.foreach_get("value", flag)
            R, K = cagelib.cli_curvature(CLI, ob.data, 2)
            self.assertEqual(len(R), len(me.vertices))
            bad = ~np.isfinite(K).all(1)
            np.testing.assert_array_equal(flag, bad, "undefined where the CLI writes nan")
            self.assertGreater((~bad).sum(), len(bad) // 2, "hardly any curvature computed")
            k1, k2 = K[~bad, 0], K[~bad, 1]
            for n, want in ((names[0], k1 * k2), (names[1], 0.5 * (k1 + k2))):
                err = np.abs(got[n][~bad] - want).max() / np.abs(want).max()
                self.assertLessEqual(err, 1e-5, "%s %s differs from the CLI by %.3g" % (mode, n, err))
            self.assertTrue((got[names[0]][bad] == 0).all() and (got[names[1]][bad] == 0).all())
            self.assertTrue(ccn.ui.curvature_legend(ob), "no legend in the panel")
        ob.ccnurbs.curvature = 'NONE'
        me = ob.evaluated_get(update()).data
        self.assertFalse(any(n in me.attributes for n in names), "Off left the attributes")
        self.assertMatchesCLI(ob)

    def test_curvature_follows_once_editing_pauses(self):
        """Interactive edits with Analysis > Curvature on: the update writes the surface (and
        its normals) at once and the curvature attributes once editing pauses (the handlers'
        timer; here called directly), so a drag costs what it costs without analysis. Then the
        attributes equal `ccnurbs limit --curvature` of the edited cage; a frame change computes
        them at once (a viewport render of an animation shows each frame's)."""
        ob = add_modifier(load_cage("CurvLater", os.path.join(DATA, "fig16_v6.obj")), levels=2)
        ob.ccnurbs.curvature = 'MEAN'
        name = ccn.analysis.NAMES[1]

        def mean_now():
            me = ob.evaluated_get(update()).data
            a = np.empty(len(me.vertices), np.float32)
            me.attributes[name].data.foreach_get("value", a)
            return a.astype(np.float64)

        def mean_cli():
            _, K = cagelib.cli_curvature(CLI, ob.data, 2)
            good = np.isfinite(K).all(1)
            return np.where(good, 0.5 * (K[:, 0] + K[:, 1]), 0.0)

        before = mean_now()

        def check():
            self.assertMatchesCLI(ob, normals=False)  # the surface at once
            self.assertEqual(ccn.sync.pending_normals(), [ob])
            np.testing.assert_array_equal(mean_now(), before, "the curvature while pending")

        with self.deferring() as h:
            self.edit_twice(ob, check)
            want = mean_cli()
            scale = np.abs(want).max()
            self.assertGreater(np.abs(want - before).max(), 1e-3 * scale, "the edit changed nothing")
            h.write_pending_normals()
            self.assertEqual(ccn.sync.pending_normals(), [])
            err = np.abs(mean_now() - want).max() / scale
            self.assertLessEqual(err, 1e-5, "after the pause: %.3g from the CLI" % err)
            self.assertMatchesCLI(ob)
            # a frame change: at once
            ob.data.vertices[2].co.z += 0.3
            ob.data.update()
            bpy.context.scene.frame_set(bpy.context.scene.frame_current + 1)
            err = np.abs(mean_now() - mean_cli()).max() / scale
            self.assertLessEqual(err, 1e-5, "a frame's curvature: %.3g from the CLI" % err)

    def test_highlight_lines(self):
        """Analysis > Highlight Lines: Solid shading with the add-on's stripe matcap in the
        scene's Workbench settings (and every 3D view), rendered as stripes; Off restores Studio
        lighting. The matcap is a studio light, not data in the file."""
        ob = add_modifier(load_cage("Stripes", os.path.join(DATA, "fig16_v6.obj")), levels=3)
        res = bpy.ops.view3d.ccnurbs_highlight_lines(show=True)
        self.assertEqual(res, {'FINISHED'})
        sh = bpy.context.scene.display.shading
        self.assertEqual((sh.light, sh.studio_light), ('MATCAP', ccn.analysis.matcap_name()))
        scene = bpy.context.scene
        cam = bpy.data.objects.new("Cam", bpy.data.cameras.new("Cam"))
        scene.collection.objects.link(cam)
        cam.location, cam.rotation_euler = (0.0, 0.0, 12.0), (0.0, 0.0, 0.0)
        scene.camera = cam
        scene.render.engine = 'BLENDER_WORKBENCH'
        scene.render.resolution_x = scene.render.resolution_y = 96
        scene.render.filepath = os.path.join(TMP, "stripes.png")
        bpy.ops.render.render(write_still=True)
        im = bpy.data.images.load(scene.render.filepath)
        v = np.array(im.pixels[:]).reshape(96, 96, 4)[24:72, 24:72, 0]
        bpy.data.images.remove(im)
        # stripes: light and dark bands alternate along a row through the surface
        row = v[24]
        flips = int(np.sum(np.abs(np.diff((row > row.mean()).astype(int)))))
        self.assertGreaterEqual(flips, 4, "no stripes in the render (%d light/dark changes)" % flips)
        self.assertFalse([i.name for i in bpy.data.images if "stripes" in i.name],
                         "the matcap left an image in the file")
        # zebra stripes of the other directions and densities: other matcaps
        for direction, n in (('HORIZONTAL', 8), ('VERTICAL', 30)):
            bpy.ops.view3d.ccnurbs_highlight_lines(show=True, direction=direction, stripes=n)
            self.assertEqual(sh.studio_light, ccn.analysis.matcap_name(direction, n))
            names = [sl.name for sl in bpy.context.preferences.studio_lights]
            self.assertIn(ccn.analysis.matcap_name(direction, n), names)
        bpy.ops.view3d.ccnurbs_highlight_lines(show=False)
        self.assertEqual(sh.light, 'STUDIO')
        self.assertMatchesCLI(ob)

    def test_cap_status(self):
        """Analysis > Cap Status marks each extraordinary point: a cube's 8 corners capped
        (uniform intervals), refined with Cap = Refine; the valence-7 point of Fig. 17 (spoke
        ratio 8) refined, with Cap = G1 Fill closed by the fill cap (the surface the CLI's
        --cap fill gives); the marks sit on the surface's vertices; off, none."""
        ob = add_modifier(cube("CapCube"), levels=3)
        ob.ccnurbs.cap_status = True
        update()
        self.assertIn("8 capped (green), 0 blended (yellow), 0 refined", ccn.ui.cap_status_line(ob))
        marks = ccn.state.of(ob).ev_marks
        P = evaluated_positions(ob)
        d = np.abs(marks["coords"][:, None, :] - P[None]).max(2).min(1)
        self.assertLessEqual(d.max(), 1e-5, "a mark is not on a vertex of the surface")
        ob.ccnurbs.cap = 'REFINE'
        update()
        self.assertIn("0 capped (green), 0 blended (yellow), 8 refined", ccn.ui.cap_status_line(ob))
        fig = add_modifier(load_cage("Fig17", os.path.join(DATA, "fig17_v7.obj")), levels=3)
        fig.ccnurbs.cap_status = True
        update()
        self.assertIn("0 capped (green), 0 blended (yellow), 1 refined", ccn.ui.cap_status_line(fig))
        fig.ccnurbs.cap = 'G1_FILL'
        update()
        self.assertIn("0 refined (red: unbounded curvature), 1 G1 fill (blue)", ccn.ui.cap_status_line(fig))
        self.assertMatchesCLI(fig)
        fig.ccnurbs.cap_status = False
        update()
        self.assertIsNone(ccn.ui.cap_status_line(fig))
        self.assertIsNone(ccn.state.of(fig).ev_marks)

    def _reload_without_addon(self, path):
        """(viewport positions of Fig16, vertex counts of both proxies) in a fresh Blender
        without the add-on."""
        out = os.path.join(TMP, "reload.npy")
        script = os.path.join(TMP, "reload_check.py")
        with open(script, "w") as fh:
            fh.write(
                "import bpy, numpy as np, sys\n"
                "assert not hasattr(bpy.types.Object, 'ccnurbs')\n"
                "ob = bpy.data.objects['Fig16']\n"
                "dg = bpy.context.evaluated_depsgraph_get()\n"
                "me = ob.evaluated_get(dg).data\n"
                "co = np.empty(3 * len(me.vertices), np.float32)\n"
                "me.vertices.foreach_get('co', co)\n"
                "n = [len(o.data.vertices) for p in ('.CCNURBS view', '.CCNURBS render')\n"
                "     for o in bpy.data.objects if o.name.startswith(p)]\n"
                "np.save(%r, co.reshape(-1, 3))\n"
                "np.save(%r, np.array(n))\n" % (out, out + ".n.npy"))
        r = subprocess.run(blender_command(script, path), capture_output=True, text=True,
                           timeout=120)
        self.assertEqual(r.returncode, 0, r.stdout[-2000:] + r.stderr[-2000:])
        return np.load(out).astype(np.float64), list(np.load(out + ".n.npy"))

    def test_save_reload_without_addon(self):
        """Default: the file holds the cage and empty proxies; without the add-on it shows the
        cage (as a file with Subsurf shows what Blender computes, here nothing to compute)."""
        ob = load_cage("Fig16", os.path.join(DATA, "fig16_v6.obj"))
        add_modifier(ob, scheme='NURSS', levels=2, render_levels=3)
        ob.data.vertices[0].co.z = 1.3
        ob.data.update()
        update()
        path = os.path.join(TMP, "reload.blend")
        bpy.ops.wm.save_as_mainfile(filepath=path)
        self.assertMatchesCLI(ob)  # the session keeps its limit across the save
        P, counts = self._reload_without_addon(path)
        np.testing.assert_array_equal(P, cagelib.mesh_positions(ob.data))
        self.assertEqual(counts, [0, 0], "proxy meshes were saved")

    def test_store_render_mesh_in_file(self):
        """Store Render Mesh in File: the render-levels limit is in the file and shows (viewport
        and render) where the add-on is not installed; the panel states its size."""
        ob = load_cage("Fig16", os.path.join(DATA, "fig16_v6.obj"))
        add_modifier(ob, scheme='NURSS', levels=2, render_levels=3)
        ob.ccnurbs.store_render_mesh = True
        ob.data.vertices[0].co.z = 1.3
        ob.data.update()
        update()
        R3, _ = reference(ob, levels=3)
        bpy.context.view_layer.objects.active = ob
        shown = labels(draw_panel(ccn.ui.DATA_PT_ccnurbs_modifier))
        self.assertRegex(shown, r"Render mesh in file: %d vertices, [0-9.]+ MB" % len(R3))
        path = os.path.join(TMP, "reload_store.blend")
        bpy.ops.wm.save_as_mainfile(filepath=path)
        P, counts = self._reload_without_addon(path)
        self.assertEqual(counts, [0, len(R3)])
        self.assertEqual(P.shape, R3.shape)
        self.assertLessEqual(np.abs(P - R3).max(), POS_TOL)
        ob.ccnurbs.store_render_mesh = False
        update()
        shown = labels(draw_panel(ccn.ui.DATA_PT_ccnurbs_modifier))
        self.assertIn("Render mesh: computed per frame when rendering, not saved", shown)
        self.assertEqual(len(ccn.modifier.proxy(ob, 'RENDER').data.vertices), 0)

    def test_non_manifold_edit_keeps_a_live_surface(self):
        """An edit that makes the cage non-manifold (a third face on an edge, two faces wound
        against each other) updates the surface as Subdivision Surface would: no error, the
        counts of Subdivision Surface (case_creases compares the positions)."""
        ob = add_modifier(grid(2))
        me = ob.data
        bm = bmesh.new()
        bm.from_mesh(me)
        bm.verts.ensure_lookup_table()
        a, b = bm.verts[1], bm.verts[4]
        bm.faces.new((a, b, bm.verts.new((1.0, 0.5, 1.0))))
        bm.to_mesh(me)
        bm.free()
        me.update()
        P = evaluated_positions(ob)
        st = ccn.sync.status(ob)
        self.assertIsNone(st.error, st.error)
        self.assertTrue(np.isfinite(P).all())
        self.assertEqual(len(P), len(case_creases.subsurf_positions(ob, ob.ccnurbs.levels)))
        ob2 = grid(1, "Fan")
        bm = bmesh.new()
        bm.from_mesh(ob2.data)
        bm.verts.ensure_lookup_table()
        a, b = bm.verts[0], bm.verts[1]
        bm.faces.new((b, a, bm.verts.new((0.5, -0.5, 1.0))))
        bm.faces.new((a, b, bm.verts.new((0.5, 0.5, -1.0))))
        bm.to_mesh(ob2.data)
        bm.free()
        add_modifier(ob2)
        P2 = evaluated_positions(ob2)
        st = ccn.sync.status(ob2)
        self.assertIsNone(st.error, st.error)
        self.assertEqual(len(P2), len(case_creases.subsurf_positions(ob2, ob2.ccnurbs.levels)))

    def test_levels_zero_shows_the_cage(self):
        """Levels 0 shows the cage itself, as Subdivision Surface does (not the limit of the
        cage's vertices, not one level of the split of its triangles and n-gons): positions,
        faces and UVs as the cage's, in the viewport, after Apply and after save and reopen;
        Levels 1 brings the limit back."""
        V = np.array([(0, 0, 0), (1, 0, 0.2), (2, 0, 0), (0, 1, 0.1), (1, 1, 0.5), (2, 1, 0),
                      (1, 2, 0.3), (2.5, 0.5, 0)], float)
        F = [(0, 1, 4, 3), (1, 2, 5, 4), (3, 4, 6), (2, 7, 5)]  # quads and triangles
        ob = load_cage("Zero", V=V, F=F, K={})
        bpy.ops.mesh.primitive_circle_add(vertices=7, fill_type='NGON', location=(4, 0, 0))
        ng = bpy.context.object
        for o in (ob, ng):
            o.data.uv_layers.new(name="UVMap")
            uv = np.random.default_rng(1).random(2 * len(o.data.loops)).astype(np.float32)
            o.data.uv_layers[0].data.foreach_set("uv", uv)
            add_modifier(o, levels=0, render_levels=2)
            me = o.evaluated_get(update()).data
            self.assertEqual(len(me.vertices), len(o.data.vertices))
            self.assertEqual(len(me.polygons), len(o.data.polygons))
            np.testing.assert_array_equal(cagelib.mesh_positions(me), cagelib.mesh_positions(o.data))
            got = np.zeros(2 * len(me.loops), np.float32)
            me.uv_layers[0].data.foreach_get("uv", got)
            np.testing.assert_array_equal(got, uv)
            st = ccn.sync.status(o)
            self.assertIsNone(st.error, st.error)
            self.assertIn("Levels 0: the cage", ccn.ui.status_lines(o)[0])
            # Subdivision Surface at Levels 0 shows the same
            np.testing.assert_array_equal(evaluated_positions(o),
                                          case_creases.subsurf_positions(o, 0))
            o.ccnurbs.levels = 1
            self.assertMatchesCLI(o)
            o.ccnurbs.levels = 0
            np.testing.assert_array_equal(evaluated_positions(o), cagelib.mesh_positions(o.data))
        path = os.path.join(TMP, "levels0.blend")
        bpy.ops.wm.save_as_mainfile(filepath=path)
        bpy.ops.wm.open_mainfile(filepath=path)
        ob = bpy.data.objects["Zero"]
        np.testing.assert_array_equal(evaluated_positions(ob), cagelib.mesh_positions(ob.data))
        for o in bpy.context.view_layer.objects:
            o.select_set(o == ob)
        bpy.context.view_layer.objects.active = ob
        bpy.ops.object.modifier_apply(modifier=ccn.modifier.get_modifier(ob).name)
        self.assertEqual(len(ob.data.polygons), len(F))
        np.testing.assert_array_equal(cagelib.mesh_positions(ob.data), V.astype(np.float32))

    def test_levels_that_do_not_fit_are_refused(self):
        """A Levels value whose limit mesh would not fit in the free memory is refused before
        anything is allocated (addon/memory.py), the last limit stays, nothing crashes."""
        bpy.ops.mesh.primitive_monkey_add()
        ob = add_modifier(bpy.context.object, levels=1)
        sizes = np.array([p.loop_total for p in ob.data.polygons])
        for L in (1, 2):  # the estimate counts the faces the plan makes
            ob.ccnurbs.levels = L
            update()
            self.assertEqual(ccn.memory.limit_faces(sizes, L), ccn.sync.status(ob).num_faces)
        good = evaluated_positions(ob)
        ob.ccnurbs.levels = 10  # 500 million faces, ~800 GB: refused on any machine
        P = evaluated_positions(ob)
        st = ccn.sync.status(ob)
        self.assertIn("levels 10 would make 515.9 million faces, about 768.8 GB, but ", st.error or "")
        self.assertIn("of memory is free: lower Levels Viewport", st.error)
        self.assertEqual(st.showing, "last valid limit")
        np.testing.assert_array_equal(P, good)  # the last limit stays
        self.assertIn("lower the levels", ccn.errors.advice(st))
        # with 50 MB free, levels 3 (32k faces, ~51 MB) is refused, and built once it fits
        free = ccn.memory.free_bytes
        try:
            ccn.memory.free_bytes = lambda: 50 * 2 ** 20
            ob.ccnurbs.levels = 3
            update()
            self.assertIn("of memory is free", ccn.sync.status(ob).error or "")
            ccn.memory.free_bytes = lambda: 100 * 2 ** 20
            ob.ccnurbs.levels = 2
            ob.ccnurbs.levels = 3
            update()
            self.assertIsNone(ccn.sync.status(ob).error)
        finally:
            ccn.memory.free_bytes = free
        self.assertGreater(len(evaluated_positions(ob)), len(good))

    def test_subsurf_above_is_pointed_out(self):
        """CCNURBS added to an object that has Subdivision Surface goes after it (as any new
        modifier), so it takes the subdivided cage: the panel says so, and stops saying it
        once Subsurf is disabled."""
        ob = grid(2, "HadSubsurf")
        sub = ob.modifiers.new("My Subsurf", 'SUBSURF')
        sub.levels = 1
        add_modifier(ob, levels=1)
        self.assertEqual(ccn.modifier.subdivisions_above(ob), ["My Subsurf"])
        bpy.context.view_layer.objects.active = ob
        shown = labels(draw_panel(ccn.ui.DATA_PT_ccnurbs_modifier))
        self.assertIn('"My Subsurf" above CCNURBS subdivides the cage first', shown)
        self.assertEqual(ccn.sync.status(ob).sizes["num_cage_verts"], 25, "not the subdivided cage")
        sub.show_viewport = False
        update()
        self.assertEqual(ccn.modifier.subdivisions_above(ob), [])
        self.assertNotIn("subdivides the cage first", labels(draw_panel(ccn.ui.DATA_PT_ccnurbs_modifier)))
        self.assertMatchesCLI(ob)

    def test_vertex_groups_reach_modifiers_below(self):
        """A vertex group that a modifier below CCNURBS names is carried to the limit mesh as
        a real vertex group, its weights the exact limit of the cage's (the positions' rules):
        Displace (direction Z, mid-level 0) below moves each limit vertex by its weight, which
        is the z of `ccnurbs limit` of the cage lifted to z = weight. An Armature below
        (bone groups, not carried) is named in the panel."""
        ob = grid(4, "Groups")
        w = np.zeros(len(ob.data.vertices))
        w[[0, 1, 5, 6, 12]] = (1.0, 0.5, 1.0, 0.25, 0.75)
        vg = ob.vertex_groups.new(name="pin")
        for i in np.nonzero(w)[0]:
            vg.add([int(i)], float(w[i]), 'REPLACE')
        ob.vertex_groups.new(name="unused").add([3], 1.0, 'REPLACE')
        add_modifier(ob, levels=2)
        disp = ob.modifiers.new("Disp", 'DISPLACE')
        disp.direction, disp.mid_level, disp.strength, disp.vertex_group = 'Z', 0.0, 1.0, "pin"
        self.assertEqual(ccn.modifier.groups_needed_below(ob), ["pin"])
        P = evaluated_positions(ob)
        self.assertIsNone(ccn.sync.status(ob).error)
        p = ccn.modifier.proxy(ob, 'VIEW')
        self.assertEqual([g.name for g in p.vertex_groups], ["pin"])
        disp.show_viewport = False  # the limit itself (no group needed below any more)
        P0 = evaluated_positions(ob)
        lifted = ob.data.copy()
        co = cagelib.mesh_positions(lifted)
        co[:, 2] = w
        lifted.vertices.foreach_set("co", co.ravel())
        R, _ = cagelib.cli_limit(CLI, lifted, 2, ob.ccnurbs.scheme, ob.ccnurbs.cap,
                                 ob.ccnurbs.boundary_smooth)
        bpy.data.meshes.remove(lifted)
        dz = P[:, 2] - P0[:, 2]
        self.assertGreater(np.abs(dz).max(), 0.5, "nothing displaced")
        self.assertLessEqual(np.abs(dz - R[:, 2]).max(), POS_TOL, "weights are not the limit")
        # an Armature below deforms by bone groups, which are not carried: the panel says so
        disp.show_viewport = True
        ob.modifiers.new("Rig", 'ARMATURE')
        update()
        bpy.context.view_layer.objects.active = ob
        shown = " ".join(labels(draw_panel(ccn.ui.DATA_PT_ccnurbs_modifier)).split())
        self.assertIn('"Rig" below CCNURBS deforms by the vertex groups of its bones', shown)
        self.assertNotIn('"Disp"', shown)
        ob.modifiers.remove(ob.modifiers["Rig"])
        update()
        self.assertEqual([g.name for g in p.vertex_groups], ["pin"])
        # no group named below: the chains and the proxies' groups go
        disp.vertex_group = ""
        update()
        group = ccn.modifier.get_modifier(ob).node_group
        self.assertEqual(list(group.get(ccn.modifier.VG_PROP, [])), [])
        self.assertFalse([n for n in group.nodes if n.name.startswith(ccn.modifier.VG_NODE)])
        self.assertEqual(len(p.vertex_groups), 0)
        # a group from before the chains (a file saved by an older add-on: unnamed nodes) is
        # replaced by a fresh one when a group is needed below
        group.nodes[ccn.modifier.FALLBACK_NODE].name = "Switch"
        disp.vertex_group = "pin"
        update()  # the fresh proxies are written during this evaluation, shown by the next
        P2 = evaluated_positions(ob)
        fresh = ccn.modifier.get_modifier(ob).node_group
        self.assertEqual(list(fresh.get(ccn.modifier.VG_PROP, [])), ["pin"])
        np.testing.assert_allclose(P2, P, atol=POS_TOL)
        # Apply keeps the group with the limit weights, and no helper attribute
        with bpy.context.temp_override(object=ob, active_object=ob):
            bpy.ops.object.modifier_apply(modifier=ccn.modifier.get_modifier(ob).name)
        me, pin = ob.data, ob.vertex_groups["pin"].index
        got = np.array([max((g.weight for g in v.groups if g.group == pin), default=0.0)
                        for v in me.vertices])
        np.testing.assert_allclose(got, R[:, 2], atol=POS_TOL)
        self.assertFalse([a.name for a in me.attributes if a.name.startswith(ccn.modifier.VG_PREFIX)])

    def test_duplicate_gets_own_proxies(self):
        ob = add_modifier(grid(2, "Orig"))
        before = evaluated_positions(ob)
        bpy.ops.object.select_all(action='DESELECT')
        ob.select_set(True)
        bpy.context.view_layer.objects.active = ob
        bpy.ops.object.duplicate()
        dup = bpy.context.object
        self.assertIsNot(dup, ob)
        update()
        self.assertIsNot(ccn.modifier.proxy(dup, 'VIEW'), ccn.modifier.proxy(ob, 'VIEW'))
        dup.data.vertices[4].co.z = 2.0
        dup.data.update()
        update()
        np.testing.assert_array_equal(evaluated_positions(ob), before)
        self.assertGreater(evaluated_positions(dup)[:, 2].max(), 0.5)

    def _ours(self, ob):
        return [m for m in ob.modifiers if m.type == 'NODES' and ccn.modifier.is_group(m.node_group)]

    def test_duplicated_modifier_is_removed(self):
        """The modifier panel's Duplicate (object.modifier_copy): the second CCNURBS shared the
        first's group, read the first's limit as its cage and wrote the limit of the limit into
        the same proxy, growing at every edit. It is removed, with a note; the surface stays
        the cage's limit through later edits."""
        ob = add_modifier(load_cage("Fan5Dup", os.path.join(DATA, "fan5.obj")))
        n0 = len(evaluated_positions(ob))
        bpy.ops.object.modifier_copy(modifier=ccn.modifier.get_modifier(ob).name)
        update()
        self.assertEqual(len(self._ours(ob)), 1, "one CCNURBS modifier per object")
        self.assertEqual(len(evaluated_positions(ob)), n0)
        self.assertMatchesCLI(ob)
        for k in range(3):  # later edits: no growth
            ob.data.vertices[k].co.z += 0.1
            ob.data.update()
            update()
            self.assertMatchesCLI(ob, normals=False)
        bpy.context.view_layer.objects.active = ob
        self.assertIn("one per object", labels(draw_panel(ccn.ui.DATA_PT_ccnurbs_modifier)))

    def test_copy_to_selected_keeps_the_targets_surface(self):
        """Copy to Selected of the modifier onto a cage that has its own CCNURBS: the target
        keeps exactly one working modifier with its own group, showing its own limit, also
        after save and reopen."""
        src = add_modifier(grid(3, "Src"))
        dst = add_modifier(load_cage("Dst", os.path.join(DATA, "fan5.obj")))
        own_group = ccn.modifier.get_modifier(dst).node_group
        bpy.ops.object.select_all(action='DESELECT')
        dst.select_set(True)
        src.select_set(True)
        bpy.context.view_layer.objects.active = src
        if hasattr(bpy.ops.object, "modifier_copy_to_selected"):
            bpy.ops.object.modifier_copy_to_selected(modifier=ccn.modifier.get_modifier(src).name)
        else:  # what it does: the source's modifier, appended to the target
            m = dst.modifiers.new("CCNURBS.001", 'NODES')
            m.node_group = ccn.modifier.get_modifier(src).node_group
        update()
        update()
        mods = self._ours(dst)
        self.assertEqual(len(mods), 1, "one CCNURBS on the target")
        self.assertIs(mods[0].node_group, own_group)
        self.assertEqual(ccn.modifier.owner_of(mods[0].node_group), dst.name_full)
        self.assertMatchesCLI(dst)
        self.assertMatchesCLI(src)
        path = os.path.join(TMP, "ccn_copy_to_selected.blend")
        bpy.ops.wm.save_as_mainfile(filepath=path)
        bpy.ops.wm.open_mainfile(filepath=path)
        dst = bpy.data.objects["Dst"]
        self.assertEqual(len(self._ours(dst)), 1)
        self.assertMatchesCLI(dst)

    def test_a_part_ignores_a_disconnected_part(self):
        """The limit of a part of a cage is the same whatever else the cage holds: a fan with
        non-uniform intervals and extraordinary points, alone and next to a pentagon with much
        larger intervals (it changes the intervals' normalisation and splits an n-gon)."""
        V, F, K = cagelib.read_obj(os.path.join(DATA, "fan5.obj"))
        K = {e: 0.2 + 0.37 * (i % 5) for i, e in enumerate(sorted(
            {(min(f[k], f[(k + 1) % 4]), max(f[k], f[(k + 1) % 4])) for f in F for k in range(4)}))}
        alone = add_modifier(load_cage("Alone", V=V, F=F, K=K))
        A = evaluated_positions(alone)
        n = len(V)
        pent = np.array([[10 + np.cos(2 * np.pi * k / 5), np.sin(2 * np.pi * k / 5), 0.3 * k] for k in range(5)])
        K2 = dict(K)
        K2.update({(n + k, n + (k + 1) % 5) if k < 4 else (n, n + 4): 40.0 + k for k in range(5)})
        both = add_modifier(load_cage("Both", V=np.vstack([V, pent]), F=list(F) + [list(range(n, n + 5))], K=K2))
        B = evaluated_positions(both)
        far = max(np.abs(B - a).max(1).min() for a in A)
        size = float(np.linalg.norm(V.max(0) - V.min(0)))
        self.assertLessEqual(far / size, 1e-6, "the fan's limit moved by %g of its size next to a "
                             "disconnected pentagon" % (far / size))

    def test_undo_of_a_levels_change_updates_the_panel(self):
        """Undo of a Levels change: the surface and the panel's counts are the restored ones."""
        ob = add_modifier(grid(3, "UndoLevels"), levels=1)
        bpy.ops.ed.undo_push(message="levels 1")
        ob.ccnurbs.levels = 2
        update()
        bpy.ops.ed.undo_push(message="levels 2")
        self.assertEqual(ccn.sync.status(ob, 'VIEW').num_verts, len(evaluated_positions(ob)))
        bpy.ops.ed.undo()
        ob = bpy.data.objects["UndoLevels"]
        update()
        n = len(evaluated_positions(ob))
        self.assertEqual(ob.ccnurbs.levels, 1)
        self.assertEqual(n, (3 * 2 + 1) ** 2)
        st = ccn.sync.status(ob, 'VIEW')
        self.assertEqual(st.num_verts, n, "the panel reports %d vertices, the surface has %d" % (st.num_verts, n))

    def test_add_is_undoable(self):
        ob = grid(2, "UndoMe")
        bpy.ops.ed.undo_push(message="before add")
        add_modifier(ob)
        self.assertIsNotNone(bpy.data.objects["UndoMe"].modifiers.get("CCNURBS"))
        bpy.ops.ed.undo()
        self.assertIsNone(bpy.data.objects["UndoMe"].modifiers.get("CCNURBS"))
        bpy.ops.ed.redo()
        ob = bpy.data.objects["UndoMe"]
        self.assertIsNotNone(ob.modifiers.get("CCNURBS"))
        self.assertMatchesCLI(ob)

    def test_panels(self):
        ob = grid(2, "Panel")
        bpy.context.view_layer.objects.active = ob
        self.assertIn(("operator", "object.ccnurbs_add"),
                      draw_panel(ccn.ui.DATA_PT_ccnurbs_modifier))
        add_modifier(ob)
        log = draw_panel(ccn.ui.DATA_PT_ccnurbs_modifier)
        for p in ("levels", "render_levels", "scheme", "cap", "boundary_smooth"):
            self.assertIn(("prop", p), log)
        self.assertIn("Limit: 81 vertices, 64 faces", labels(log))
        self.assertIn(("operator", "object.ccnurbs_remove"), log)
        edit_select_edges(ob, [0])
        bpy.ops.mesh.ccnurbs_set_knot_interval(value=2.5)
        log = draw_panel(ccn.ui.VIEW3D_PT_ccnurbs_knots)
        for op in ("mesh.ccnurbs_set_knot_interval", "mesh.ccnurbs_select_ring",
                   "mesh.ccnurbs_clear_knot_interval"):
            self.assertIn(("operator", op), log)
        self.assertIn(("prop", "show_overlay"), log)
        self.assertIn("Active edge: 2.5", labels(log))
        bpy.ops.object.mode_set(mode='OBJECT')

    def test_remove(self):
        ob = add_modifier(grid(2, "Rm"))
        proxy_name = ccn.modifier.proxy(ob, 'VIEW').name
        bpy.context.view_layer.objects.active = ob
        bpy.ops.ed.undo_push(message="before remove")
        self.assertEqual(bpy.ops.object.ccnurbs_remove(*UNDO), {'FINISHED'})
        self.assertIsNone(ob.modifiers.get("CCNURBS"))
        self.assertNotIn(proxy_name, bpy.data.objects)
        self.assertEqual(len(evaluated_positions(ob)), 9)
        bpy.ops.ed.undo()
        ob = bpy.data.objects["Rm"]
        self.assertIsNotNone(ob.modifiers.get("CCNURBS"))
        self.assertEqual(len(evaluated_positions(ob)), 81)


