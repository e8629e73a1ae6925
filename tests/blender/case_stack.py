"""Modifiers above CCNURBS: the cage the library sees is the evaluated stack (Mirror with merge
and clipping, Array, Solidify, Displace, Lattice, Geometry Nodes), intervals carried through;
Edit Mode edits the original and the result follows."""
from bltest import *  # noqa: F401,F403

TOL = 1e-6


def half_grid(name="Half"):
    """A 3x3 grid on x >= 0 whose x = 0 column is the mirror seam, with ring intervals."""
    n = 3
    V = np.array([(x, y, 0.3 * x * (y - 1)) for y in range(n + 1) for x in range(n + 1)], float)
    F = [(y * (n + 1) + x, y * (n + 1) + x + 1, (y + 1) * (n + 1) + x + 1, (y + 1) * (n + 1) + x)
         for y in range(n) for x in range(n)]
    ob = load_cage(name, V=V, F=F, K={})
    me = ob.data
    P = cagelib.mesh_positions(me)
    knots = {}
    for a, b in cagelib.edge_keys(me):
        d = P[b] - P[a]
        if abs(d[1]) > 0.5:   # vertical edges: the ring is a row of quads; value by row
            knots[(a, b)] = (1.0, 3.0, 0.5)[int(min(P[a][1], P[b][1]))]
        else:                 # horizontal edges: value by column, seam column included
            knots[(a, b)] = (2.0, 1.0, 4.0)[int(min(P[a][0], P[b][0]))]
    cagelib.set_knots(me, knots)
    return ob


def add_above(ob, name, kind, **settings):
    """A modifier placed above CCNURBS (CCNURBS stays last)."""
    mod = ob.modifiers.new(name, kind)
    for k, v in settings.items():
        setattr(mod, k, v)
    ccn_mod = ccn.modifier.get_modifier(ob)
    if ccn_mod is not None:
        bpy.context.view_layer.objects.active = ob
        with bpy.context.temp_override(object=ob, active_object=ob):
            bpy.ops.object.modifier_move_to_index(modifier=ccn_mod.name,
                                                  index=len(ob.modifiers) - 1)
    return mod


def stack_without_ccnurbs(ob):
    """A twin object sharing the mesh, with the same modifiers minus CCNURBS: its evaluated
    mesh is the cage CCNURBS must see (the oracle's input)."""
    twin = ob.copy()
    twin.name = ob.name + " twin"
    twin.modifiers.remove(ccn.modifier.get_modifier(twin))
    twin.ccnurbs.role = 'NONE'
    bpy.context.scene.collection.objects.link(twin)
    return twin


def applied_twin(ob):
    """The same object with every modifier above CCNURBS applied and CCNURBS re-added."""
    twin = stack_without_ccnurbs(ob)
    twin.data = ob.data.copy()
    bpy.context.view_layer.objects.active = twin
    for mod in list(twin.modifiers):
        with bpy.context.temp_override(object=twin, active_object=twin):
            bpy.ops.object.modifier_apply(modifier=mod.name)
    add_modifier(twin)
    for k in ("levels", "scheme", "cap", "boundary_smooth"):
        setattr(twin.ccnurbs, k, getattr(ob.ccnurbs, k))
    update()
    return twin


def cli_of_stack(ob, levels=None):
    """`ccnurbs limit` of the evaluated stack above CCNURBS (independent of the add-on)."""
    twin = stack_without_ccnurbs(ob)
    dg = update()
    me = twin.evaluated_get(dg).data
    s = ob.ccnurbs
    R, _ = cagelib.cli_limit(CLI, me, s.levels if levels is None else levels, s.scheme, s.cap,
                             s.boundary_smooth)
    bpy.data.objects.remove(twin)
    return R


