"""`make bench`, Blender part: the CCNURBS modifier vs Blender's Subdivision Surface modifier at
the same output density ((2^L+1)^2 samples per cage quad), headless, on the same cages.

    blender --background --factory-startup --python-exit-code 1 \
            --python tests/blender/bench_blender.py -- BENCH_DIR build/ccnurbs.zip

For each cage and level: the time from a change to the evaluated mesh being available
(depsgraph update + evaluated mesh access, min over repeats), for a position-only change (one
vertex moved) and a topology change (the mesh datablock swapped for one with a face removed).
Prints lines starting with "bench".
"""
import os
import sys
import time

import addon_utils
import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import cagelib  # noqa: E402

ARGS = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
BENCH = os.path.abspath(ARGS[0] if ARGS else "build/bench")
ZIP = os.path.abspath(ARGS[1] if len(ARGS) > 1 else "build/ccnurbs.zip")
REPS = 5


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
    sub_topo = time_topology(ob, me_a, me_b)
    ob.modifiers.remove(mod)
    bpy.ops.object.ccnurbs_add()
    ob.ccnurbs.levels = level
    n_ccn = evaluated(ob)
    evaluated(ob)
    ccn_pos = time_positions(ob)
    ccn_topo = time_topology(ob, me_a, me_b)
    ob.ccnurbs.normals = 'FAST'
    evaluated(ob)
    evaluated(ob)
    fast_pos = time_positions(ob)
    fast_topo = time_topology(ob, me_a, me_b)
    print("bench %s L%d: %d vs %d verts | subsurf pos %.4f s topo %.4f s | ccnurbs exact normals "
          "pos %.4f s topo %.4f s (ratio %.2f, %.2f) | fast normals pos %.4f s topo %.4f s "
          "(ratio %.2f, %.2f)" % (name, level, n_ccn, n_sub, sub_pos, sub_topo, ccn_pos, ccn_topo,
                                  ccn_pos / sub_pos, ccn_topo / sub_topo, fast_pos, fast_topo,
                                  fast_pos / sub_pos, fast_topo / sub_topo))
    sys.stdout.flush()


def main():
    bpy.ops.preferences.addon_install(filepath=ZIP, overwrite=True)
    if addon_utils.enable("ccnurbs", default_set=True) is None:
        raise RuntimeError("cannot enable the add-on")
    for name in ("sphere8k", "carlike", "carlike_knots"):
        for level in (2, 3):
            bench(name, level)


main()
