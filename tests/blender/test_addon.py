"""Headless tests of the CCNURBS Blender add-on (unittest inside Blender's Python).

    blender --background --factory-startup --python-exit-code 1 \
            --python tests/blender/test_addon.py -- build/ccnurbs.zip build/ccnurbs TMPDIR

Installs the add-on from the zip, then checks knot-ring operators (and their undo), the
modifier against `ccnurbs limit`, live updates, render levels, save/reload without the add-on,
error reporting and clean disable/re-enable. Prints a final line "N passed, N failed".
"""
import os
import subprocess
import sys
import unittest

import addon_utils
import bmesh
import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import cagelib  # noqa: E402

ARGS = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
ZIP, CLI, TMP = (os.path.abspath(a) for a in (ARGS + ["build/ccnurbs.zip", "build/ccnurbs",
                                                        "/tmp"])[:3])
DATA = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "data")
POS_TOL = 1e-5
# Python calls push no undo step unless asked: ('EXEC_DEFAULT', True) makes an operator call push
# its step exactly as a button or menu does (and only if the operator has the UNDO flag).
UNDO = ('EXEC_DEFAULT', True)
HANDLER_EVENTS = ("depsgraph_update_post", "load_post", "undo_post", "redo_post", "render_init",
                  "save_pre")

ccn = None  # the add-on package, once enabled


def handler_counts():
    """Our footprint in Blender's global registries: app handlers, edge-menu entries."""
    counts = {e: len(getattr(bpy.app.handlers, e)) for e in HANDLER_EVENTS}
    draw = bpy.types.VIEW3D_MT_edit_mesh_edges.draw
    counts["edge_menu"] = sum(1 for f in getattr(draw, "_draw_funcs", [])
                              if getattr(f, "__name__", "") == "edge_menu")
    return counts


BASE_HANDLERS = handler_counts()


def enable():
    global ccn
    mod = addon_utils.enable("ccnurbs", default_set=True, handle_error=None)
    if mod is None:
        raise RuntimeError("addon_utils.enable('ccnurbs') failed")
    ccn = sys.modules[mod.__name__]
    return mod


def install():
    bpy.ops.preferences.addon_install(filepath=ZIP, overwrite=True)
    enable()


def reset_scene():
    if bpy.context.object is not None and bpy.context.object.mode != 'OBJECT':
        bpy.ops.object.mode_set(mode='OBJECT')
    bpy.ops.wm.read_homefile(use_empty=True)
    # read_homefile keeps add-ons enabled; handlers persist (they are @persistent)


def update():
    bpy.context.view_layer.update()
    return bpy.context.evaluated_depsgraph_get()


def evaluated_positions(ob):
    dg = update()
    me = ob.evaluated_get(dg).data
    return cagelib.mesh_positions(me)


def load_cage(name, path=None, V=None, F=None, K=None):
    if path is not None:
        V, F, K = cagelib.read_obj(path)
    ob = cagelib.make_object(name, V, F, K)
    bpy.context.view_layer.objects.active = ob
    ob.select_set(True)
    return ob


def grid(n=4, name="Grid"):
    V = [(x, y, 0.0) for y in range(n + 1) for x in range(n + 1)]
    F = [(y * (n + 1) + x, y * (n + 1) + x + 1, (y + 1) * (n + 1) + x + 1, (y + 1) * (n + 1) + x)
         for y in range(n) for x in range(n)]
    return load_cage(name, V=np.array(V, float), F=F, K={})


def cube(name="Cube"):
    bpy.ops.mesh.primitive_cube_add(size=2)
    ob = bpy.context.object
    ob.name = name
    return ob


