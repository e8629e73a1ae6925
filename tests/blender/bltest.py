"""Shared helpers of the headless add-on tests (see test_addon.py): scene set-up, install,
the CLI reference, a stand-in for UILayout. Imported by every case_*.py module."""
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

ARGS = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else sys.argv[1:]
ZIP, CLI, TMP = (os.path.abspath(a) for a in (ARGS + ["build/ccnurbs.zip", "build/ccnurbs",
                                                        "/tmp"])[:3])
# Blender as a program (Debian's 3.4) or as the `bpy` module (PyPI wheels, 4.5 and 5.x).
AS_MODULE = not bpy.app.binary_path
EXTENSIONS = bpy.app.version >= (4, 2, 0)
DATA = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "data")
POS_TOL = 1e-5
# Python calls push no undo step unless asked: ('EXEC_DEFAULT', True) makes an operator call push
# its step exactly as a button or menu does (and only if the operator has the UNDO flag).
UNDO = ('EXEC_DEFAULT', True)
HANDLER_EVENTS = ("depsgraph_update_post", "frame_change_post", "load_post", "undo_post",
                  "redo_post", "render_init", "render_complete", "render_cancel", "save_pre", "save_post") + \
    (("save_post_fail",) if hasattr(bpy.app.handlers, "save_post_fail") else ())


class _Package:
    """The enabled add-on package (`ccnurbs` or `bl_ext.user_default.ccnurbs`), by attribute."""
    module = None

    def __getattr__(self, name):
        return getattr(sys.modules[type(self).module], name)


ccn = _Package()


def handler_counts():
    """Our footprint in Blender's global registries: app handlers, edge-menu entries."""
    counts = {e: len(getattr(bpy.app.handlers, e)) for e in HANDLER_EVENTS}
    draw = bpy.types.VIEW3D_MT_edit_mesh_edges.draw
    counts["edge_menu"] = sum(1 for f in getattr(draw, "_draw_funcs", [])
                              if getattr(f, "__name__", "") == "edge_menu")
    return counts


BASE_HANDLERS = handler_counts()


def module_name():
    return "bl_ext.user_default.ccnurbs" if EXTENSIONS else "ccnurbs"


def enable():
    mod = addon_utils.enable(module_name(), default_set=True, handle_error=None)
    if mod is None:
        raise RuntimeError("addon_utils.enable(%r) failed" % module_name())
    _Package.module = mod.__name__
    return mod


def disable():
    addon_utils.disable(module_name(), default_set=True)


def install():
    """3.x: Preferences > Add-ons > Install; 4.2+: the extension API (Install from Disk)."""
    if EXTENSIONS:
        res = bpy.ops.extensions.package_install_files(filepath=ZIP, repo="user_default",
                                                       enable_on_install=False)
        if res != {'FINISHED'}:
            raise RuntimeError("extensions.package_install_files: %s" % res)
    else:
        bpy.ops.preferences.addon_install(filepath=ZIP, overwrite=True)
    enable()


def blender_command(script, blend=None):
    """argv that runs `script` in a fresh Blender of the same kind, factory settings, add-on
    not enabled (the program: --background --factory-startup; the module: a new interpreter)."""
    if AS_MODULE:
        boot = ("import bpy, sys; bpy.ops.wm.read_factory_settings(use_empty=True); "
                + ("bpy.ops.wm.open_mainfile(filepath=%r, load_ui=False); " % blend
                   if blend else "")
                + "sys.argv = [%r]; exec(compile(open(%r).read(), %r, 'exec'))"
                % (script, script, script))
        return [sys.executable, "-c", boot]
    cmd = [bpy.app.binary_path, "--background", "--factory-startup"]
    if blend:
        cmd.append(blend)
    return cmd + ["--python-exit-code", "1", "--python", script]


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

