"""Animation: armature, shape-key and driver animation above CCNURBS follow frame_set; renders
(Workbench, Cycles with Persistent Data and motion blur, EEVEE with motion blur) show each frame's
limit at Render levels; Alembic and USD exports carry it to a Blender without the add-on."""
import math
import os
import subprocess

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

    def test_alembic_and_usd_carry_each_frames_surface(self):
        """For a render farm without the add-on: Alembic and USD exports of the animated limit
        surface, read back by a fresh Blender without the add-on (Mesh Sequence Cache), give
        each frame's own limit."""
        ob = shape_keyed("Farm")
        add_modifier(ob, levels=1, render_levels=2)
        scene = bpy.context.scene
        scene.frame_start, scene.frame_end = FRAMES[0], FRAMES[-1]
        expect = {}
        for f in FRAMES:
            scene.frame_set(f)
            expect[f] = cli_of_stack(ob, levels=2)
        self.assertGreater(np.abs(expect[FRAMES[1]] - expect[FRAMES[0]]).max(), 0.05,
                           "the frames do not differ: the test shows nothing")
        bpy.ops.object.select_all(action='DESELECT')
        ob.select_set(True)
        files = {}
        if "alembic_export" in dir(bpy.ops.wm):  # Debian's 3.4 is built without both
            files["abc"] = os.path.join(TMP, "farm.abc")
            bpy.ops.wm.alembic_export(filepath=files["abc"], start=FRAMES[0], end=FRAMES[-1],
                                      selected=True, evaluation_mode='RENDER')
        if "usd_export" in dir(bpy.ops.wm):
            files["usd"] = os.path.join(TMP, "farm.usdc")
            usd = {"selected_objects_only": True, "export_animation": True,
                   "evaluation_mode": 'RENDER'}
            # shape keys and armatures written as USD skeletons would bypass the modifier stack
            names = bpy.ops.wm.usd_export.get_rna_type().properties.keys()
            usd.update({k: False for k in ("export_shapekeys", "export_armatures") if k in names})
            bpy.ops.wm.usd_export(filepath=files["usd"], **usd)
        if not files:
            self.skipTest("this Blender has neither Alembic nor USD")
        reader = os.path.join(TMP, "farm_read.py")
        out = os.path.join(TMP, "farm_read.npz")
        with open(reader, "w") as fh:
            fh.write(FARM_READER % {"files": files, "out": out, "frames": list(FRAMES)})
        subprocess.run(blender_command(reader), check=True, timeout=300,
                       stdout=subprocess.DEVNULL)
        got = np.load(out)
        for kind in files:
            for f in FRAMES:
                P = got["%s_%d" % (kind, f)]
                self.assertEqual(P.shape, expect[f].shape, "%s frame %d" % (kind, f))
                self.assertLessEqual(np.abs(P - expect[f]).max(), POS_TOL, "%s frame %d" % (kind, f))


    def test_cycles_motion_blur_as_subsurf(self):
        """Cycles' motion blur sees the limit surface of the shutter's subframes: the blurred
        coverage (alpha) of the cage equals that of the same cage under Subdivision Surface
        (equal intervals: the same surface), and differs clearly from an unblurred render."""
        scene = bpy.context.scene
        obs = blur_twins()
        scene.render.engine = 'CYCLES'
        scene.cycles.samples = 16
        scene.cycles.device = 'CPU'
        scene.cycles.use_denoising = False
        scene.frame_set(2)
        alpha = {}
        for blur in (True, False):
            scene.render.use_motion_blur = blur
            alpha.update(render_alpha(obs, "blur%d" % blur, (blur,)))
        same = np.abs(alpha[True, "CCNURBS"] - alpha[True, "SUBSURF"]).max()
        blurred = np.abs(alpha[True, "SUBSURF"] - alpha[False, "SUBSURF"]).max()
        print("measure motion-blur alpha: CCNURBS vs Subsurf %.4f, blurred vs sharp %.4f"
              % (same, blurred))
        self.assertGreater(blurred, 0.3, "no motion blur to compare: the test shows nothing")
        self.assertLessEqual(same, 0.02, "the blurred limit differs from Subdivision Surface's")

    def test_eevee_frames_and_motion_blur_as_subsurf(self):
        """EEVEE renders each frame's limit surface, with and without motion blur: the coverage
        (alpha) of the cage equals that of the same cage under Subdivision Surface."""
        scene = bpy.context.scene
        obs = blur_twins()
        engines = [e.identifier for e in scene.render.bl_rna.properties["engine"].enum_items]
        scene.render.engine = "BLENDER_EEVEE_NEXT" if "BLENDER_EEVEE_NEXT" in engines \
            else "BLENDER_EEVEE"
        # EEVEE Legacy blurs with one time step per sample: 4 leave 0.035 of noise in alpha
        scene.eevee.taa_render_samples = 8 if bpy.app.version < (4, 2, 0) else 4
        alpha = {}
        for blur, f in ((False, 2), (False, 3), (True, 2)):
            scene.render.use_motion_blur = blur
            if hasattr(scene.eevee, "use_motion_blur"):  # before 4.2
                scene.eevee.use_motion_blur = blur
            scene.frame_set(f)
            alpha.update(render_alpha(obs, "eevee%d_%d" % (blur, f), (blur, f)))
        for blur, f in ((False, 2), (False, 3), (True, 2)):
            same = np.abs(alpha[blur, f, "CCNURBS"] - alpha[blur, f, "SUBSURF"]).max()
            self.assertLessEqual(same, 0.02, "frame %d, motion blur %s" % (f, blur))
        self.assertGreater(np.abs(alpha[False, 3, "SUBSURF"] - alpha[False, 2, "SUBSURF"]).max(),
                           0.3, "the frames do not differ: the test shows nothing")
        self.assertGreater(np.abs(alpha[True, 2, "SUBSURF"] - alpha[False, 2, "SUBSURF"]).max(),
                           0.1, "no motion blur to compare: the test shows nothing")