def edit_select_edges(ob, indices):
    """Edit mode, edge select mode, exactly the given edges selected."""
    bpy.context.view_layer.objects.active = ob
    if ob.mode != 'EDIT':
        bpy.ops.object.mode_set(mode='EDIT')
    bpy.context.tool_settings.mesh_select_mode = (False, True, False)
    bm = bmesh.from_edit_mesh(ob.data)
    bm.select_mode = {'EDGE'}
    for f in bm.faces:
        f.select_set(False)
    for e in bm.edges:
        e.select_set(False)
    for v in bm.verts:
        v.select_set(False)
    bm.edges.ensure_lookup_table()
    bm.select_history.clear()
    for i in indices:
        bm.edges[i].select_set(True)
        bm.select_history.add(bm.edges[i])  # the last one is active, as after a click
    bm.select_flush_mode()
    bmesh.update_edit_mesh(ob.data)


def edit_knots(ob):
    """Knot values read through bmesh in edit mode (None if the layer is absent)."""
    bm = bmesh.from_edit_mesh(ob.data)
    layer = bm.edges.layers.float.get("knot_interval")
    if layer is None:
        return None
    return np.array([e[layer] for e in bm.edges])


def edit_selected(ob):
    bm = bmesh.from_edit_mesh(ob.data)
    return {e.index for e in bm.edges if e.select}


def parallel_ring(ob, e0):
    """Independent ring oracle for axis-aligned grids/boxes: edges parallel to edge e0 that lie
    in the same slab (same coordinates along the edge's axis)."""
    me = ob.data
    P = cagelib.mesh_positions(me)
    ev = np.array([e.vertices[:] for e in me.edges])
    d0 = P[ev[e0, 1]] - P[ev[e0, 0]]
    axis = int(np.argmax(np.abs(d0)))
    lo0, hi0 = sorted((P[ev[e0, 0], axis], P[ev[e0, 1], axis]))
    out = set()
    for i, (a, b) in enumerate(ev):
        nz = np.abs(P[b] - P[a]) > 1e-9
        if nz.sum() != 1 or not nz[axis]:
            continue
        lo, hi = sorted((P[a, axis], P[b, axis]))
        if abs(lo - lo0) < 1e-9 and abs(hi - hi0) < 1e-9:
            out.add(i)
    return out


class FakeLayout:
    """Stands in for UILayout (not constructible headless) to run the panels' draw code: records
    labels, properties and operators, and checks that every property and operator exists."""

    def __init__(self, log):
        self.log, self.alert, self.use_property_split, self.enabled = log, False, False, True

    def column(self, **kw):
        return FakeLayout(self.log)

    row = box = column

    def label(self, text="", **kw):
        self.log.append(("label", text))

    def separator(self, **kw):
        pass

    def prop(self, data, name, **kw):
        assert name in data.bl_rna.properties, name
        self.log.append(("prop", name))

    def operator(self, idname, **kw):
        mod, name = idname.split(".")
        getattr(getattr(bpy.ops, mod), name).get_rna_type()  # KeyError if not registered
        self.log.append(("operator", idname))
        return type("OpProps", (), {})()


def draw_panel(cls):
    log = []
    panel = type("P", (), {"layout": FakeLayout(log)})()
    if not hasattr(cls, "poll") or cls.poll(bpy.context):
        cls.draw(panel, bpy.context)
    return log


def labels(log):
    return " ".join(t for k, t in log if k == "label")


def add_modifier(ob, **settings):
    bpy.context.view_layer.objects.active = ob
    for o in bpy.context.selected_objects:
        o.select_set(False)
    ob.select_set(True)
    res = bpy.ops.object.ccnurbs_add(*UNDO)
    assert res == {'FINISHED'}, res
    for k, v in settings.items():
        setattr(ob.ccnurbs, k, v)
    update()
    return ob


def reference(ob, levels=None):
    s = ob.ccnurbs
    return cagelib.cli_limit(CLI, ob.data, s.levels if levels is None else levels, s.scheme,
                             s.cap, s.boundary_smooth)


