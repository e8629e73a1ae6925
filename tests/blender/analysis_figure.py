"""The picture of docs/analysis.png: the add-on's Analysis on the valence-7 cage of Li, Finnigan
& Sederberg (2016) Fig. 17 (spoke intervals 1,8,8,1,1,1,8), CCNURBS at Levels 5: mean curvature
colours (left) and highlight lines (right), Workbench.

    <bpy python> tests/blender/analysis_figure.py ZIP OUT.png

Needs a Blender with the extension API (4.2+), run as the bpy module."""
import os
import sys

import bpy
import addon_utils  # noqa: E402 (after bpy: the bpy module puts it on the path)
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import cagelib  # noqa: E402

ZIP, OUT = (os.path.abspath(a) for a in sys.argv[1:3])
CAGE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "data", "fig17_v7.obj")
SIZE = 420


def render(path):
    bpy.context.scene.render.filepath = path
    bpy.ops.render.render(write_still=True)
    im = bpy.data.images.load(path)
    px = np.array(im.pixels[:], np.float32).reshape(SIZE, SIZE, 4)
    bpy.data.images.remove(im)
    return px


def main():
    bpy.ops.extensions.package_install_files(filepath=ZIP, repo="user_default",
                                             enable_on_install=False)
    addon_utils.enable("bl_ext.user_default.ccnurbs", default_set=True)
    bpy.ops.wm.read_homefile(use_empty=True)
    V, F, K = cagelib.read_obj(CAGE)
    ob = cagelib.make_object("Fig17", V, F, K)
    bpy.context.view_layer.objects.active = ob
    ob.select_set(True)
    bpy.ops.object.ccnurbs_add()
    ob.ccnurbs.levels = ob.ccnurbs.render_levels = 5
    ob.ccnurbs.curvature = 'MEAN'
    sc = bpy.context.scene
    cam = bpy.data.objects.new("Cam", bpy.data.cameras.new("Cam"))
    sc.collection.objects.link(cam)
    cam.data.type = 'ORTHO'
    cam.data.ortho_scale = 8.5
    c = np.array(V).mean(0)
    cam.location = (c[0], c[1] - 7.0, c[2] + 8.0)
    cam.rotation_euler = (0.72, 0.0, 0.0)
    sc.camera = cam
    sc.render.engine = 'BLENDER_WORKBENCH'
    sc.render.resolution_x = sc.render.resolution_y = SIZE
    sc.render.film_transparent = False
    sh = sc.display.shading
    sh.light, sh.color_type = 'STUDIO', 'VERTEX'
    left = render(OUT + ".curvature.png")
    bpy.ops.view3d.ccnurbs_highlight_lines(show=True)
    sh.color_type, sh.single_color = 'SINGLE', (0.9, 0.9, 0.9)
    right = render(OUT + ".lines.png")
    both = np.concatenate([left, right], axis=1)
    img = bpy.data.images.new("analysis", 2 * SIZE, SIZE, alpha=True)
    img.pixels.foreach_set(both.ravel())
    img.filepath_raw = OUT
    img.file_format = 'PNG'
    img.save()
    for p in (OUT + ".curvature.png", OUT + ".lines.png"):
        os.remove(p)
    print("analysis figure:", OUT)


main()