def blur_twins():
    """Two cubes with the same animated Displace: one under Subdivision Surface, one under
    CCNURBS (equal intervals: the same limit), a camera and transparent film."""
    scene = bpy.context.scene
    obs = {}
    for kind in ("SUBSURF", "CCNURBS"):
        bpy.ops.mesh.primitive_cube_add()
        ob = bpy.context.object
        ob.name = "Blur" + kind
        d = ob.modifiers.new("Disp", 'DISPLACE')
        for f, v in ((1, 0.0), (2, 1.5), (3, -1.0)):
            d.strength = v
            d.keyframe_insert("strength", frame=f)
        if kind == "SUBSURF":
            m = ob.modifiers.new("Subsurf", 'SUBSURF')
            m.levels, m.render_levels, m.use_limit_surface = 1, 2, True
            m.boundary_smooth = 'ALL'
        else:
            add_modifier(ob, levels=1, render_levels=2)
            compat_move_last(ob)
        obs[kind] = ob
    cam = bpy.data.objects.new("Cam", bpy.data.cameras.new("Cam"))
    scene.collection.objects.link(cam)
    cam.location, cam.rotation_euler = (4.0, -4.0, 3.0), (1.1, 0.0, 0.785)
    scene.camera = cam
    scene.render.film_transparent = True
    scene.render.resolution_x = scene.render.resolution_y = 32
    scene.render.image_settings.file_format = 'PNG'
    scene.render.image_settings.color_mode = 'RGBA'
    return obs


def render_alpha(obs, stem, key):
    """{key + (kind,): alpha} of a still of each twin alone."""
    scene = bpy.context.scene
    out = {}
    for kind, ob in obs.items():
        for o in obs.values():
            o.hide_render = o is not ob
        path = os.path.join(TMP, "%s_%s.png" % (stem, kind))
        scene.render.filepath = path
        bpy.ops.render.render(write_still=True)
        im = bpy.data.images.load(path)
        out[key + (kind,)] = np.array(im.pixels[:]).reshape(-1, 4)[:, 3]
        bpy.data.images.remove(im)
    return out

FARM_READER = '''import bpy, numpy as np
frames = %(frames)r
res = {}
for kind, path in %(files)r.items():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    before = set(bpy.data.objects)
    if kind == "abc":
        bpy.ops.wm.alembic_import(filepath=path)
    else:
        bpy.ops.wm.usd_import(filepath=path)
    # the modifier's input tap comes along as an instance scaled to zero: it draws nothing
    obs = [o for o in bpy.data.objects if o not in before and o.type == 'MESH'
           and o.matrix_world.to_scale().length > 0]
    assert len(obs) == 1, obs
    for f in frames:
        bpy.context.scene.frame_set(f)
        me = obs[0].evaluated_get(bpy.context.evaluated_depsgraph_get()).data
        P = np.empty(3 * len(me.vertices))
        me.vertices.foreach_get("co", P)
        res["%%s_%%d" %% (kind, f)] = P.reshape(-1, 3)
np.savez(%(out)r, **res)
'''


def compat_move_last(ob):
    """Keeps CCNURBS at the bottom of the stack (add_modifier put it first)."""
    mod = ccn.modifier.get_modifier(ob)
    bpy.context.view_layer.objects.active = ob
    with bpy.context.temp_override(object=ob, active_object=ob):
        bpy.ops.object.modifier_move_to_index(modifier=mod.name, index=len(ob.modifiers) - 1)
    update()
