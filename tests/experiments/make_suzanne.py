# Writes tests/data/suzanne.obj, run once with Blender 3.4:
#   blender --background --factory-startup --python-exit-code 1 --python tests/experiments/make_suzanne.py
# then move /tmp/q/suzanne.obj to tests/data/.
import bpy, bmesh
bpy.ops.mesh.primitive_monkey_add(size=2)
ob = bpy.context.active_object
bm = bmesh.new(); bm.from_mesh(ob.data)
v2 = [v for v in bm.verts if len(v.link_edges) == 2]
print("valence-2 vertices:", len(v2), [tuple(round(c, 4) for c in v.co) for v in v2])
bmesh.ops.dissolve_verts(bm, verts=v2)
bm.verts.index_update()
sizes = {}
for f in bm.faces: sizes[len(f.verts)] = sizes.get(len(f.verts), 0) + 1
print("faces by size:", sizes, "verts", len(bm.verts))
with open("/tmp/q/suzanne.obj", "w") as fo:
    fo.write("# Blender %s primitive_monkey_add(size=2), its valence-2 vertices dissolved (bmesh.ops.dissolve_verts)\n" % bpy.app.version_string)
    for v in bm.verts: fo.write("v %.9g %.9g %.9g\n" % tuple(v.co))
    for f in bm.faces: fo.write("f %s\n" % " ".join(str(v.index + 1) for v in f.verts))
