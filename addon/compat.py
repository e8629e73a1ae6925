"""Every Blender 3.x / 4.x API difference used by the add-on lives here.

Tested headless on Blender 3.4.1 (Debian), 4.5 LTS and 5.0 (PyPI `bpy` wheels).
"""
import bpy

VERSION = bpy.app.version


# ---- node groups ------------------------------------------------------------------------------

def new_group_socket(group, name, in_out, socket_type):
    """Group interface socket: `interface.new_socket` (4.0+) vs `inputs/outputs.new` (3.x)."""
    if hasattr(group, "interface"):
        return group.interface.new_socket(name=name, in_out=in_out, socket_type=socket_type)
    sockets = group.inputs if in_out == 'INPUT' else group.outputs
    return sockets.new(socket_type, name)


def switch_geometry_sockets(node):
    """(switch, false, true, output) of a Geometry Switch node. 3.x: one pair of sockets per
    type, the non-field boolean 'Switch' is the enabled one; 4.1+: a single typed set."""
    node.input_type = 'GEOMETRY'
    switch = [s for s in node.inputs if s.type == 'BOOLEAN' and s.enabled][0]
    false_in, true_in = [s for s in node.inputs if s.type == 'GEOMETRY'][:2]
    out = [s for s in node.outputs if s.type == 'GEOMETRY'][0]
    return switch, false_in, true_in, out


# ---- meshes -----------------------------------------------------------------------------------

# Bulk arrays through their attributes where Blender stores them as attributes (positions 3.5+,
# corner vertices/edges and edge vertices 3.6+, face materials 4.0+, edge selection 4.0+): one
# copy, where `vertices.foreach_set("co")`, `loops.foreach_get("vertex_index")` and the other
# element properties walk every element (measured on 4.5 and 5.0, 131k vertices / faces:
# positions 17 ms -> 0.1 ms, corner vertices 26-36 ms -> 0.2 ms, material 11-25 ms -> 0.2 ms).
# Not for a mesh evaluated from an edit mesh: its attribute API reads the edit
# BMesh's layers (tap.py), so the element properties are used there.

def _array_attr(mesh, name, domain, data_type, n):
    """The mesh's own attribute `name` with n elements, or None (absent, other layout, or an
    edit-mode mesh whose attributes are the BMesh's)."""
    if getattr(mesh, "is_editmode", False):
        return None
    a = mesh.attributes.get(name)
    if a is None or a.domain != domain or a.data_type != data_type or len(a.data) != n:
        return None
    return a


# array -> (attribute, domain, data type, its foreach property, element collection, element
#           property, the value when 4.0+ has no such attribute (None: read the elements))
_ARRAYS = {
    "positions": ("position", 'POINT', 'FLOAT_VECTOR', "vector", "vertices", "co", None),
    "corner_verts": (".corner_vert", 'CORNER', 'INT', "value", "loops", "vertex_index", None),
    "corner_edges": (".corner_edge", 'CORNER', 'INT', "value", "loops", "edge_index", None),
    "edge_verts": (".edge_verts", 'EDGE', 'INT32_2D', "value", "edges", "vertices", None),
    "material_index": ("material_index", 'FACE', 'INT', "value", "polygons", "material_index", 0),
    "edge_select": (".select_edge", 'EDGE', 'BOOLEAN', "value", "edges", "select", False),
}


def _bulk(mesh, spec, elems, eprop, array, write, absent=None):
    name, domain, dtype, prop = spec
    a = _array_attr(mesh, name, domain, dtype, len(elems))
    if a is not None:
        (a.data.foreach_set if write else a.data.foreach_get)(prop, array)
    elif (not write and absent is not None and VERSION >= (4, 0, 0)
          and not getattr(mesh, "is_editmode", False)):
        array[:] = absent
    else:
        (elems.foreach_set if write else elems.foreach_get)(eprop, array)


def get_array(mesh, what, out):
    """One of _ARRAYS into `out` (flat numpy array of the element property's layout)."""
    name, domain, dtype, prop, coll, eprop, absent = _ARRAYS[what]
    _bulk(mesh, (name, domain, dtype, prop), getattr(mesh, coll), eprop, out, False, absent)


def set_array(mesh, what, values):
    name, domain, dtype, prop, coll, eprop, _ = _ARRAYS[what]
    _bulk(mesh, (name, domain, dtype, prop), getattr(mesh, coll), eprop, values, True)


def get_uv(mesh, layer, out):
    """A UV map's per-corner values (flat, 2 per corner): its FLOAT2 corner attribute (3.5+)."""
    _bulk(mesh, (layer.name, 'CORNER', 'FLOAT2', "vector"), layer.data, "uv", out, False)


def set_uv(mesh, layer, values):
    _bulk(mesh, (layer.name, 'CORNER', 'FLOAT2', "vector"), layer.data, "uv", values, True)


