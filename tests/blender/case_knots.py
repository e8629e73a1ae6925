"""Knot-ring operators (set, select, clear), their undo, ring labels, the overlay."""
from bltest import *  # noqa: F401,F403


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
        entry = ccn.state.of(ob).overlay
        self.assertIsNotNone(entry, "overlay data not refreshed after an edit")
        self.assertEqual(entry["coords"].shape, (2 * len(ob.data.edges), 3))
        red = set(np.flatnonzero(np.all(np.abs(entry["colors"][::2] - ccn.overlay.LONG) < 1e-6,
                                        axis=1)))
        self.assertEqual(red, parallel_ring(ob, 0))
        self.assertEqual(ccn.overlay.handle_count(), 3)
        bpy.context.scene.ccnurbs_tools.show_overlay = False
        bpy.ops.object.mode_set(mode='OBJECT')


