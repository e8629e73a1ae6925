"""`make bench`, Blender part: the CCNURBS modifier vs Blender's Subdivision Surface modifier at
the same output density ((2^L+1)^2 samples per cage quad), headless, on the same cages.

    blender --background --factory-startup --python-exit-code 1 \
            --python tests/blender/bench_blender.py -- BENCH_DIR build/ccnurbs.zip
    VENV/bin/python tests/blender/bench_blender.py BENCH_DIR build/ccnurbs.zip   (bpy 4.5 / 5.x)

For each cage and level: the time from a change to the evaluated mesh being available
(depsgraph update + evaluated mesh access, min over repeats), for a position-only change (one
vertex moved, in Object Mode and in Edit Mode), a topology change (the mesh datablock swapped
for one with a face removed) and, for CCNURBS, an interval edit (one edge's knot interval
changed: same topology). Default settings (Exact normals, Guided Bi-5 cap) and Fast normals.
Edits are timed as in an interactive session: on Blender < 4.5 (encoded custom normals) the
exact normals are written once editing pauses, and that write is timed on its own line.
Then animation playback: the production-like cage (carlike, 2.3k faces) bent by a one-bone
armature over 24 keyed frames, frames per second of frame_set + evaluation
(CCN_BENCH_ANIMATION_CASES). Prints lines starting with "bench".
"""
import os
import sys
import time

import bpy  # first: the bpy module (4.5 / 5.x venvs) puts addon_utils and bmesh on the path
import addon_utils  # noqa: E402
import bmesh  # noqa: E402
import numpy as np  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import cagelib  # noqa: E402

ARGS = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else sys.argv[1:]
BENCH = os.path.abspath(ARGS[0] if ARGS else "build/bench")
ZIP = os.path.abspath(ARGS[1] if len(ARGS) > 1 else "build/ccnurbs.zip")
REPS = 3


def update():
    bpy.context.view_layer.update()
    return bpy.context.evaluated_depsgraph_get()


def evaluated(ob):
    """Evaluate until the result is stable (our handler writes the proxy on the first update)."""
    dg = update()
    me = ob.evaluated_get(dg).data
    return len(me.vertices)


def load(name):
    V, F, knots = cagelib.read_obj(os.path.join(BENCH, name + ".obj"))
    ob = cagelib.make_object(name, V, F, knots)
    bpy.context.view_layer.objects.active = ob
    ob.select_set(True)
    # the topology-change twin: the same cage without its last face
    me2 = bpy.data.meshes.new(name + "_minus")
    me2.from_pydata([tuple(v) for v in V], [], [tuple(f) for f in F[:-1]])
    me2.update()
    if knots:
        cagelib.set_knots(me2, knots)
    return ob, ob.data, me2


def time_positions(ob):
    me = ob.data
    co = np.empty(3 * len(me.vertices))
    me.vertices.foreach_get("co", co)
    best = 1e30
    for r in range(REPS):
        co[0] += 1e-3
        me.vertices.foreach_set("co", co)
        me.update()
        t0 = time.perf_counter()
        evaluated(ob)
        evaluated(ob)  # a proxy written by a handler is read on the next evaluation
        best = min(best, time.perf_counter() - t0)
    return best


def time_edit_positions(ob):
    """One vertex moved in Edit Mode (bmesh + update_edit_mesh, as a grab does)."""
    bpy.context.view_layer.objects.active = ob
    bpy.ops.object.mode_set(mode='EDIT')
    bm = bmesh.from_edit_mesh(ob.data)
    bm.verts.ensure_lookup_table()
    evaluated(ob)
    evaluated(ob)
    best = 1e30
    for r in range(REPS):
        bm.verts[0].co.x += 1e-3
        bmesh.update_edit_mesh(ob.data)
        t0 = time.perf_counter()
        evaluated(ob)
        evaluated(ob)
        best = min(best, time.perf_counter() - t0)
    bpy.ops.object.mode_set(mode='OBJECT')
    return best


def time_interval(ob):
    """One edge's knot interval changed (the add-on's EDGE attribute): same topology."""
    me = ob.data
    att = me.attributes.get("knot_interval") or me.attributes.new("knot_interval", 'FLOAT', 'EDGE')
    best = 1e30
    for r in range(REPS):
        att.data[0].value = 1.0 + 0.125 * (1 + (att.data[0].value / 0.125) % 7)  # always a new value
        me.update()
        t0 = time.perf_counter()
        evaluated(ob)
        evaluated(ob)
        best = min(best, time.perf_counter() - t0)
    return best