class TestStackAbove(AddonTestCase):
    def test_mirror_merge_clip_equals_applied(self):
        ob = add_modifier(half_grid(), levels=2)
        add_above(ob, "Mirror", 'MIRROR', use_clip=True, use_mirror_merge=True)
        P = evaluated_positions(ob)
        self.assertLess(P[:, 0].min(), -2.5, "the mirrored half is missing")
        twin = applied_twin(ob)
        Q = evaluated_positions(twin)
        self.assertEqual(P.shape, Q.shape)
        self.assertLessEqual(np.abs(P - Q).max(), TOL, "Mirror above != Mirror applied")
        R = cli_of_stack(ob)
        self.assertLessEqual(np.abs(P - R).max(), POS_TOL, "differs from `ccnurbs limit`")
        # the intervals went through: the seam column's ring keeps its value 2 on both sides
        k = cagelib.get_knots(twin.data)
        Pt = cagelib.mesh_positions(twin.data)
        ev = np.array([e.vertices[:] for e in twin.data.edges])
        seam_ring = [i for i, (a, b) in enumerate(ev)
                     if abs(Pt[a, 1] - Pt[b, 1]) < 1e-9 and {round(Pt[a, 0]), round(Pt[b, 0])}
                     in ({0, 1}, {0, -1})]
        self.assertEqual(len(seam_ring), 8)
        self.assertEqual(set(k[seam_ring].tolist()), {2.0})
        uniform = applied_twin(ob)
        cagelib.set_knots(uniform.data, {})
        uniform.data.update()
        self.assertGreater(np.abs(evaluated_positions(uniform) - P).max(), 1e-3,
                           "intervals had no effect: the test would not see them lost")

    def test_add_goes_below_the_existing_stack(self):
        """Add CCNURBS on an object that already has Mirror (the half-modelling set-up) puts it
        last, as Blender puts any new modifier (Subsurf too): the existing Mirror is above it,
        counts, and the limit is the smooth surface across the seam, not a mirrored limit. On
        4.2+ a modifier pinned last stays last."""
        ob = half_grid("AddBelow")
        mirror = ob.modifiers.new("Mirror", 'MIRROR')
        mirror.use_clip = mirror.use_mirror_merge = True
        pinned = None
        if hasattr(mirror, "use_pin_to_last"):
            pinned = ob.modifiers.new("WeightedNormal", 'WEIGHTED_NORMAL')
            pinned.use_pin_to_last = True
        add_modifier(ob, levels=2)
        names = [m.name for m in ob.modifiers]
        ccn_name = ccn.modifier.get_modifier(ob).name
        self.assertEqual(names.index("Mirror"), 0, names)
        self.assertEqual(names.index(ccn_name), 1, names)
        if pinned is not None:
            self.assertEqual(names[-1], "WeightedNormal", names)
            pinned.show_viewport = False  # the comparison below is of the limit itself
        P = evaluated_positions(ob)
        self.assertLess(P[:, 0].min(), -2.5, "the mirrored half is missing")
        R = cli_of_stack(ob)
        self.assertEqual(P.shape, R.shape, "not the limit of the mirrored cage")
        self.assertLessEqual(np.abs(P - R).max(), POS_TOL, "differs from `ccnurbs limit` of the stack")

    def test_other_modifiers_above(self):
        ob = add_modifier(half_grid("Stack"), levels=1)
        lat = bpy.data.objects.new("Lattice", bpy.data.lattices.new("Lattice"))
        bpy.context.scene.collection.objects.link(lat)
        lat.scale = (8, 8, 3)
        lat.location = (1.5, 1.5, 0)
        lat.data.points[0].co_deform.z -= 0.3
        tex = bpy.data.textures.new("T", 'CLOUDS')
        cases = [("Array", 'ARRAY', dict(count=2, use_relative_offset=False,
                                         use_constant_offset=True,
                                         constant_offset_displace=(0.0, 3.5, 0.0))),
                 ("Solidify", 'SOLIDIFY', dict(thickness=0.2)),
                 ("Displace", 'DISPLACE', dict(texture=tex, strength=0.3)),
                 ("Lattice", 'LATTICE', dict(object=lat))]
        for name, kind, settings in cases:
            with self.subTest(modifier=name):
                mod = add_above(ob, name, kind, **settings)
                try:
                    P = evaluated_positions(ob)
                    R = cli_of_stack(ob)
                    self.assertEqual(P.shape, R.shape)
                    self.assertLessEqual(np.abs(P - R).max(), POS_TOL)
                finally:
                    ob.modifiers.remove(mod)
        with self.subTest(modifier="Geometry Nodes"):
            P0 = evaluated_positions(ob)
            g = bpy.data.node_groups.new("Lift", 'GeometryNodeTree')
            ccn.compat.new_group_socket(g, "Geometry", 'INPUT', 'NodeSocketGeometry')
            ccn.compat.new_group_socket(g, "Geometry", 'OUTPUT', 'NodeSocketGeometry')
            gi, go = g.nodes.new('NodeGroupInput'), g.nodes.new('NodeGroupOutput')
            sp = g.nodes.new('GeometryNodeSetPosition')
            sp.inputs["Offset"].default_value = (0.0, 0.0, 0.75)
            g.links.new(gi.outputs[0], sp.inputs["Geometry"])
            g.links.new(sp.outputs[0], go.inputs[0])
            mod = add_above(ob, "Lift", 'NODES')
            mod.node_group = g
            P = evaluated_positions(ob)
            R = cli_of_stack(ob)
            self.assertLessEqual(np.abs(P - R).max(), POS_TOL)
            np.testing.assert_allclose(P - P0, np.tile([0.0, 0.0, 0.75], (len(P), 1)),
                                       atol=POS_TOL, err_msg="the Geometry Nodes offset")

    def test_edit_mode_follows_through_mirror(self):
        ob = add_modifier(half_grid("EditMirror"), levels=2)
        add_above(ob, "Mirror", 'MIRROR', use_clip=True, use_mirror_merge=True,
                  show_on_cage=False, show_in_editmode=True)
        update()
        bpy.ops.object.mode_set(mode='EDIT')
        bm = bmesh.from_edit_mesh(ob.data)
        bm.verts.ensure_lookup_table()
        bm.verts[15].co.z = 1.25  # a corner away from the seam
        bmesh.update_edit_mesh(ob.data)
        P = evaluated_positions(ob)  # still in edit mode: the original is edited, result follows
        self.assertEqual(len(bm.verts), 16, "edit mode edits the original cage, not the mirror")
        bpy.ops.object.mode_set(mode='OBJECT')
        R = cli_of_stack(ob)
        self.assertEqual(P.shape, R.shape)
        self.assertLessEqual(np.abs(P - R).max(), POS_TOL, "edit-mode result != mirrored cage")
        np.testing.assert_allclose(evaluated_positions(ob), P, atol=TOL)

    def test_edit_mode_through_deform_only_stack(self):
        """Edit Mode with only deforming modifiers above (Displace, Simple Deform): the cage is
        the edit mesh's elements at the stack's positions; equals the stack's CLI limit."""
        ob = add_modifier(half_grid("EditDeform"), levels=2)
        tex = bpy.data.textures.new("T", 'CLOUDS')
        add_above(ob, "Displace", 'DISPLACE', texture=tex, strength=0.3, show_in_editmode=True,
                  show_on_cage=False)
        add_above(ob, "Twist", 'SIMPLE_DEFORM', deform_method='TWIST', angle=0.6,
                  show_in_editmode=True, show_on_cage=False)
        self.assertTrue(ccn.modifier.stack_keeps_topology(ob))
        update()
        bpy.ops.object.mode_set(mode='EDIT')
        bm = bmesh.from_edit_mesh(ob.data)
        bm.verts.ensure_lookup_table()
        bm.verts[5].co.z = 0.8
        bmesh.update_edit_mesh(ob.data)
        P = evaluated_positions(ob)
        bpy.ops.object.mode_set(mode='OBJECT')
        R = cli_of_stack(ob)
        self.assertEqual(P.shape, R.shape)
        self.assertLessEqual(np.abs(P - R).max(), POS_TOL, "edit-mode result != deformed cage")
        np.testing.assert_allclose(evaluated_positions(ob), P, atol=TOL)

    def test_apply_keeps_limit_only(self):
        ob = add_modifier(half_grid("ApplyMe"), levels=1)
        add_above(ob, "Mirror", 'MIRROR', use_mirror_merge=True)
        P = evaluated_positions(ob)
        bpy.context.view_layer.objects.active = ob
        for mod in list(ob.modifiers):
            with bpy.context.temp_override(object=ob, active_object=ob):
                bpy.ops.object.modifier_apply(modifier=mod.name)
        update()
        Q = cagelib.mesh_positions(ob.data)
        self.assertEqual(Q.shape, P.shape, "Apply added or lost vertices (the tap leaked?)")
        self.assertLessEqual(np.abs(Q - P).max(), TOL)