class AddonTestCase(unittest.TestCase):
    def setUp(self):
        reset_scene()

    def assertMatchesCLI(self, ob, levels=None, normals=True):
        P = evaluated_positions(ob)
        R, N = reference(ob, levels)
        self.assertEqual(P.shape, R.shape, "vertex count differs from `ccnurbs limit`")
        err = np.abs(P - R).max()
        self.assertLessEqual(err, POS_TOL, "positions differ from `ccnurbs limit` by %g" % err)
        if normals and not os.environ.get("CCN_TEST_NO_VN"):
            self.assertEqual(N.shape, R.shape, "`ccnurbs limit` wrote no vn")
            me = ob.evaluated_get(bpy.context.evaluated_depsgraph_get()).data
            self.assertIs(me.has_custom_normals, True, "no custom split normals")
            cn = ccn.compat.corner_normals(me)
            lv = np.empty(len(me.loops), np.int32)
            me.loops.foreach_get("vertex_index", lv)
            dev = np.abs(cn - N[lv]).max()
            self.assertLess(dev, 2e-3, "corner normals differ from the exact normals by %g" % dev)
        return P


# ---- knot intervals -----------------------------------------------------------------------------

class TestKnotOperators(AddonTestCase):
    def _set_and_undo(self, ob, e0):
        name = ob.name
        ring = parallel_ring(ob, e0)
        self.assertGreater(len(ring), 1)
        edit_select_edges(ob, [e0])
        bpy.ops.ed.undo_push(message="before set")
        self.assertEqual(bpy.ops.mesh.ccnurbs_set_knot_interval(*UNDO, value=3.5), {'FINISHED'})
        k = edit_knots(ob)
        self.assertEqual(set(np.flatnonzero(k == np.float32(3.5))), ring)
        self.assertEqual(np.count_nonzero(~(np.delete(k, sorted(ring)) <= 0)), 0, "edges outside the ring set")
        bpy.ops.ed.undo()
        ob = bpy.data.objects[name]  # undo may reload data: Python references go stale
        k = edit_knots(ob)
        n_set = 0 if k is None else np.count_nonzero(~(k <= 0))
        self.assertEqual(n_set, 0, "undo did not restore the intervals")
        bpy.ops.ed.redo()
        ob = bpy.data.objects[name]
        k = edit_knots(ob)
        self.assertEqual(set(np.flatnonzero(k == np.float32(3.5))), ring, "redo")
        bpy.ops.object.mode_set(mode='OBJECT')
        stored = cagelib.get_knots(ob.data)  # the EDGE attribute in object mode
        self.assertEqual(set(np.flatnonzero(stored == np.float32(3.5))), ring)
        return ring

    def test_grid_ring(self):
        ob = grid(4)
        # an interior horizontal edge of the 4x4 grid: its ring is its column (5 edges)
        e0 = [i for i, e in enumerate(ob.data.edges)
              if set(e.vertices) == {6, 7}][0]
        ring = self._set_and_undo(ob, e0)
        self.assertEqual(len(ring), 5)

    def test_cube_ring(self):
        ob = cube()
        ring = self._set_and_undo(ob, 0)
        self.assertEqual(len(ring), 4)

    def test_select_ring_and_undo(self):
        ob = grid(4)
        e0 = [i for i, e in enumerate(ob.data.edges) if set(e.vertices) == {6, 11}][0]
        edit_select_edges(ob, [e0])
        bpy.ops.ed.undo_push(message="before select")
        self.assertEqual(bpy.ops.mesh.ccnurbs_select_ring(*UNDO), {'FINISHED'})
        self.assertEqual(edit_selected(ob), parallel_ring(ob, e0))
        bpy.ops.ed.undo()
        self.assertEqual(edit_selected(bpy.data.objects["Grid"]), {e0})

    def test_clear_and_undo(self):
        ob = grid(4)
        e0 = [i for i, e in enumerate(ob.data.edges) if set(e.vertices) == {6, 7}][0]
        e1 = [i for i, e in enumerate(ob.data.edges) if set(e.vertices) == {6, 11}][0]
        edit_select_edges(ob, [e0, e1])
        bpy.ops.mesh.ccnurbs_set_knot_interval(value=4.0)
        ring0, ring1 = parallel_ring(ob, e0), parallel_ring(ob, e1)
        edit_select_edges(ob, [e0])
        bpy.ops.ed.undo_push(message="before clear")
        res = bpy.ops.mesh.ccnurbs_clear_knot_interval(*UNDO, scope='SELECTED')
        self.assertEqual(res, {'FINISHED'})
        k = edit_knots(ob)
        self.assertEqual(np.count_nonzero(~(k[sorted(ring0)] <= 0)), 0, "ring 0 still set")
        self.assertEqual(set(np.flatnonzero(k == 4.0)), ring1, "other ring must stay")
        bpy.ops.ed.undo()
        ob = bpy.data.objects["Grid"]
        k = edit_knots(ob)
        self.assertEqual(set(np.flatnonzero(k == 4.0)), ring0 | ring1)
        res = bpy.ops.mesh.ccnurbs_clear_knot_interval(*UNDO, scope='ALL')
        self.assertEqual(res, {'FINISHED'})
        self.assertIsNone(edit_knots(ob), "Clear All removes the attribute")
        bpy.ops.ed.undo()
        ob = bpy.data.objects["Grid"]
        self.assertEqual(set(np.flatnonzero(edit_knots(ob) == 4.0)), ring0 | ring1)
        bpy.ops.object.mode_set(mode='OBJECT')

    def test_nothing_selected_is_cancelled(self):
        ob = grid(2)
        edit_select_edges(ob, [])
        self.assertEqual(bpy.ops.mesh.ccnurbs_set_knot_interval(value=2.0), {'CANCELLED'})
        self.assertIsNone(edit_knots(ob))
        bpy.ops.object.mode_set(mode='OBJECT')

    def test_ring_labels_numpy(self):
        # every ring of a 3x3 grid, against the geometric oracle
        ob = grid(3)
        c = ccn.cage.read(ob)
        labels = ccn.knots.ring_labels(c.num_edges,
                                       ccn.knots.quad_opposite_pairs(c.face_sizes, c.loop_edges))
        for e in range(c.num_edges):
            self.assertEqual(set(np.flatnonzero(labels == labels[e])), parallel_ring(ob, e))

    def test_overlay_colours(self):
        cols, span = ccn.overlay.interval_colors(np.array([1.0, 0.0, 8.0, 0.125, -1.0]), 5)
        self.assertEqual(span, 3.0)
        np.testing.assert_allclose(cols[0], ccn.overlay.NEUTRAL, atol=1e-6)
        np.testing.assert_allclose(cols[1], ccn.overlay.NEUTRAL, atol=1e-6)  # unset = 1
        np.testing.assert_allclose(cols[2], ccn.overlay.LONG, atol=1e-6)
        np.testing.assert_allclose(cols[3], ccn.overlay.SHORT, atol=1e-6)
        ob = grid(3)
        edit_select_edges(ob, [0])
        bpy.context.scene.ccnurbs_tools.show_overlay = True
        bpy.ops.mesh.ccnurbs_set_knot_interval(value=4.0)
        update()
        entry = ccn.overlay._cache.get(ob.name_full)
        self.assertIsNotNone(entry, "overlay data not refreshed after an edit")
        self.assertEqual(entry["coords"].shape, (2 * len(ob.data.edges), 3))
        red = set(np.flatnonzero(np.all(np.abs(entry["colors"][::2] - ccn.overlay.LONG) < 1e-6,
                                        axis=1)))
        self.assertEqual(red, parallel_ring(ob, 0))
        self.assertEqual(ccn.overlay.handle_count(), 2)
        bpy.context.scene.ccnurbs_tools.show_overlay = False
        bpy.ops.object.mode_set(mode='OBJECT')