def time_topology(ob, me_a, me_b):
    best = 1e30
    for r in range(REPS):
        ob.data = me_b if r % 2 == 0 else me_a
        t0 = time.perf_counter()
        evaluated(ob)
        evaluated(ob)
        best = min(best, time.perf_counter() - t0)
    ob.data = me_a
    return best


def bench(name, level):
    bpy.ops.wm.read_homefile(use_empty=True)
    ob, me_a, me_b = load(name)
    mod = ob.modifiers.new("Subsurf", 'SUBSURF')
    mod.levels = mod.render_levels = level
    n_sub = evaluated(ob)
    sub_pos = time_positions(ob)
    sub_edit = time_edit_positions(ob)
    sub_topo = time_topology(ob, me_a, me_b)
    ob.modifiers.remove(mod)
    bpy.ops.object.ccnurbs_add()
    ob.ccnurbs.levels = level
    n_ccn = evaluated(ob)
    evaluated(ob)
    r = {}
    flush = None
    for normals in ('EXACT', 'FAST'):
        ob.ccnurbs.normals = normals
        evaluated(ob)
        evaluated(ob)
        r[normals] = (time_positions(ob), time_edit_positions(ob), time_interval(ob),
                      time_topology(ob, me_a, me_b))
        if normals == 'EXACT' and HANDLERS.sync.pending_normals():  # < 4.5: once editing pauses
            t0 = time.perf_counter()
            HANDLERS.write_pending_normals()
            evaluated(ob)
            evaluated(ob)
            flush = time.perf_counter() - t0
    # Analysis > Curvature (mean) on against off: a vertex move as an interactive edit does it
    # (the curvatures once editing pauses), the two measured in turn (3 rounds of REPS each) so
    # that a noisy moment does not fall on one of them only; then that pause's write, and the
    # update that computes the curvatures at once (frame changes, scripts, renders)
    ob.ccnurbs.normals = 'EXACT'
    best = {'NONE': 1e30, 'MEAN': 1e30, 'NOW': 1e30}
    pause = 1e30
    for _ in range(3):
        for mode in ('NONE', 'MEAN', 'NOW'):
            HANDLERS.DEFER_IN_BACKGROUND[0] = mode != 'NOW'
            ob.ccnurbs.curvature = 'NONE' if mode == 'NONE' else 'MEAN'
            evaluated(ob)
            evaluated(ob)
            HANDLERS.write_pending_normals()
            best[mode] = min(best[mode], time_positions(ob))
            if mode == 'MEAN':
                t0 = time.perf_counter()
                HANDLERS.write_pending_normals()
                evaluated(ob)
                evaluated(ob)
                pause = min(pause, time.perf_counter() - t0)
    HANDLERS.DEFER_IN_BACKGROUND[0] = True
    ob.ccnurbs.curvature = 'NONE'
    evaluated(ob)
    print("bench %s L%d (Blender %s) ccnurbs analysis: pos with curvature %.4f s, without %.4f s "
          "(%.2fx); the curvatures once editing pauses %.4f s; computed at once %.4f s (%.2fx)"
          % (name, level, bpy.app.version_string, best['MEAN'], best['NONE'],
             best['MEAN'] / best['NONE'], pause, best['NOW'], best['NOW'] / best['NONE']))
    print("bench %s L%d (Blender %s): %d vs %d verts | subsurf pos %.4f s edit %.4f s topo %.4f s"
          % (name, level, bpy.app.version_string, n_ccn, n_sub, sub_pos, sub_edit, sub_topo))
    if flush is not None:
        print("bench %s L%d (Blender %s) ccnurbs deferred normal write (once editing pauses, "
              "encoded custom normals): %.4f s" % (name, level, bpy.app.version_string, flush))
    for normals in ('EXACT', 'FAST'):
        pos, edit, itv, topo = r[normals]
        print("bench %s L%d (Blender %s) ccnurbs %s normals: pos %.4f s (%.2fx) edit %.4f s (%.2fx) "
              "interval %.4f s (%.2fx subsurf topo) topo %.4f s (%.2fx)"
              % (name, level, bpy.app.version_string, normals.lower(), pos, pos / sub_pos, edit,
                 edit / sub_edit, itv, itv / sub_topo, topo, topo / sub_topo))
    sys.stdout.flush()