def set_edges(mesh, edge_verts, corner_edges):
    """Edges given (flat arrays) to a mesh without edges, where edges are attributes (4.0+):
    returns False if not, and the caller lets Blender compute them (`update(calc_edges=True)`), which is 15 ms per 131k faces
    where writing them is 0.5 ms (5.0); on 3.x writing them element by element costs more."""
    if VERSION < (4, 0, 0) or len(mesh.edges):
        return False
    mesh.edges.add(len(edge_verts) // 2)
    ev = _array_attr(mesh, ".edge_verts", 'EDGE', 'INT32_2D', len(mesh.edges))
    ce = _array_attr(mesh, ".corner_edge", 'CORNER', 'INT', len(mesh.loops))
    if ev is None or ce is None:  # edges added but not writable: never leave them unset
        raise RuntimeError("mesh edges are not attributes in Blender %d.%d" % VERSION[:2])
    ev.data.foreach_set("value", edge_verts)
    ce.data.foreach_set("value", corner_edges)
    return True


def set_material_index(mesh, values):
    if VERSION >= (4, 0, 0):
        a = mesh.attributes.get("material_index")
        if a is None or a.domain != 'FACE' or a.data_type != 'INT':
            if a is not None:
                mesh.attributes.remove(a)
            a = mesh.attributes.new("material_index", 'INT', 'FACE')
        a.data.foreach_set("value", values)
    else:
        mesh.polygons.foreach_set("material_index", values)


def set_all_smooth(mesh):
    """Smooth shading on every face: 4.0+ no `sharp_face` attribute (its absence means smooth)."""
    if VERSION >= (4, 0, 0):
        a = mesh.attributes.get("sharp_face")
        if a is not None:
            mesh.attributes.remove(a)
    else:
        import numpy as np
        mesh.polygons.foreach_set("use_smooth", np.ones(len(mesh.polygons), bool))


def set_face_loops(mesh, loop_start, loop_total):
    """Polygon corner ranges: `loop_total` is writable (and required) in 3.x only."""
    mesh.polygons.foreach_set("loop_start", loop_start)
    if VERSION < (4, 0, 0):
        mesh.polygons.foreach_set("loop_total", loop_total)


# 4.5+: custom normals can be "free" normals, the float vectors themselves in the
# `custom_normal` attribute on the point or corner domain, shown and kept as they are. Writing
# them is one foreach_set; the encoded custom normals of `normals_split_custom_set*` (and of
# every version before) cost a loop-normal-space pass per write (measured on a 40k-vertex
# grid: 0.07-0.10 s encoded, 0.0004 s free).
FREE_NORMALS = VERSION >= (4, 5, 0)


def _set_free_normals(mesh, normals, domain):
    a = mesh.attributes.get("custom_normal")
    if a is not None and (a.data_type != 'FLOAT_VECTOR' or a.domain != domain):
        mesh.attributes.remove(a)
        a = None
    if a is None:
        a = mesh.attributes.new("custom_normal", 'FLOAT_VECTOR', domain)
    a.data.foreach_set("vector", normals.reshape(-1))
    mesh.update()


def set_vertex_normals(mesh, normals):
    """Custom normals from per-vertex unit normals (numpy float32 (N, 3)), smooth shading:
    free point normals on 4.5+, else encoded split normals; < 4.1 needs `use_auto_smooth` for
    custom normals to be used (4.1 removed it)."""
    if FREE_NORMALS:
        return _set_free_normals(mesh, normals, 'POINT')
    if hasattr(mesh, "use_auto_smooth"):
        mesh.use_auto_smooth = True
    mesh.normals_split_custom_set_from_vertices(normals)


def set_corner_normals(mesh, normals):
    """Custom normals per face corner (loop order), smooth shading: each side of a crease
    keeps its own exact normal. Free corner normals on 4.5+, else encoded, as above."""
    if FREE_NORMALS:
        return _set_free_normals(mesh, normals, 'CORNER')
    if hasattr(mesh, "use_auto_smooth"):
        mesh.use_auto_smooth = True
    mesh.normals_split_custom_set(normals)


def use_plain_normals(mesh):
    """Blender's own smooth vertex normals (no custom normals): < 4.1 turns auto smooth off
    (custom normals are then ignored); 4.1+ drops a `custom_normal` attribute if there is one
    (none after `clear_geometry`)."""
    if hasattr(mesh, "use_auto_smooth"):
        mesh.use_auto_smooth = False
    elif mesh.attributes.get("custom_normal") is not None:
        mesh.attributes.remove(mesh.attributes["custom_normal"])


def corner_normals(mesh):
    """Per-corner (loop) normals as a flat float list: `calc_normals_split` + loops (< 4.1)
    vs `corner_normals` (4.1+)."""
    import numpy as np
    n = len(mesh.loops)
    out = np.empty(3 * n, np.float32)
    if hasattr(mesh, "corner_normals"):
        mesh.corner_normals.foreach_get("vector", out)
    else:
        mesh.calc_normals_split()
        mesh.loops.foreach_get("normal", out)
    return out.reshape(n, 3)


def edge_creases(mesh):
    """Edge creases in [0, 1] as float64, or None if the mesh has none: the `crease_edge`
    attribute (4.0+) vs `MeshEdge.crease` (3.x, zeros when unset)."""
    import numpy as np
    n = len(mesh.edges)
    a = mesh.attributes.get("crease_edge") if VERSION >= (4, 0, 0) else None
    out = np.empty(n, np.float32)
    if a is not None and a.domain == 'EDGE' and a.data_type == 'FLOAT' and len(a.data) == n:
        a.data.foreach_get("value", out)
    elif VERSION < (4, 0, 0) and n:
        mesh.edges.foreach_get("crease", out)
        if not out.any():
            return None
    else:
        return None
    return out.astype(np.float64)


def vertex_creases(mesh):
    """Vertex creases in [0, 1] as float64, or None: the `crease_vert` attribute (4.0+) vs the
    `Mesh.vertex_creases` layer (3.x)."""
    import numpy as np
    n = len(mesh.vertices)
    out = np.empty(n, np.float32)
    if VERSION >= (4, 0, 0):
        a = mesh.attributes.get("crease_vert")
        if a is None or a.domain != 'POINT' or a.data_type != 'FLOAT' or len(a.data) != n:
            return None
        a.data.foreach_get("value", out)
    else:
        layers = getattr(mesh, "vertex_creases", None)
        if not layers or len(layers[0].data) != n:
            return None
        layers[0].data.foreach_get("value", out)
    return out.astype(np.float64)


def set_edge_creases(mesh, values):
    """Writes edge creases (float array, one per edge): attribute (4.0+) / MeshEdge.crease."""
    if VERSION >= (4, 0, 0):
        a = mesh.attributes.get("crease_edge") or mesh.attributes.new("crease_edge", 'FLOAT',
                                                                      'EDGE')
        a.data.foreach_set("value", values)
    else:
        mesh.edges.foreach_set("crease", values)


def set_vertex_creases(mesh, values):
    if VERSION >= (4, 0, 0):
        a = mesh.attributes.get("crease_vert") or mesh.attributes.new("crease_vert", 'FLOAT',
                                                                      'POINT')
        a.data.foreach_set("value", values)
    else:
        if not mesh.vertex_creases:  # 3.x: the layer can only be made through BMesh
            import bmesh
            bm = bmesh.new()
            bm.from_mesh(mesh)
            bm.verts.layers.crease.verify()
            bm.to_mesh(mesh)
            bm.free()
        mesh.vertex_creases[0].data.foreach_set("value", values)


def drop_custom_normals(mesh):
    """Removes custom normals where they are an attribute (4.4+: "custom_normal"); 3.x keeps
    them (removing them needs an operator). Returns whether they went."""
    a = mesh.attributes.get("custom_normal")
    if a is None:
        return False
    mesh.attributes.remove(a)
    return True


def has_custom_normals(mesh):
    return bool(mesh.has_custom_normals)


# ---- drawing ----------------------------------------------------------------------------------

_SHADERS_3X = {"POLYLINE_SMOOTH_COLOR": "3D_POLYLINE_SMOOTH_COLOR",
               "SMOOTH_COLOR": "3D_SMOOTH_COLOR",
               "UNIFORM_COLOR_2D": "2D_UNIFORM_COLOR",
               "SMOOTH_COLOR_2D": "2D_SMOOTH_COLOR",
               "FLAT_COLOR": "3D_FLAT_COLOR"}
_SHADERS_4X = {"POLYLINE_SMOOTH_COLOR": "POLYLINE_SMOOTH_COLOR",
               "SMOOTH_COLOR": "SMOOTH_COLOR",
               "UNIFORM_COLOR_2D": "UNIFORM_COLOR",
               "SMOOTH_COLOR_2D": "SMOOTH_COLOR",
               "FLAT_COLOR": "FLAT_COLOR"}


def builtin_shader(name):
    """Built-in shader names lost their 2D_/3D_ prefixes in 4.0."""
    import gpu
    table = _SHADERS_4X if VERSION >= (4, 0, 0) else _SHADERS_3X
    return gpu.shader.from_builtin(table[name])


def blf_size(font_id, size):
    """blf.size lost its dpi argument in 4.0."""
    import blf
    if VERSION >= (4, 0, 0):
        blf.size(font_id, size)
    else:
        blf.size(font_id, size, 72)


# ---- context ----------------------------------------------------------------------------------

def has_evaluated_geometry():
    """`Object.evaluated_geometry()`: the evaluated GeometrySet with its instance references,
    read per object instead of walking `depsgraph.object_instances`. Used from 5.0: on 4.3-4.5
    each call on a geometry holding instances leaks one 16-byte block (measured on 4.5.15:
    "Not freed memory blocks: 50" after 50 calls, none on 5.2 and 5.3), and the tap is such a
    geometry, read on every update."""
    return hasattr(bpy.types.Object, "evaluated_geometry") and bpy.app.version >= (5, 0, 0)



def set_active_color(me, name):
    """Makes colour attribute `name` the one Solid shading's Attribute colour shows (3.2+:
    color_attributes.active_color; 4.0+ also active_color_name)."""
    ca = getattr(me, "color_attributes", None)
    a = ca.get(name) if ca is not None else None
    if a is None:
        return
    if hasattr(ca, "active_color_name"):
        ca.active_color_name = name
    else:
        ca.active_color = a
    if hasattr(ca, "render_color_index"):
        ca.render_color_index = ca.active_color_index
