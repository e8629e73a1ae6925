"""Disable / re-enable leaves no handler, class or draw callback behind (run last)."""
from bltest import *  # noqa: F401,F403


class TestZEnableDisable(unittest.TestCase):
    def test_disable_reenable_no_leaks(self):
        self.assertEqual(ccn.sync.stats["internal_errors"], 0,
                         "a handler hit an unexpected exception during the tests (see log)")
        reset_scene()
        enabled_counts = handler_counts()
        for e in HANDLER_EVENTS + ("edge_menu",):
            self.assertEqual(enabled_counts[e], BASE_HANDLERS[e] + 1, e)
        for _ in range(2):
            disable()
            self.assertEqual(handler_counts(), BASE_HANDLERS, "handlers left after disable")
            self.assertFalse(hasattr(bpy.types.Object, "ccnurbs"))
            self.assertFalse(hasattr(bpy.types, "MESH_OT_ccnurbs_set_knot_interval"))
            self.assertFalse(hasattr(bpy.types, "DATA_PT_ccnurbs_modifier"))
            self.assertEqual(ccn.overlay.handle_count(), 0)
            enable()
            self.assertEqual(handler_counts(), enabled_counts, "handlers after re-enable")
            self.assertEqual(ccn.overlay.handle_count(), 3)
        ob = add_modifier(grid(2))
        self.assertEqual(len(evaluated_positions(ob)), 81)