def _rig(ob):
    """An armature with one bone bending the cage's +x half, keyed over FRAMES frames."""
    arm = bpy.data.armatures.new("Rig")
    rig = bpy.data.objects.new("Rig", arm)
    bpy.context.scene.collection.objects.link(rig)
    for o in bpy.context.view_layer.objects:
        o.select_set(False)
    bpy.context.view_layer.objects.active = rig
    bpy.ops.object.mode_set(mode='EDIT')
    b = arm.edit_bones.new("Bend")
    b.head, b.tail = (0.0, 0.0, 0.0), (1.0, 0.0, 0.0)
    bpy.ops.object.mode_set(mode='OBJECT')
    co = np.empty(3 * len(ob.data.vertices), np.float32)
    ob.data.vertices.foreach_get("co", co)
    vg = ob.vertex_groups.new(name="Bend")
    vg.add([int(i) for i in np.nonzero(co[0::3] > 0)[0]], 1.0, 'REPLACE')
    m = ob.modifiers.new("Armature", 'ARMATURE')
    m.object = rig
    pb = rig.pose.bones["Bend"]
    pb.rotation_mode = 'XYZ'
    for f, a in ((1, 0.0), (FRAMES, 0.6)):
        pb.rotation_euler = (0.0, a, 0.0)
        pb.keyframe_insert("rotation_euler", frame=f)
    bpy.context.view_layer.objects.active = ob
    ob.select_set(True)


FRAMES = 24


def time_playback(ob):
    """Frames per second of stepping through the animation (each frame evaluated until the
    modifier's output is there: for CCNURBS the second evaluation shows the new limit)."""
    sc = bpy.context.scene
    best = 1e30
    for r in range(REPS):
        t0 = time.perf_counter()
        for f in range(1, FRAMES + 1):
            sc.frame_set(f)
            evaluated(ob)
        best = min(best, time.perf_counter() - t0)
    # what was timed is the animation: the shown surface differs from frame to frame
    seen = set()
    for f in (2, FRAMES // 2, FRAMES):
        sc.frame_set(f)
        evaluated(ob)
        me = ob.evaluated_get(bpy.context.evaluated_depsgraph_get()).data
        co = np.empty(3 * len(me.vertices), np.float32)
        me.vertices.foreach_get("co", co)
        seen.add(round(float(np.abs(co).sum()), 3))
    if len(seen) < 3:
        raise RuntimeError("playback: the evaluated surface did not follow the armature")
    return FRAMES / best


def bench_animation(name, level):
    """Playback of an armature-deformed cage, CCNURBS vs Subdivision Surface."""
    bpy.ops.wm.read_homefile(use_empty=True)
    ob, _, _ = load(name)
    _rig(ob)
    mod = ob.modifiers.new("Subsurf", 'SUBSURF')
    mod.levels = mod.render_levels = level
    evaluated(ob)
    sub = time_playback(ob)
    ob.modifiers.remove(mod)
    bpy.ops.object.ccnurbs_add()
    ob.ccnurbs.levels = level
    ccn_mod = [m for m in ob.modifiers if m.type == 'NODES'][0]  # Add puts it first: below the rig
    with bpy.context.temp_override(object=ob, active_object=ob):
        bpy.ops.object.modifier_move_to_index(modifier=ccn_mod.name, index=len(ob.modifiers) - 1)
    evaluated(ob)
    evaluated(ob)
    ccn = time_playback(ob)
    print("bench animation %s L%d (Blender %s, %d faces, armature, %d frames): ccnurbs %.1f fps, "
          "subsurf %.1f fps (%.2fx)" % (name, level, bpy.app.version_string, len(ob.data.polygons),
                                        FRAMES, ccn, sub, sub / ccn))
    sys.stdout.flush()


def install():
    if bpy.app.version >= (4, 2, 0):
        res = bpy.ops.extensions.package_install_files(filepath=ZIP, repo="user_default",
                                                       enable_on_install=False)
        if res != {'FINISHED'}:
            raise RuntimeError("extensions.package_install_files: %s" % res)
        name = "bl_ext.user_default.ccnurbs"
    else:
        bpy.ops.preferences.addon_install(filepath=ZIP, overwrite=True)
        name = "ccnurbs"
    if addon_utils.enable(name, default_set=True) is None:
        raise RuntimeError("cannot enable the add-on")
    global HANDLERS
    HANDLERS = sys.modules[name + ".handlers"]
    # what an interactive session does (timers do not run here): on Blender < 4.5 exact normals
    # are written once editing pauses; that write is timed apart
    HANDLERS.DEFER_IN_BACKGROUND[0] = True


HANDLERS = None


def main():
    install()
    cases = os.environ.get("CCN_BENCH_BLENDER_CASES",
                           "sphere8k:2 sphere8k:3 sphere50k:2 carlike_knots:2 carlike_knots:3")
    for c in cases.split():
        name, level = c.split(":")
        bench(name, int(level))
    for c in os.environ.get("CCN_BENCH_ANIMATION_CASES", "carlike:2").split():
        name, level = c.split(":")
        bench_animation(name, int(level))


main()