# ---- the modifier ------------------------------------------------------------------------------

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
        for p in (s.proxy, s.render_proxy):
            self.assertEqual(len(p.users_collection), 0, "proxy must not be in a scene")
        self.assertNotIn(s.proxy, list(bpy.context.scene.objects))

    def test_closed_cage_with_ngons(self):
        ob = add_modifier(load_cage("Prism", os.path.join(DATA, "ngon_prism.obj")), levels=2)
        self.assertMatchesCLI(ob)

    def test_live_updates(self):
        ob = load_cage("Fan5", os.path.join(DATA, "fan5.obj"))
        me = ob.data
        cagelib.set_knots(me, {k: 1.0 for k in cagelib.edge_keys(me)})
        add_modifier(ob)
        self.assertMatchesCLI(ob)
        proxy_me = ob.ccnurbs.proxy.data
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
        ob.ccnurbs.proxy.data.loops.foreach_get("vertex_index", loops_after)
        self.assertIs(ob.ccnurbs.proxy.data, proxy_me)
        np.testing.assert_array_equal(loops_before, loops_after)

        # nothing changed: further updates do nothing (no loop)
        st = dict(ccn.sync.stats)
        for _ in range(3):
            update()
        self.assertEqual(ccn.sync.stats["syncs"], st["syncs"])
        # what a proxy write looks like to the depsgraph (the cage is re-evaluated because its
        # modifier reads the proxy): the handler runs, sees the same content key, writes nothing
        st = dict(ccn.sync.stats)
        ob.ccnurbs.proxy.data.update()
        ob.ccnurbs.render_proxy.data.update()
        update()
        d = {k: ccn.sync.stats[k] - st[k] for k in st}
        self.assertGreaterEqual(d["handler_calls"], 1, d)
        self.assertGreaterEqual(d["skipped"], 1, d)
        self.assertEqual(d["syncs"], 0, d)

        # change an interval (ring of the first spoke) → rebuild with the new intervals
        st = dict(ccn.sync.stats)
        k = cagelib.get_knots(me)
        k[0] = 6.0
        me.attributes["knot_interval"].data.foreach_set("value", k)
        me.update()
        self.assertMatchesCLI(ob)
        self.assertEqual(ccn.sync.stats["syncs"] - st["syncs"], 1)

        # levels → new vertex count
        n2 = len(evaluated_positions(ob))
        ob.ccnurbs.levels = 3
        self.assertGreater(len(self.assertMatchesCLI(ob)), n2)

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

    def test_render_uses_render_levels(self):
        ob = add_modifier(load_cage("Fan5", os.path.join(DATA, "fan5.obj")), levels=1,
                          render_levels=3)
        n_view = len(evaluated_positions(ob))
        seen = {}

        class ProbeEngine(bpy.types.RenderEngine):
            bl_idname = "CCNURBS_TEST_PROBE"
            bl_label = "probe"

            def render(self, depsgraph):
                for inst in depsgraph.object_instances:
                    if inst.object.original.name == ob.name:
                        seen["verts"] = len(inst.object.data.vertices)
                        seen["positions"] = cagelib.mesh_positions(inst.object.data)
                r = self.begin_result(0, 0, 4, 4)
                self.end_result(r)

        bpy.utils.register_class(ProbeEngine)
        try:
            scene = bpy.context.scene
            cam = bpy.data.objects.new("Cam", bpy.data.cameras.new("Cam"))
            scene.collection.objects.link(cam)
            scene.camera = cam
            scene.render.engine = ProbeEngine.bl_idname
            scene.render.resolution_x = scene.render.resolution_y = 4
            bpy.ops.render.render()
        finally:
            bpy.utils.unregister_class(ProbeEngine)
        R, _ = reference(ob, levels=3)
        self.assertIn("verts", seen, "render did not see the cage")
        self.assertEqual(seen["verts"], len(R))
        np.testing.assert_allclose(seen["positions"], R, atol=POS_TOL)
        self.assertEqual(len(evaluated_positions(ob)), n_view, "viewport result not restored")
        self.assertMatchesCLI(ob, normals=False)

    def test_save_reload_without_addon(self):
        ob = load_cage("Fig16", os.path.join(DATA, "fig16_v6.obj"))
        add_modifier(ob, scheme='NURSS', levels=2, render_levels=3)
        ob.data.vertices[0].co.z = 1.3
        ob.data.update()
        update()
        R, _ = reference(ob)
        R3, _ = reference(ob, levels=3)
        path = os.path.join(TMP, "reload.blend")
        bpy.ops.wm.save_as_mainfile(filepath=path)
        out = os.path.join(TMP, "reload.npy")
        script = os.path.join(TMP, "reload_check.py")
        with open(script, "w") as fh:
            fh.write(
                "import bpy, numpy as np, addon_utils, sys\n"
                "assert not addon_utils.check('ccnurbs')[1], 'add-on must be disabled'\n"
                "assert not hasattr(bpy.types.Object, 'ccnurbs')\n"
                "ob = bpy.data.objects['Fig16']\n"
                "dg = bpy.context.evaluated_depsgraph_get()\n"
                "me = ob.evaluated_get(dg).data\n"
                "co = np.empty(3 * len(me.vertices), np.float32)\n"
                "me.vertices.foreach_get('co', co)\n"
                "rp = [o for o in bpy.data.objects if o.name.startswith('.CCNURBS render')][0]\n"
                "np.save(%r, co.reshape(-1, 3))\n"
                "np.save(%r, np.array([len(rp.data.vertices)]))\n"
                % (out, out + ".render.npy"))
        r = subprocess.run([bpy.app.binary_path, "--background", "--factory-startup", path,
                            "--python-exit-code", "1", "--python", script],
                           capture_output=True, text=True, timeout=120)
        self.assertEqual(r.returncode, 0, r.stdout[-2000:] + r.stderr[-2000:])
        P = np.load(out).astype(np.float64)
        self.assertEqual(P.shape, R.shape)
        self.assertLessEqual(np.abs(P - R).max(), POS_TOL)
        self.assertEqual(int(np.load(out + ".render.npy")[0]), len(R3),
                         "the saved render proxy is not at render_levels")

    def test_non_manifold_cage(self):
        ob = add_modifier(grid(2))
        good = evaluated_positions(ob)
        me = ob.data
        # a third face on the interior edge (1,4): non-manifold edge
        bm = bmesh.new()
        bm.from_mesh(me)
        bm.verts.ensure_lookup_table()
        a, b = bm.verts[1], bm.verts[4]
        bm.faces.new((a, b, bm.verts.new((1.0, 0.5, 1.0))))
        bm.to_mesh(me)
        bm.free()
        me.update()
        P = evaluated_positions(ob)  # must not raise
        lines = ccn.ui.status_lines(ob)
        self.assertGreater(len(lines), 0, "no status lines")
        self.assertIn("error", lines[0].lower(), lines)
        # the panel shows exactly the library's message
        c = ccn.cage.read(ob)
        with self.assertRaises(ccn.native.CCNError) as cm:
            ccn.native.Plan(c.positions, c.face_sizes, c.face_verts, c.edge_verts, c.knots,
                            levels=2)
        self.assertEqual(lines[1], str(cm.exception))
        self.assertIn("non-manifold", str(cm.exception))
        bpy.context.view_layer.objects.active = ob
        shown = labels(draw_panel(ccn.ui.DATA_PT_ccnurbs_modifier))
        self.assertIn(" ".join(str(cm.exception).split()), shown)
        np.testing.assert_array_equal(P, good)  # the previous limit stays
        self.assertIsNotNone(ccn.sync.status(ob).error)
        # non-manifold from the start: no limit yet, the modifier shows the cage itself
        ob2 = grid(1, "Bad")
        bm = bmesh.new()
        bm.from_mesh(ob2.data)
        bm.verts.ensure_lookup_table()
        a, b = bm.verts[0], bm.verts[1]
        bm.faces.new((b, a, bm.verts.new((0.5, -0.5, 1.0))))
        bm.faces.new((a, b, bm.verts.new((0.5, 0.5, -1.0))))
        bm.to_mesh(ob2.data)
        bm.free()
        add_modifier(ob2)
        st = ccn.sync.status(ob2)
        self.assertIsNotNone(st, "no status for the non-manifold cage")
        self.assertIn("non-manifold", (st.error or "").lower(), "no error reported")
        np.testing.assert_array_equal(evaluated_positions(ob2),
                                      cagelib.mesh_positions(ob2.data))

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
        self.assertIsNot(dup.ccnurbs.proxy, ob.ccnurbs.proxy)
        dup.data.vertices[4].co.z = 2.0
        dup.data.update()
        update()
        np.testing.assert_array_equal(evaluated_positions(ob), before)
        self.assertGreater(evaluated_positions(dup)[:, 2].max(), 0.5)

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
        proxy_name = ob.ccnurbs.proxy.name
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


