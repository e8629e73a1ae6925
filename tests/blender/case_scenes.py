"""Scene structures: a cage in a second scene, in a collection one view layer excludes and
another shows, and in a collection appended from another file. Rendered there (as `blender -b
file.blend -S scene -f 1` renders them), the object shows the limit surface, equal to
Subdivision Surface's (Use Limit Surface, Quality 10) on a twin of the same cage in the same
place, also after save and reopen; the appended one also in the viewport."""
from bltest import *  # noqa: F401,F403
from mathutils import kdtree

LEVELS = 2


def twins(name, collection):
    """A cage with CCNURBS and its twin with Subdivision Surface, both in `collection` (and in
    no other), equal intervals: the same limit surface."""
    obs = []
    for kind in ("CCNURBS", "SUBSURF"):
        bpy.ops.mesh.primitive_cube_add()
        ob = bpy.context.object
        ob.name = name + kind
        ob.data.vertices[0].co.z += 0.4  # not a symmetric shape
        for c in list(ob.users_collection):
            c.objects.unlink(ob)
        collection.objects.link(ob)
        if kind == "SUBSURF":
            m = ob.modifiers.new("Subsurf", 'SUBSURF')
            m.levels = m.render_levels = LEVELS
            m.use_limit_surface = True
            m.quality = 10
            m.boundary_smooth = 'ALL'
        obs.append(ob)
    return obs


def asset_library(prefix, stem, **settings):
    """A library file holding the collection "Asset" with twins (CCNURBS on the first, with
    `settings`), saved as TMP/stem.blend; then a new file. Returns the twins' names and the
    library's path."""
    coll = bpy.data.collections.new("Asset")
    bpy.context.scene.collection.children.link(coll)
    names = [o.name for o in twins(prefix, coll)]
    add_modifier(bpy.data.objects[names[0]], levels=LEVELS, render_levels=LEVELS, **settings)
    lib = os.path.join(TMP, stem + ".blend")
    bpy.ops.wm.save_as_mainfile(filepath=lib)
    reset_scene()  # a new file
    return names, lib


def linked_instance(prefix, stem, **settings):
    """asset_library's collection linked into a new file (File > Link) and instanced there by an
    Empty (Instance Collections). Returns the twins' names and the instancing Empty."""
    names, lib = asset_library(prefix, stem, **settings)
    with bpy.data.libraries.load(lib, link=True) as (src, dst):
        dst.collections = ["Asset"]
    inst = bpy.data.objects.new("Asset instance", None)
    inst.instance_type = 'COLLECTION'
    inst.instance_collection = dst.collections[0]
    bpy.context.scene.collection.objects.link(inst)
    return names, inst


def positions_in(dg, ob):
    me = ob.evaluated_get(dg).data
    P = np.empty(3 * len(me.vertices))
    me.vertices.foreach_get("co", P)
    return P.reshape(-1, 3)


def set_distance(A, B):
    t = kdtree.KDTree(len(B))
    for i, p in enumerate(B):
        t.insert(p, i)
    t.balance()
    return max(t.find(p)[2] for p in A) if len(A) else np.inf


def render_probe(scene, layer, names):
    """Renders `scene`'s view layer `layer` with a probe engine; returns {name: positions} of
    the named objects as that render's depsgraph holds them (how a render, or `blender -b
    file.blend -S scene -f 1`, sees them)."""
    seen = {}

    class ProbeEngine(bpy.types.RenderEngine):
        bl_idname = "CCNURBS_SCENES_PROBE"
        bl_label = "probe"

        def render(self, depsgraph):
            if depsgraph.view_layer.name != layer:  # a render of every view layer
                r = self.begin_result(0, 0, 4, 4)
                self.end_result(r)
                return
            for inst in depsgraph.object_instances:  # to its end (a walk left early leaks)
                # the objects themselves, or drawn by a collection instance; not the tap (an
                # instance scaled to zero)
                if inst.object.original.name in names and (
                        not inst.is_instance or abs(inst.matrix_world.determinant()) > 0):
                    seen[inst.object.original.name] = cagelib.mesh_positions(inst.object.data)
            r = self.begin_result(0, 0, 4, 4)
            self.end_result(r)

    bpy.utils.register_class(ProbeEngine)
    old = scene.render.engine
    try:
        if scene.camera is None:
            cam = bpy.data.objects.new("Cam " + scene.name, bpy.data.cameras.new("Cam"))
            scene.collection.objects.link(cam)
            scene.camera = cam
        scene.render.engine = ProbeEngine.bl_idname
        scene.render.resolution_x = scene.render.resolution_y = 4
        bpy.ops.render.render(scene=scene.name, layer=layer)
    finally:
        scene.render.engine = old
        bpy.utils.unregister_class(ProbeEngine)
    return seen


