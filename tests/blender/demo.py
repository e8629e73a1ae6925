"""`make demo` (Blender part): NURSS vs eigen rules side by side, rendered with highlight lines.

    blender --background --factory-startup --python-exit-code 1 \
            --python tests/blender/demo.py -- build/ccnurbs.zip OUTDIR

Installs the add-on from the zip, loads the valence-7 cage of Li, Finnigan & Sederberg (2016)
Fig. 17 (tests/data/fig17_v7.obj: spoke intervals 1,8,8,1,1,1,8, every ring parallel to spoke s
carrying d_s, centre lifted to z = 1: the blending function of the extraordinary point), adds
the CCNURBS modifier twice — scheme NURSS on the left, EIGEN on the right — draws the cage edges
(long intervals red, 1 grey), counts the local maxima of both render meshes and writes them in
the labels, and renders a top view with Workbench and a highlight-line (stripe) matcap to
OUTDIR/demo.png: every maximum is a bullseye of closed stripes. Saves OUTDIR/demo.blend (it opens
and renders without the add-on).

Why not Fig. 1: its exact colouring is not known (DESIGN §4.3). Fig. 17 gives two maxima with
NURSS and one with the eigen rules at every level 3–6 (Fig. 16 and 18 too, since the eigen rules
act from level 0 on an extraordinary vertex that is ready for them, refine.c).
"""
import os
import sys

import addon_utils
import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import cagelib  # noqa: E402

ARGS = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
ZIP = os.path.abspath(ARGS[0] if ARGS else "build/ccnurbs.zip")
OUT = os.path.abspath(ARGS[1] if len(ARGS) > 1 else "out")
CAGE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "data", "fig17_v7.obj")
SPACING = 9.5
RED = (0.85, 0.08, 0.05, 1.0)
GREY = (0.25, 0.25, 0.28, 1.0)
SURFACE = (0.92, 0.92, 0.92, 1.0)


def stripe_matcap(path, size=512, period_deg=6.0):
    """A highlight-line matcap: light and dark stripes by the angle between the normal and the
    view direction. Seen from above, every point where the surface is horizontal (a maximum,
    a minimum or a saddle) sits in the middle of its own closed stripe, so each peak shows up
    as a bullseye, and kinks in the stripes show curvature defects."""
    y, x = np.mgrid[0:size, 0:size]
    nx, ny = (x + 0.5) / size * 2 - 1, (y + 0.5) / size * 2 - 1
    r = np.sqrt(nx * nx + ny * ny)
    theta = np.degrees(np.arcsin(np.clip(r, 0, 1)))
    c = np.cos(2 * np.pi * theta / period_deg)
    px = np.gradient(theta, axis=1)  # about one pixel in degrees: antialiased edges
    band = np.clip(0.5 + c / (2 * np.pi / period_deg * np.maximum(np.abs(px), 1e-3) * 2), 0, 1)
    v = np.where(r <= 1, 0.12 + 0.83 * band, 0.0)
    rgba = np.dstack([v, v, v, np.ones_like(v)]).astype(np.float32)
    img = bpy.data.images.new("stripes", size, size, alpha=True, float_buffer=True)
    img.pixels.foreach_set(rgba.ravel())
    img.filepath_raw = path
    img.file_format = 'PNG'
    img.save()
    bpy.data.images.remove(img)
    return path


def edge_tubes(name, P, edges, radius, color):
    """Thin square tubes along edges (numpy-built mesh), one object, flat colour."""
    a, b = P[edges[:, 0]], P[edges[:, 1]]
    d = b - a
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    ref = np.where(np.abs(d[:, 2:3]) < 0.9, [[0, 0, 1.0]], [[1.0, 0, 0]])
    u = np.cross(d, ref)
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    w = np.cross(d, u)
    ring = np.stack([u + w, -u + w, -u - w, u - w], axis=1) * radius * 0.7071
    V = np.concatenate([a[:, None] + ring, b[:, None] + ring], axis=1).reshape(-1, 3)
    base = (np.arange(len(edges)) * 8)[:, None]
    quads = np.array([[0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]])
    F = (base[:, None, :] + quads[None]).reshape(-1, 4)
    me = bpy.data.meshes.new(name)
    me.from_pydata(V.tolist(), [], F.tolist())
    ob = bpy.data.objects.new(name, me)
    ob.color = color
    bpy.context.scene.collection.objects.link(ob)
    return ob


def label(text, x, y):
    cu = bpy.data.curves.new(text, 'FONT')
    cu.body = text
    cu.align_x = 'CENTER'
    cu.size = 0.6
    ob = bpy.data.objects.new(text, cu)
    ob.location = (x, y, 0.0)
    ob.color = (0.1, 0.1, 0.1, 1.0)
    bpy.context.scene.collection.objects.link(ob)
    return ob


