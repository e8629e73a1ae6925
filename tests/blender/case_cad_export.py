"""CAD export (addon/cad_export.py): File > Export > "CCNURBS Surface (.step, .iges)"
and the panel's "Export CAD" button. Every file is read back by OpenCASCADE (build/occt_read,
the independent reader of tests/oracle): valid, one shell (closed for closed cages), and as many
faces as `ccnurbs export` gives for the same cage and settings. The modifier's settings are
used (cap, Use Creases), several selected cages give one file each, the panel exports only its
object, and errors are reports that write nothing."""
import subprocess

from bltest import *  # noqa: F401,F403

OCCT = os.path.abspath(os.environ.get("CCN_OCCT") or os.path.join(
    os.path.dirname(os.path.abspath(__file__)), "..", "..", "build", "occt_read"))


def occt(path):
    out = subprocess.run([OCCT, path], capture_output=True, text=True).stdout
    return dict(ln.split(": ", 1) for ln in out.splitlines()
                if ": " in ln and not ln.startswith("face "))


def cli_export(obj_path, *opts):
    out = subprocess.run([CLI, "export", *opts, obj_path, os.path.join(TMP, "cli.step")],
                         capture_output=True, text=True, check=True).stdout
    return dict(ln.split(": ", 1) for ln in out.splitlines())


def cage(name, **settings):
    ob = load_cage(name, os.path.join(DATA, name + ".obj"))
    return add_modifier(ob, **settings)


def export(path, **kw):
    kw.setdefault("apply_transform", False)
    kw.setdefault("scale", 1.0)
    return bpy.ops.export_scene.ccnurbs_cad(filepath=path, **kw)


class TestCadExport(AddonTestCase):
    def setUp(self):
        super().setUp()
        self.assertTrue(os.path.isfile(OCCT), "no OpenCASCADE reader at %s (make test builds it)"
                        % OCCT)

    def test_menu_entry(self):
        log = []
        for f in getattr(bpy.types.TOPBAR_MT_file_export.draw, "_draw_funcs", []):
            if getattr(f, "__module__", "").endswith("cad_export"):
                f(type("M", (), {"layout": FakeLayout(log)})(), bpy.context)
        self.assertIn(("operator", "export_scene.ccnurbs_cad"), log)

    def test_panel_button(self):
        cage("cube")
        log = draw_panel(ccn.ui.DATA_PT_ccnurbs_modifier)
        self.assertIn(("operator", "export_scene.ccnurbs_cad"), log)

    def test_step_and_iges(self):
        cage("cube")
        want = cli_export(os.path.join(DATA, "cube.obj"))
        for ext, fmt in ((".step", "step"), (".igs", "iges")):
            path = os.path.join(TMP, "cube" + ext)
            self.assertEqual(export(path), {'FINISHED'})
            rep = occt(path)
            self.assertEqual((rep["format"], rep["valid"], rep["shells"], rep["closed_shells"]),
                             (fmt, "1", "1", "1"))
            self.assertEqual(rep["faces"], want["faces"])
            self.assertGreater(float(rep["volume"]), 0)
            self.assertFalse([f for f in os.listdir(TMP) if ".tmp" in f])
        self.assertGreater(int(want["bi5"]), 0)  # the caps are exported, not fills

    def test_settings_and_nonuniform(self):
        cage("fig18_v8", cap='REFINE')  # knot intervals from the OBJ, the cap from the modifier
        path = os.path.join(TMP, "fig18.step")
        self.assertEqual(export(path, packed=False), {'FINISHED'})
        rep = occt(path)
        self.assertEqual((rep["valid"], rep["shells"]), ("1", "1"))
        self.assertEqual(rep["faces"], cli_export(os.path.join(DATA, "fig18_v8.obj"),
                                                  "--cap", "refine", "--unpacked")["faces"])

    def test_creases(self):
        """Use Creases: the unit cube with every edge crease 1 (sharpness 10) is six flat
        faces meeting C0, volume 1; without it the smooth cube of `ccnurbs export`."""
        V = [(x, y, z) for z in (0, 1) for y in (0, 1) for x in (0, 1)]
        F = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
        ob = load_cage("Sharp", V=np.array(V, float), F=F, K={})
        ccn.compat.set_edge_creases(ob.data, np.ones(len(ob.data.edges), np.float32))
        add_modifier(ob, use_creases=True)
        path = os.path.join(TMP, "sharp.step")
        self.assertEqual(export(path), {'FINISHED'})
        rep = occt(path)
        self.assertEqual((rep["valid"], rep["closed_shells"], rep["faces"], rep["edges"]),
                         ("1", "1", "6", "12"))
        self.assertAlmostEqual(float(rep["volume"]), 1.0, places=9)
        # the info as the library fills it: its last fields (the ctypes mirror's layout)
        (p, info), = ccn.cad_export.export_objects([ob], path, world=False)
        self.assertEqual((info["num_faces"], info["num_crease_edges"]), (6, 12))
        self.assertAlmostEqual(info["max_crease_angle"], np.pi / 2, places=9)
        ob.ccnurbs.use_creases = False
        self.assertEqual(export(path), {'FINISHED'})
        self.assertEqual(occt(path)["faces"], cli_export(os.path.join(DATA, "cube.obj"))["faces"])

    def test_several_cages(self):
        a = cage("cube")
        b = cage("torus")
        a.select_set(True)
        b.select_set(True)
        path = os.path.join(TMP, "two.step")
        self.assertEqual(export(path), {'FINISHED'})
        for n in ("cube", "torus"):
            rep = occt(os.path.join(TMP, "two_%s.step" % n))
            self.assertEqual((rep["valid"], rep["shells"]), ("1", "1"))
        self.assertEqual(occt(os.path.join(TMP, "two_torus.step"))["faces"], "1")  # one pack

    def test_panel_exports_its_object(self):
        a = cage("cube")
        b = cage("torus")
        a.select_set(True)
        b.select_set(True)
        bpy.context.view_layer.objects.active = b
        path = os.path.join(TMP, "panel.step")
        self.assertEqual(export(path, active_only=True), {'FINISHED'})
        self.assertEqual(occt(path)["faces"], "1")  # the torus alone, under the path itself
        self.assertFalse(os.path.exists(os.path.join(TMP, "panel_cube.step")))

    def test_errors_are_reports(self):
        cage("cube")
        bpy.ops.object.select_all(action='DESELECT')
        path = os.path.join(TMP, "none.step")
        self.assertIn("no CCNURBS cage selected", error_of(path))
        self.assertFalse(os.path.exists(path))
        cage("cube")
        bad = os.path.join(TMP, "no_such_dir", "x.step")
        self.assertIn("CCNURBS export", error_of(bad))
        self.assertFalse(os.path.exists(os.path.dirname(bad)))


def error_of(path, **kw):
    """The ERROR report of an export as text ('' if none): an ERROR report raises
    RuntimeError in a Python operator call."""
    try:
        export(path, **kw)
    except RuntimeError as e:
        return str(e)
    return ""