# ---- install / enable / disable (last: it reloads the module) -----------------------------------

class TestZEnableDisable(unittest.TestCase):
    def test_disable_reenable_no_leaks(self):
        self.assertEqual(ccn.sync.stats["internal_errors"], 0,
                         "a handler hit an unexpected exception during the tests (see log)")
        reset_scene()
        enabled_counts = handler_counts()
        for e in HANDLER_EVENTS + ("edge_menu",):
            self.assertEqual(enabled_counts[e], BASE_HANDLERS[e] + 1, e)
        for _ in range(2):
            addon_utils.disable("ccnurbs", default_set=True)
            self.assertEqual(handler_counts(), BASE_HANDLERS, "handlers left after disable")
            self.assertFalse(hasattr(bpy.types.Object, "ccnurbs"))
            self.assertFalse(hasattr(bpy.types, "MESH_OT_ccnurbs_set_knot_interval"))
            self.assertFalse(hasattr(bpy.types, "DATA_PT_ccnurbs_modifier"))
            self.assertEqual(ccn.overlay.handle_count(), 0)
            enable()
            self.assertEqual(handler_counts(), enabled_counts, "handlers after re-enable")
            self.assertEqual(ccn.overlay.handle_count(), 2)
        ob = add_modifier(grid(2))
        self.assertEqual(len(evaluated_positions(ob)), 81)


