"""Writing the limit into a proxy mesh, and keeping proxy meshes out of saved files.

All bulk data goes through foreach_set. A proxy's mesh is its own (never the shared empty mesh
used while saving). Saving: a viewport proxy shows what the add-on computes again on load, so
it points at one empty mesh during the write (`save_pre` / `save_post`: O(1) per cage, the mesh
itself is untouched; through the Python API, so the proxies are evaluated again at the next
redraw -- the add-on writes nothing into Blender's memory behind its API); a render proxy is
empty outside renders unless the cage's *Store Render Mesh in File* is on, and is then written
as it is (never rebuilt by saving).
"""
import bpy
import numpy as np

from . import attrs, compat

EMPTY_NAME = ".CCNURBS empty"
KEY_PROP = "ccnurbs_key"
LIMIT_ATTR = "ccn_limit"  # FACE bool on every limit face: tells an applied limit from a cage
TOPO_PROP = "ccnurbs_topology"
PLAN_PROP = "ccnurbs_plan"  # the plan (intervals included) its UV maps and attributes come from

_detached = []  # (proxy name, mesh name) swapped out for a save


def own_mesh(p):
    """The proxy's mesh, replaced by a new one if it is shared (the empty mesh of a save)."""
    me = p.data
    if me is None or me.users > 1 or me.name.startswith(EMPTY_NAME) or me.library is not None:
        me = bpy.data.meshes.new(p.name)
        p.data = me
    return me


def write_normals(me, res, exact):
    """Exact: the library's normals as custom split normals, per face corner where the surface
    has creases or corners (each side its own), else per vertex. Fast: Blender's own."""
    if not exact:
        compat.use_plain_normals(me)
    elif "corner_normals" in res:
        compat.set_corner_normals(me, res["corner_normals"].astype(np.float32))
    else:
        compat.set_vertex_normals(me, res["normals"].astype(np.float32))


def write_creases(me, res, cage):
    """The cage's edge creases on the limit mesh's edges that lie on creased cage edges
    (attrs.edge_origin), so a crease survives Apply as on Subdivision Surface's result."""
    if cage.edge_creases is None or not np.any(cage.edge_creases > 0) or "corner_edge_origin" not in res:
        return
    edge_from = attrs.edge_origin(me, res["corner_edge_origin"], cage.loop_edges)
    out = np.zeros(len(me.edges), np.float32)
    on = edge_from >= 0
    out[on] = np.maximum(cage.edge_creases[edge_from[on]], 0.0)
    compat.set_edge_creases(me, out)


def write_topology(me, res, cage, exact=True):
    pos = res["positions"].astype(np.float32).ravel()
    fv = res["face_verts"].ravel()
    nv, nf = len(res["positions"]), len(res["face_verts"])
    me.clear_geometry()
    me.vertices.add(nv)
    me.loops.add(4 * nf)
    me.polygons.add(nf)
    compat.set_array(me, "positions", pos)
    compat.set_array(me, "corner_verts", fv)
    compat.set_face_loops(me, np.arange(0, 4 * nf, 4, dtype=np.int32), np.full(nf, 4, np.int32))
    edges = compat.set_edges(me, res["edge_verts"].ravel(), res["corner_edges"].ravel())
    compat.set_all_smooth(me)
    if cage.material_index is not None and cage.material_index.any():  # all 0: no attribute
        origin = np.clip(res["face_origin"], 0, len(cage.material_index) - 1)
        compat.set_material_index(me, cage.material_index[origin])
    me.attributes.new(LIMIT_ATTR, 'BOOLEAN', 'FACE').data.foreach_set("value", np.ones(nf, bool))
    me.update(calc_edges=not edges)
    if not edges and "loose_edges" in res:  # edges Blender computed from the faces: add the loose
        ev = np.empty(2 * len(me.edges), np.int32)
        me.edges.foreach_get("vertices", ev)
        me.edges.add(len(res["loose_edges"]))
        me.edges.foreach_set("vertices", np.concatenate([ev, res["loose_edges"].ravel()]))
        me.update()
    write_creases(me, res, cage)
    write_normals(me, res, exact)


def write_positions(me, res, exact=True):
    compat.set_array(me, "positions", res["positions"].astype(np.float32).ravel())
    me.update()
    write_normals(me, res, exact)


CAGE_KEY = "cage"  # KEY_PROP of a proxy that shows the cage itself (Levels 0)


def show_cage(p):
    """Levels 0, as Subdivision Surface: the modifier shows its input. The proxy becomes one
    point and no face, which the group reads as "show the input mesh" (modifier.build_group);
    an empty proxy would mean "no limit of this kind: show the other one"."""
    me = p.data
    if me is not None and me.get(KEY_PROP) == CAGE_KEY and len(me.vertices) == 1 \
            and not len(me.polygons):
        return False
    me = own_mesh(p)
    me.clear_geometry()
    me.vertices.add(1)
    for k in (TOPO_PROP, PLAN_PROP, attrs.KEY_PROP):
        if k in me:
            del me[k]
    me[KEY_PROP] = CAGE_KEY
    me.update()
    return True


def clear(p):
    """Empties a proxy (the modifier then shows its input, or the viewport proxy in renders)."""
    if p is None or p.data is None or not len(p.data.vertices) and KEY_PROP not in p.data:
        return False
    me = own_mesh(p)
    me.clear_geometry()
    for k in (KEY_PROP, TOPO_PROP, PLAN_PROP):
        if k in me:
            del me[k]
    return True


def sync_materials(src_mesh, p):
    src, dst = src_mesh.materials, p.data.materials
    if [m for m in src] != [m for m in dst]:
        dst.clear()
        for m in src:
            dst.append(m)


def size_bytes(me):
    """What a mesh adds to a .blend (positions, edges, corners, faces, custom normals), roughly."""
    if me is None:
        return 0
    nv, ne, nl, nf = len(me.vertices), len(me.edges), len(me.loops), len(me.polygons)
    normals = 4 * nl if compat.has_custom_normals(me) else 0
    return 12 * nv + 8 * ne + 8 * nl + 8 * nf + nf + normals


def _empty_mesh():
    me = bpy.data.meshes.get(EMPTY_NAME)
    if me is None or me.library is not None or len(me.vertices):
        me = bpy.data.meshes.new(EMPTY_NAME)
    return me


def detach_for_save(view_proxies):
    """Points each non-empty viewport proxy at one empty mesh for the write; its limit mesh then
    has no user and is not saved (the proxies are evaluated again at the next redraw)."""
    _detached.clear()
    empty = None
    for p in view_proxies:
        if p is None or p.library is not None or p.data is None or not len(p.data.vertices):
            continue
        empty = empty or _empty_mesh()
        _detached.append((p.name, p.data.name))
        p.data = empty


def reattach_after_save():
    """Gives the viewport proxies their meshes back; returns whether any was swapped (then their
    next update is the swap's echo)."""
    swapped = False
    for pname, mname in _detached:
        p, me = bpy.data.objects.get(pname), bpy.data.meshes.get(mname)
        if p is None or me is None:
            continue
        p.data = me
        swapped = True
    _detached.clear()
    me = bpy.data.meshes.get(EMPTY_NAME)
    if me is not None and me.users == 0 and swapped:
        bpy.data.meshes.remove(me)
    return swapped
