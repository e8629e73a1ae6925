"""Animation: armature, shape-key and driver animation above CCNURBS follow frame_set; a 3-frame
render (Workbench, headless) renders each frame's limit at Render levels."""
import math

from bltest import *  # noqa: F401,F403
from case_stack import cli_of_stack, half_grid

FRAMES = (1, 5, 9)


def rigged(name="Rigged"):
    """The half grid bent by a one-bone armature (weights grow with x), bone keyed at 3 frames."""
    ob = half_grid(name)
    arm = bpy.data.objects.new(name + " Rig", bpy.data.armatures.new(name + " Rig"))
    bpy.context.scene.collection.objects.link(arm)
    bpy.context.view_layer.objects.active = arm
    bpy.ops.object.mode_set(mode='EDIT')
    b = arm.data.edit_bones.new("Bone")
    b.head, b.tail = (0.0, 1.5, 0.0), (3.0, 1.5, 0.0)
    bpy.ops.object.mode_set(mode='OBJECT')
    vg = ob.vertex_groups.new(name="Bone")
    P = cagelib.mesh_positions(ob.data)
    for i, p in enumerate(P):
        vg.add([i], float(p[0]) / 3.0, 'REPLACE')
    pb = arm.pose.bones["Bone"]
    pb.rotation_mode = 'XYZ'
    for f, angle in zip(FRAMES, (0.0, 0.6, -0.4)):
        pb.rotation_euler = (0.0, angle, 0.0)
        pb.keyframe_insert("rotation_euler", frame=f)
    mod = ob.modifiers.new("Armature", 'ARMATURE')
    mod.object = arm
    return ob


def shape_keyed(name="Keyed"):
    ob = half_grid(name)
    ob.shape_key_add(name="Basis")
    k = ob.shape_key_add(name="Lift")
    for i, p in enumerate(k.data):
        p.co.z += 0.5 * math.sin(i)
    for f, v in zip(FRAMES, (0.0, 1.0, 0.3)):
        k.value = v
        k.keyframe_insert("value", frame=f)
    return ob