class _Result(unittest.TestResult):
    """Collects (status, test id, traceback) for the summary printed after the run."""

    def __init__(self, *a, **kw):
        super().__init__(*a, **kw)
        self.rows = []

    def addSuccess(self, test):
        super().addSuccess(test)
        self.rows.append(("ok", test, ""))

    def addFailure(self, test, err):
        super().addFailure(test, err)
        self.rows.append(("FAIL", test, self.failures[-1][1]))

    def addError(self, test, err):
        super().addError(test, err)
        self.rows.append(("ERROR", test, self.errors[-1][1]))

    def addSubTest(self, test, subtest, err):
        super().addSubTest(test, subtest, err)
        if err is not None:
            kind, lst = ("FAIL", self.failures) if issubclass(err[0], test.failureException) \
                else ("ERROR", self.errors)
            self.rows.append((kind, subtest, lst[-1][1]))


def main():
    install()
    suite = unittest.defaultTestLoader.loadTestsFromModule(sys.modules[__name__])
    result = _Result()
    suite.run(result)
    failed_ids = {t.id() for k, t, _ in result.rows if k != "ok"}
    print("== CCNURBS blender tests ==")
    for kind, test, tb in result.rows:
        name = test.id().replace("__main__.", "")
        if kind == "ok" and test.id() in failed_ids:
            continue  # a test with a failing subtest is reported as failing
        print("%-5s %s" % (kind, name))
        if tb:
            print("      " + tb.rstrip().replace("\n", "\n      "))
    failed = len({t.id() for k, t, _ in result.rows if k != "ok"} |
                 {t.id() for t, _ in result.failures + result.errors})
    print("%d passed, %d failed" % (result.testsRun - min(failed, result.testsRun), failed))
    sys.stdout.flush()
    if failed:
        raise SystemExit(1)


main()
