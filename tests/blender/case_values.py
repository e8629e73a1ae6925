"""One meaning of a knot value (<= 0 / NaN / Inf = unset = 1) in the operator, the attribute and
the library; and the small items: loose-element counts, a cage without faces, the status text
when there never was a limit, enabling the add-on refreshes surfaces."""
from bltest import *  # noqa: F401,F403


def set_value(ob, edge, value):
    """(operator result, error message or None): an ERROR report raises in Python calls."""
    edit_select_edges(ob, [edge])
    try:
        return bpy.ops.mesh.ccnurbs_set_knot_interval(value=value), None
    except RuntimeError as e:
        return {'CANCELLED'}, str(e)


class TestValues(AddonTestCase):
    def test_set_operator_outcomes(self):
        """Each bad value is refused with its message and stores nothing; good ones are kept."""
        ob = grid(3, "Vals")
        # (typed value, the message the operator reports; README "Knot intervals" table)
        cases = [(0.0, "0 refused: it must be > 0"), (-2.0, "-2 refused: it must be > 0"),
                 (float("nan"), "NaN refused"), (float("inf"), "refused: Inf or outside"),
                 (-float("inf"), "refused: it must be > 0"), (1e300, "refused: Inf or outside"),
                 (1e-300, "0 refused: it must be > 0"), (1e-40, "refused: outside")]
        for value, message in cases:
            with self.subTest(value=value):
                res, err = set_value(ob, 0, value)
                self.assertEqual(res, {'CANCELLED'})
                self.assertIn(message, err or "")
                self.assertIsNone(edit_knots(ob), "a refused value was stored")
        for value in (1e-30, 0.25, 3.0, 1e30):
            with self.subTest(value=value):
                self.assertEqual(set_value(ob, 0, value), ({'FINISHED'}, None))
                k = edit_knots(ob)
                self.assertEqual(np.float32(k[0]), np.float32(value))
        bpy.ops.object.mode_set(mode='OBJECT')

    def test_unset_values_mean_one_everywhere(self):
        """An attribute holding 0, -1, NaN, Inf on a ring gives the same limit as no value."""
        ob = add_modifier(load_cage("Fan", os.path.join(DATA, "fan5.obj")))
        base = evaluated_positions(ob)
        me = ob.data
        for bad in (0.0, -1.0, np.nan, np.inf, -np.inf):
            with self.subTest(value=bad):
                cagelib.set_knots(me, {k: bad for k in cagelib.edge_keys(me)[:7]})
                np.testing.assert_allclose(evaluated_positions(ob), base, atol=1e-12)
                np.testing.assert_array_equal(ccn.values.effective([bad]), [1.0])
        cagelib.set_knots(me, {cagelib.edge_keys(me)[0]: 4.0})
        self.assertGreater(np.abs(evaluated_positions(ob) - base).max(), 1e-4)
        cols, _ = ccn.overlay.interval_colors(np.array([np.nan, np.inf, -1.0, 0.0]), 4)
        np.testing.assert_allclose(cols, np.tile(ccn.overlay.NEUTRAL, (4, 1)), atol=1e-6)


class TestSmallItems(AddonTestCase):
    def test_loose_counts(self):
        ob = grid(2, "Loose")
        me = ob.data
        bm = bmesh.new()
        bm.from_mesh(me)
        a, b, c = (bm.verts.new(p) for p in ((5, 5, 0), (6, 5, 0), (9, 9, 9)))
        bm.edges.new((a, b))
        bm.to_mesh(me)
        bm.free()
        add_modifier(ob)
        self.assertEqual(ccn.sync.status(ob).loose, (3, 1))  # a, b, c in no face; 1 edge
        bpy.context.view_layer.objects.active = ob
        shown = labels(draw_panel(ccn.ui.DATA_PT_ccnurbs_modifier))
        self.assertIn("loose: 3 vertices, 1 edges (carried as Subdivision Surface carries them)",
                      shown)
        self.assertNotIn("sharp vertices", shown)  # loose ends in no face: nothing to sharpen

    def test_deleting_all_faces_shows_the_cage(self):
        ob = add_modifier(grid(2, "NoFaces"))
        self.assertEqual(len(evaluated_positions(ob)), 81)
        bpy.ops.object.mode_set(mode='EDIT')
        bpy.ops.mesh.select_all(action='SELECT')
        bpy.ops.mesh.delete(type='ONLY_FACE')
        bpy.ops.object.mode_set(mode='OBJECT')
        update()
        P = evaluated_positions(ob)
        np.testing.assert_array_equal(P, cagelib.mesh_positions(ob.data))
        lines = ccn.ui.status_lines(ob)
        self.assertIn("showing the cage", lines[0])
        self.assertIn("no faces", lines[1])

    def test_status_when_there_never_was_a_limit(self):
        def nan_at(ob, v):
            co = np.zeros(3 * len(ob.data.vertices), np.float32)
            ob.data.vertices.foreach_get("co", co)
            co[3 * v + 2] = np.nan
            ob.data.vertices.foreach_set("co", co)
            ob.data.update()

        ob = grid(1, "NeverValid")
        nan_at(ob, 0)
        add_modifier(ob)
        lines = ccn.ui.status_lines(ob)
        self.assertIn("showing the cage (no valid limit yet)", lines[0])
        self.assertNotIn("last valid", lines[0])
        ok = add_modifier(grid(2, "WasValid"))
        nan_at(ok, 4)
        update()
        self.assertIn("showing the last valid limit", ccn.ui.status_lines(ok)[0])

    def test_enabling_refreshes_surfaces(self):
        ob = add_modifier(grid(2, "Refresh"))
        disable()
        try:
            ob.data.vertices[4].co.z = 2.0  # edited while the add-on is off
            ob.data.update()
            update()
        finally:
            enable()
        # enabled with the data open (a script, the preferences on 4.x/5.x): refreshed at once;
        # where add-ons register with the data restricted (3.x) a timer does it, which the UI
        # runs on its next event loop; headless no timer runs, so the test does
        if bpy.app.timers.is_registered(ccn.handlers.refresh_after_enable):
            ccn.handlers.refresh_after_enable()
        R, _ = reference(ob)
        np.testing.assert_allclose(evaluated_positions(ob), R, atol=POS_TOL)