def cage_object(name, x, scheme, V, F, K):
    ob = cagelib.make_object(name, V, F, K)
    ob.location.x = x
    bpy.context.view_layer.objects.active = ob
    for o in bpy.context.selected_objects:
        o.select_set(False)
    ob.select_set(True)
    bpy.ops.object.ccnurbs_add()
    s = ob.ccnurbs
    s.scheme, s.levels, s.render_levels = scheme, 3, 5
    s.store_render_mesh = True  # demo.blend opens and renders without the add-on
    ob.color = SURFACE
    # cage edges: long intervals red, 1 grey; the spokes to the lifted centre are left out
    # (they would hide the bump)
    keys = np.array(cagelib.edge_keys(ob.data))
    keys = keys[keys[:, 0] != 0]
    k = np.array([K.get(tuple(e), 1.0) for e in keys])
    P = V + [x, 0, 0]
    edge_tubes(name + " cage d=10", P, keys[k > 1.5], 0.035, RED)
    edge_tubes(name + " cage d=1", P, keys[k <= 1.5], 0.02, GREY)
    return ob


def local_maxima(me, eps=1e-3):
    """Vertices higher than every other vertex of every face around them (quads)."""
    P = cagelib.mesh_positions(me)
    lv = np.empty(len(me.loops), np.int32)
    me.loops.foreach_get("vertex_index", lv)
    Fq = lv.reshape(-1, 4)
    z = P[:, 2]
    nb = np.full(len(P), -np.inf)
    for c in range(4):
        others = z[np.delete(Fq, c, axis=1)].max(axis=1)
        np.maximum.at(nb, Fq[:, c], others)
    return np.flatnonzero((z > nb) & (z > eps))


def main():
    os.makedirs(OUT, exist_ok=True)
    bpy.ops.preferences.addon_install(filepath=ZIP, overwrite=True)
    if addon_utils.enable("ccnurbs", default_set=True, handle_error=None) is None:
        raise SystemExit("demo: cannot enable the add-on from " + ZIP)
    bpy.ops.wm.read_homefile(use_empty=True)
    scene = bpy.context.scene

    V, F, K = cagelib.read_obj(CAGE)
    nurss = cage_object("NURSS", -SPACING / 2, 'NURSS', V, F, K)
    eigen = cage_object("Eigen", SPACING / 2, 'EIGEN', V, F, K)

    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    cam.data.type = 'ORTHO'
    cam.data.ortho_scale = 20.0
    scene.collection.objects.link(cam)
    cam.location = (0.0, -0.6, 30.0)
    cam.rotation_euler = (0.0, 0.0, 0.0)  # straight down
    scene.camera = cam

    world = bpy.data.worlds.new("World")
    world.color = (0.82, 0.84, 0.87)
    scene.world = world
    scene.render.engine = 'BLENDER_WORKBENCH'
    scene.render.resolution_x, scene.render.resolution_y = 1600, 900
    scene.render.resolution_percentage = 100
    scene.render.film_transparent = False
    scene.display.render_aa = '16'
    sh = scene.display.shading
    sh.light = 'MATCAP'
    matcap = stripe_matcap(os.path.join(OUT, "stripe_matcap.png"))
    sl = bpy.context.preferences.studio_lights.load(matcap, 'MATCAP')
    sh.studio_light = sl.name if sl is not None else "reflection_check_vertical.exr"
    sh.color_type = 'OBJECT'
    sh.show_specular_highlight = False

    ccn = sys.modules[[m for m in sys.modules if m.rpartition(".")[2] == "ccnurbs"][0]]
    bpy.context.view_layer.update()
    for ob, title in ((nurss, "NURSS (1998)"), (eigen, "Eigen (Li et al. 2016)")):
        n = len(local_maxima(ccn.modifier.proxy(ob, 'RENDER').data))
        label("%s: %d maxim%s" % (title, n, "um" if n == 1 else "a"), ob.location.x, -5.6)
        print("demo: %-6s %d local maxima at render levels %d" % (ob.name, n,
                                                                 ob.ccnurbs.render_levels))

    png, blend = os.path.join(OUT, "demo.png"), os.path.join(OUT, "demo.blend")
    scene.render.filepath = png
    scene.render.image_settings.file_format = 'PNG'
    bpy.ops.render.render(write_still=True)
    bpy.context.preferences.filepaths.save_version = 0  # no demo.blend1 backups
    bpy.ops.wm.save_as_mainfile(filepath=blend, compress=True)
    for ob in (nurss, eigen):
        st = ccn.sync.status(ob, 'RENDER')
        if st is None or st.error:
            raise SystemExit("demo: %s render proxy: %s" % (ob.name, st and st.error))
        print("demo: %-6s scheme %-5s render levels %d: %d vertices"
              % (ob.name, ob.ccnurbs.scheme, ob.ccnurbs.render_levels, st.num_verts))
    print("demo: wrote %s and %s" % (png, blend))


main()