class TestScenes(AddonTestCase):
    def assertTwinsEqual(self, seen, names, what):
        self.assertEqual(sorted(seen), sorted(names), "%s: not rendered" % what)
        P, Q = seen[names[0]], seen[names[1]]
        self.assertEqual(len(P), len(Q), "%s: %d vertices, Subdivision Surface %d"
                         % (what, len(P), len(Q)))
        d = max(set_distance(P, Q), set_distance(Q, P))
        self.assertLessEqual(d, POS_TOL, "%s: %.3g from Subdivision Surface" % (what, d))

    def assertRendersAndShowsTwins(self, names, cc, ss, what):
        """The scene's render and the viewport show the cage cc's surface as its Subdivision
        Surface twin ss shows its own."""
        scene = bpy.context.scene
        self.assertTwinsEqual(render_probe(scene, scene.view_layers[0].name, names), names, what)
        dg = update()
        d = set_distance(positions_in(dg, cc), positions_in(dg, ss))
        self.assertLessEqual(d, POS_TOL, "%s, viewport" % what)

    def _setup_and_check(self, build, check, stem):
        """build() makes the structure and returns the twins' names; check(names, what) looks
        at the surface; then saved, reopened and checked again."""
        names = build()
        check(names, "before saving")
        path = os.path.join(TMP, stem + ".blend")
        bpy.ops.wm.save_as_mainfile(filepath=path)
        bpy.ops.wm.open_mainfile(filepath=path)
        check(names, "after save and reopen")

    def test_cage_in_a_second_scene(self):
        """A cage only in a scene that is not the window's: evaluated there (switching to it,
        rendering it) it shows its limit surface."""
        def build():  # made here, then moved to the other scene (Object > Link/Transfer)
            other = bpy.data.scenes.new("Second")
            obs = twins("Sc2", bpy.context.scene.collection)
            add_modifier(obs[0], levels=LEVELS, render_levels=LEVELS)
            for o in obs:
                other.collection.objects.link(o)
                bpy.context.scene.collection.objects.unlink(o)
            return [o.name for o in obs]

        def check(names, what):
            other = bpy.data.scenes["Second"]
            seen = render_probe(other, other.view_layers[0].name, names)
            self.assertTwinsEqual(seen, names, "second scene, " + what)
        self._setup_and_check(build, check, "scenes_second")

    def test_collection_excluded_in_one_view_layer(self):
        """A cage whose collection one view layer excludes and another shows: the view layer
        that shows it shows its limit surface."""
        def build():
            scene = bpy.context.scene
            coll = bpy.data.collections.new("Part")
            scene.collection.children.link(coll)
            names = [o.name for o in twins("VL", coll)]
            add_modifier(bpy.data.objects[names[0]], levels=LEVELS, render_levels=LEVELS)
            shown = scene.view_layers.new("Shown")
            scene.view_layers[0].layer_collection.children["Part"].exclude = True
            shown.layer_collection.children["Part"].exclude = False
            return names

        def check(names, what):
            scene = bpy.context.scene
            seen = render_probe(scene, "Shown", names)
            self.assertTwinsEqual(seen, names, "view layer that shows it, " + what)
            self.assertEqual(render_probe(scene, scene.view_layers[0].name, names), {},
                             "the excluding view layer renders it")
        self._setup_and_check(build, check, "scenes_view_layers")

    def test_appended_collection(self):
        """A collection holding a cage appended from another file (File > Append > Collection)
        and linked into the scene: its cage shows its limit surface."""
        def build():
            names, lib = asset_library("Ap", "scenes_asset_lib")
            with bpy.data.libraries.load(lib, link=False) as (src, dst):
                dst.collections = ["Asset"]
            bpy.context.scene.collection.children.link(dst.collections[0])
            return names

        def check(names, what):
            cc, ss = (bpy.data.objects[n] for n in names)
            self.assertRendersAndShowsTwins(names, cc, ss, "appended collection, " + what)
        self._setup_and_check(build, check, "scenes_appended")

    def test_linked_collection(self):
        """A collection holding a cage linked from another file and instanced (File > Link,
        Instance Collections; no override), the library saved with Store Render Mesh in File: the
        cage shows the surface the library stored, in renders and in the viewport, and the panel
        says so. (Linked data is read-only here: a live surface needs a library override.)"""
        def build():
            return linked_instance("Ln", "scenes_linked_lib", store_render_mesh=True)[0]

        def check(names, what):
            cc, ss = (bpy.data.objects[n] for n in names)
            self.assertIsNotNone(cc.library, "the cage is not linked, " + what)
            self.assertRendersAndShowsTwins(names, cc, ss, "linked collection, " + what)
            st = ccn.sync.status(cc)
            self.assertIsNone(st.error, what)
            self.assertEqual(st.showing, "stored", what)
            self.assertIn("Linked: the surface scenes_linked_lib.blend stored, 98 vertices",
                          " ".join(ccn.ui.status_lines(cc)), what)
        self._setup_and_check(build, check, "scenes_linked")

    def test_linked_collection_override(self):
        """A collection holding a cage linked from another file and instanced (File > Link,
        Instance Collections), then made a library override (Object > Library Override > Make,
        how a linked asset is made editable): its cage shows its limit surface, in renders and
        in the viewport, and its settings can be changed."""
        def local(name):
            return next(o for o in bpy.data.objects if o.name == name and o.library is None)

        def build():
            names, inst = linked_instance("Ov", "scenes_override_lib")
            bpy.context.view_layer.update()  # the new object's base, so that it can be selected
            for o in bpy.context.view_layer.objects:
                o.select_set(o == inst)
            bpy.context.view_layer.objects.active = inst
            self.assertEqual(bpy.ops.object.make_override_library(), {'FINISHED'})
            return names

        def check(names, what):
            cc, ss = (local(n) for n in names)
            self.assertIsNotNone(cc.override_library, "the cage is not an override, " + what)
            self.assertRendersAndShowsTwins(names, cc, ss, "overridden linked collection, " + what)
        self._setup_and_check(build, check, "scenes_override")
        cc = local("OvCCNURBS")
        cc.ccnurbs.levels = LEVELS + 1  # an override's settings are its own
        n = len(positions_in(update(), cc))
        self.assertEqual(n, 6 * 4 ** (LEVELS + 1) + 2, "levels %d on the override: %d vertices" % (LEVELS + 1, n))
