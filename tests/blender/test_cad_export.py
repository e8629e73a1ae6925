"""Headless test of addon/cad_export.py (the CAD export operator; not yet registered by the
add-on's __init__, so this registers it itself):

    blender --background --factory-startup --python-exit-code 1 \\
            --python tests/blender/test_cad_export.py -- build/ccnurbs.zip build/ccnurbs \\
            build/occt_read TMPDIR

Checks: the File > Export entry; the operator on a cage writes a STEP / IGES file that
OpenCASCADE reads valid with one closed shell (a solid) and as many faces as `ccnurbs export`
gives for the same cage with the same settings; the modifier settings are used (--cap refine);
several selected cages give one file each; nothing selected is an error and writes nothing.
Prints "N passed, N failed".
"""
import importlib
import os
import subprocess
import sys
import unittest

import addon_utils
import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import cagelib  # noqa: E402

ARGS = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
ZIP, CLI, OCCT, TMP = (os.path.abspath(a) for a in (ARGS + ["build/ccnurbs.zip", "build/ccnurbs",
                                                             "build/occt_read", "/tmp"])[:4])
DATA = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "data")
cad = None


def occt(path):
    out = subprocess.run([OCCT, path], capture_output=True, text=True).stdout
    return dict(l.split(": ", 1) for l in out.splitlines() if ": " in l and not l.startswith("face "))


def cli_faces(obj_path, *opts):
    out = subprocess.run([CLI, "export", *opts, obj_path, os.path.join(TMP, "cli.step")],
                         capture_output=True, text=True, check=True).stdout
    return int(dict(l.split(": ", 1) for l in out.splitlines())["faces"])


def make_cage(name, cap='GUIDED_BI5'):
    V, F, K = cagelib.read_obj(os.path.join(DATA, name + ".obj"))
    ob = cagelib.make_object(name, V, F, K)
    bpy.ops.object.select_all(action='DESELECT')
    ob.select_set(True)
    bpy.context.view_layer.objects.active = ob
    bpy.ops.object.ccnurbs_add()
    ob.ccnurbs.cap = cap
    return ob


class CadExport(unittest.TestCase):
    def setUp(self):
        for o in list(bpy.data.objects):
            bpy.data.objects.remove(o)

    def test_menu_entry(self):
        draw = bpy.types.TOPBAR_MT_file_export.draw
        names = [getattr(f, "__name__", "") for f in getattr(draw, "_draw_funcs", [])]
        self.assertIn("menu_export", names)

    def test_step_and_iges(self):
        make_cage("cube")
        for ext, fmt in ((".step", "step"), (".igs", "iges")):
            path = os.path.join(TMP, "cube" + ext)
            r = bpy.ops.export_scene.ccnurbs_cad(filepath=path, apply_transform=False, scale=1.0)
            self.assertEqual(r, {'FINISHED'})
            rep = occt(path)
            self.assertEqual((rep["format"], rep["valid"], rep["shells"], rep["closed_shells"]),
                             (fmt, "1", "1", "1"))
            self.assertEqual(int(rep["faces"]), cli_faces(os.path.join(DATA, "cube.obj")))
            self.assertFalse([f for f in os.listdir(TMP) if ".tmp" in f])

    def test_settings_and_nonuniform(self):
        make_cage("fig18_v8", cap='REFINE')  # knot intervals from the OBJ, cap from the modifier
        path = os.path.join(TMP, "fig18.step")
        self.assertEqual(bpy.ops.export_scene.ccnurbs_cad(filepath=path, apply_transform=False,
                                                          scale=1.0, packed=False), {'FINISHED'})
        rep = occt(path)
        self.assertEqual((rep["valid"], rep["shells"]), ("1", "1"))
        self.assertEqual(int(rep["faces"]), cli_faces(os.path.join(DATA, "fig18_v8.obj"),
                                                      "--cap", "refine", "--unpacked"))

    def test_several_cages(self):
        a = make_cage("cube")
        b = make_cage("torus")
        a.select_set(True)
        b.select_set(True)
        path = os.path.join(TMP, "two.step")
        self.assertEqual(bpy.ops.export_scene.ccnurbs_cad(filepath=path), {'FINISHED'})
        for n in ("cube", "torus"):
            rep = occt(os.path.join(TMP, "two_%s.step" % n))
            self.assertEqual((rep["valid"], rep["shells"]), ("1", "1"))
        self.assertEqual(occt(os.path.join(TMP, "two_torus.step"))["faces"], "1")  # one pack

    def test_nothing_selected(self):
        make_cage("cube")
        bpy.ops.object.select_all(action='DESELECT')
        path = os.path.join(TMP, "none.step")
        with self.assertRaises(RuntimeError):  # the operator reports an error
            bpy.ops.export_scene.ccnurbs_cad(filepath=path)
        self.assertFalse(os.path.exists(path))


def main():
    global cad
    bpy.ops.preferences.addon_install(filepath=ZIP, overwrite=True)
    mod = addon_utils.enable("ccnurbs", default_set=True, handle_error=None)
    cad = importlib.import_module(mod.__name__ + ".cad_export")
    cad.register()
    print("== CCNURBS cad export tests ==")
    res = unittest.TextTestRunner(stream=sys.stdout, verbosity=2).run(
        unittest.defaultTestLoader.loadTestsFromTestCase(CadExport))
    cad.unregister()
    n, bad = res.testsRun, len(res.failures) + len(res.errors)
    print("%d passed, %d failed" % (n - bad, bad))
    sys.exit(1 if bad else 0)


main()
