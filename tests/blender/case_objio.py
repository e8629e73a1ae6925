"""File > Import / Export "OBJ with knot intervals and creases": `# knot`, `# crease`, `# corner`
and UVs survive import -> export -> import bit for bit, and round-trip with the `ccnurbs` CLI."""
import subprocess

from bltest import *  # noqa: F401,F403


def obj_import(path):
    res = bpy.ops.import_scene.ccnurbs_obj(filepath=path)
    assert res == {'FINISHED'}, res
    return bpy.context.view_layer.objects.active


def obj_export(ob, path):
    for o in bpy.context.view_layer.objects:
        o.select_set(False)
    ob.select_set(True)
    bpy.context.view_layer.objects.active = ob
    res = bpy.ops.export_scene.ccnurbs_obj(filepath=path)
    assert res == {'FINISHED'}, res
    with open(path) as fh:
        return fh.read()


def by_edge(me, values):
    """{(i, j): value} over the edges (vertex pairs sorted)."""
    return dict(zip(cagelib.edge_keys(me), np.asarray(values).tolist()))


def uv_per_corner(me):
    uv = np.empty(2 * len(me.loops), np.float32)
    me.uv_layers.active.data.foreach_get("uv", uv)
    return uv


def state(me):
    return {"co": cagelib.mesh_positions(me),
            "knots": by_edge(me, cagelib.get_knots(me)),
            "creases": by_edge(me, ccn.compat.edge_creases(me)),
            "corners": ccn.compat.vertex_creases(me),
            "uv": uv_per_corner(me)}


class TestObjFiles(AddonTestCase):
    def test_round_trip_exact(self):
        ob = load_cage("Src", os.path.join(DATA, "fig16_v6.obj"))
        me = ob.data
        rng = np.random.default_rng(7)
        ne, nv = len(me.edges), len(me.vertices)
        c = np.where(rng.random(ne) < 0.4, rng.random(ne), 0.0).astype(np.float32)
        c[:3] = (1.0, 0.5, 0.1)
        ccn.compat.set_edge_creases(me, c)
        ccn.compat.set_vertex_creases(me, np.where(rng.random(nv) < 0.3, rng.random(nv),
                                                   0.0).astype(np.float32))
        uv = me.uv_layers.new(name="UVMap")
        uv.data.foreach_set("uv", rng.random(2 * len(me.loops)).astype(np.float32))
        k = cagelib.get_knots(me)
        k[0] = 0.1 + np.float32(1.0 / 3.0)  # a value that is not short in decimal
        me.attributes["knot_interval"].data.foreach_set("value", k)
        me.update()
        first = os.path.join(TMP, "rt1.obj")
        text1 = obj_export(ob, first)
        for tag in ("# knot ", "# crease ", "# corner ", "vt ", "/"):
            self.assertIn(tag, text1)
        a = obj_import(first)
        text2 = obj_export(a, os.path.join(TMP, "rt2.obj"))
        b = obj_import(os.path.join(TMP, "rt2.obj"))
        self.assertEqual(text1, text2, "export -> import -> export changed the text")
        s0, s1, s2 = state(me), state(a.data), state(b.data)
        for name in s0:
            with self.subTest(item=name):
                for s in (s1, s2):
                    if isinstance(s0[name], dict):
                        self.assertEqual(s[name], s0[name])
                    else:
                        np.testing.assert_array_equal(s[name], s0[name])

    def test_cli_round_trip(self):
        src = os.path.join(DATA, "fig17_v7.obj")
        refined = os.path.join(TMP, "fig17_L1.obj")
        subprocess.run([CLI, "refine", "--levels", "1", src, refined], check=True,
                       capture_output=True)
        ob = obj_import(refined)
        _, _, K = cagelib.read_obj(refined)  # the CLI's `# knot` lines, read independently
        got = by_edge(ob.data, cagelib.get_knots(ob.data))
        self.assertEqual(len(K), len(ob.data.edges))
        self.assertEqual({e: np.float32(v) for e, v in K.items()},
                         {e: np.float32(v) for e, v in got.items()})
        exported = os.path.join(TMP, "fig17_L1_blender.obj")
        obj_export(ob, exported)
        lim = {}
        for name, path in (("cli", refined), ("blender", exported)):
            out = os.path.join(TMP, name + "_limit.obj")
            subprocess.run([CLI, "limit", "--levels", "2", path, out], check=True,
                           capture_output=True)
            lim[name] = cagelib.read_limit_obj(out)[0]
        self.assertEqual(lim["cli"].shape, lim["blender"].shape)
        self.assertLessEqual(np.abs(lim["cli"] - lim["blender"]).max(), 1e-6)
        add_modifier(ob, levels=2)
        np.testing.assert_allclose(evaluated_positions(ob), lim["cli"], atol=POS_TOL)

    def test_bad_values_are_unset(self):
        path = os.path.join(TMP, "bad.obj")
        with open(path, "w") as fh:
            fh.write("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n"
                     "# knot 1 2 -3\n# knot 2 3 nan\n# knot 3 4 inf\n# knot 4 1 0\n"
                     "# knot 1 3 5\n"  # not an edge
                     "# crease 1 2 12\n# crease 2 3 -1\n# crease 3 4 2.5\n# corner 1 40\n")
        ob = obj_import(path)
        me = ob.data
        np.testing.assert_array_equal(cagelib.get_knots(me), np.zeros(4, np.float32))
        cr = by_edge(me, ccn.compat.edge_creases(me))
        self.assertEqual(cr[(0, 1)], 1.0)   # sharpness >= 10: infinitely sharp = crease 1
        self.assertEqual(cr[(1, 2)], 0.0)   # negative: none
        self.assertAlmostEqual(cr[(2, 3)], 0.5, places=6)  # 10 * 0.5^2 = 2.5
        self.assertEqual(ccn.compat.vertex_creases(me)[0], 1.0)

    def test_menu_entries(self):
        for menu, op in ((bpy.types.TOPBAR_MT_file_import, "import_scene.ccnurbs_obj"),
                         (bpy.types.TOPBAR_MT_file_export, "export_scene.ccnurbs_obj")):
            log = []
            layout = FakeLayout(log)
            for f in getattr(menu.draw, "_draw_funcs", []):
                if getattr(f, "__module__", "").endswith("objio"):
                    f(type("M", (), {"layout": layout})(), bpy.context)
            self.assertIn(("operator", op), log)