class TestAnimation(AddonTestCase):
    def _frames_match(self, ob, levels=None):
        scene = bpy.context.scene
        seen = []
        for f in FRAMES:
            scene.frame_set(f)  # no extra update: frame_set alone shows the frame's limit
            P = cagelib.mesh_positions(ob.evaluated_get(
                bpy.context.evaluated_depsgraph_get()).data)
            R = cli_of_stack(ob, levels)
            self.assertEqual(P.shape, R.shape, "frame %d" % f)
            self.assertLessEqual(np.abs(P - R).max(), POS_TOL, "frame %d" % f)
            seen.append(P)
        self.assertGreater(np.abs(seen[1] - seen[0]).max(), 0.05, "the animation did nothing")
        return seen

    def test_armature_frames(self):
        ob = rigged()
        add_modifier(ob, levels=2)
        compat_move_last(ob)
        self._frames_match(ob)

    def test_shape_key_frames(self):
        ob = shape_keyed()
        add_modifier(ob, levels=1)
        self._frames_match(ob)

    def test_driver_frames(self):
        ob = half_grid("Driven")
        add_modifier(ob, levels=1)
        tex = bpy.data.textures.new("D", 'CLOUDS')
        mod = ob.modifiers.new("Displace", 'DISPLACE')
        mod.texture = tex
        compat_move_last(ob)
        fc = mod.driver_add("strength")
        fc.driver.type = 'SCRIPTED'
        fc.driver.expression = "frame / 10"  # a simple expression: runs without auto-exec
        self._frames_match(ob)

    def test_render_three_frames(self):
        ob = rigged("Rendered")
        add_modifier(ob, levels=1, render_levels=2)
        compat_move_last(ob)
        scene = bpy.context.scene
        cam = bpy.data.objects.new("Cam", bpy.data.cameras.new("Cam"))
        scene.collection.objects.link(cam)
        cam.location = (0.0, 1.5, 12.0)
        scene.camera = cam
        scene.render.engine = 'BLENDER_WORKBENCH'
        scene.render.resolution_x = scene.render.resolution_y = 16
        scene.frame_start, scene.frame_end, scene.frame_step = FRAMES[0], FRAMES[-1], 4
        scene.render.filepath = os.path.join(TMP, "anim_")
        scene.render.image_settings.file_format = 'PNG'
        rendered = {}

        def grab(scene_, *args):  # what the render used for this frame: the render proxy
            p = ccn.modifier.proxy(bpy.data.objects["Rendered"], 'RENDER')
            rendered[scene_.frame_current] = cagelib.mesh_positions(p.data)

        bpy.app.handlers.render_post.append(grab)
        try:
            bpy.ops.render.render(animation=True)
        finally:
            bpy.app.handlers.render_post.remove(grab)
        self.assertEqual(sorted(rendered), list(FRAMES))
        for f in FRAMES:
            scene.frame_set(f)
            R = cli_of_stack(ob, levels=2)
            self.assertEqual(rendered[f].shape, R.shape, "frame %d not at Render levels" % f)
            self.assertLessEqual(np.abs(rendered[f] - R).max(), POS_TOL, "frame %d" % f)
            self.assertTrue(os.path.exists(os.path.join(TMP, "anim_%04d.png" % f)))
        self.assertEqual(len(ccn.modifier.proxy(ob, 'RENDER').data.vertices), 0,
                         "the render mesh outlived the render")
        R = cli_of_stack(ob)  # the viewport limit of the current frame is back
        self.assertLessEqual(np.abs(evaluated_positions(ob) - R).max(), POS_TOL)


    def test_cycles_persistent_data_renders_each_frame(self):
        """Cycles with Persistent Data renders each frame's own surface (the add-on turns it off
        for the render and back on after it): its images equal those of a render without it."""
        bpy.ops.mesh.primitive_cube_add()
        ob = bpy.context.object
        d = ob.modifiers.new("Disp", 'DISPLACE')
        for f, v in ((1, 0.0), (2, 1.5), (3, -1.0)):
            d.strength = v
            d.keyframe_insert("strength", frame=f)
        add_modifier(ob, levels=1, render_levels=2)
        compat_move_last(ob)
        scene = bpy.context.scene
        cam = bpy.data.objects.new("Cam", bpy.data.cameras.new("Cam"))
        scene.collection.objects.link(cam)
        cam.location, cam.rotation_euler = (4.0, -4.0, 3.0), (1.1, 0.0, 0.785)
        scene.camera = cam
        sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", 'SUN'))
        scene.collection.objects.link(sun)
        scene.render.engine = 'CYCLES'
        scene.cycles.samples = 2
        scene.cycles.device = 'CPU'
        scene.cycles.use_denoising = False  # Debian's 3.4 is built without OpenImageDenoise
        scene.render.resolution_x = scene.render.resolution_y = 24
        scene.frame_start, scene.frame_end, scene.frame_step = 1, 3, 1
        scene.render.image_settings.file_format = 'PNG'
        images = {}
        for persistent in (True, False):
            scene.render.use_persistent_data = persistent
            scene.render.filepath = os.path.join(TMP, "pd%d_" % persistent)
            bpy.ops.render.render(animation=True)
            self.assertEqual(scene.render.use_persistent_data, persistent, "setting not restored")
            for f in (1, 2, 3):
                im = bpy.data.images.load(os.path.join(TMP, "pd%d_%04d.png" % (persistent, f)))
                images[persistent, f] = np.array(im.pixels[:])
                bpy.data.images.remove(im)
        for f in (1, 2, 3):
            np.testing.assert_array_equal(images[True, f], images[False, f],
                                          "frame %d differs with Persistent Data" % f)
        self.assertGreater(np.abs(images[False, 2] - images[False, 1]).max(), 0.05,
                           "the frames do not differ: the test shows nothing")

def compat_move_last(ob):
    """Keeps CCNURBS at the bottom of the stack (add_modifier put it first)."""
    mod = ccn.modifier.get_modifier(ob)
    bpy.context.view_layer.objects.active = ob
    with bpy.context.temp_override(object=ob, active_object=ob):
        bpy.ops.object.modifier_move_to_index(modifier=mod.name, index=len(ob.modifiers) - 1)
    update()
