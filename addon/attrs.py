"""UV maps and attributes carried from the cage to the limit mesh.

* UV maps: each UV map of the cage (as the stack above hands it over, tap.py) is a face-varying
  channel of the plan. The corners of a vertex whose UVs are within 1e-4 share one value, as
  Blender's Subdivision Surface connects them; where they differ more the edge is a seam. Interpolated with the UV Smooth setting
  (Subdivision Surface's names and default, OpenSubdiv's FVarLinearInterpolation modes), with
  the intervals and creases of the surface, to their exact limit; written as UV maps of the
  same names, in the same order, the active and the render-active one kept.
* Point attributes (float, 2-D and 3-D vectors, colours): interpolated by the positions' rules
  through the same plan (ccn_plan_evaluate_vertex_data: their exact limit).
* Corner attributes (float, 2-D and 3-D vectors, colours; e.g. vertex colours painted or
  imported per face corner): interpolated bilinearly inside each cage face (a face-varying
  channel with one value per cage corner and linear interpolation everywhere, OpenSubdiv's
  FVAR_LINEAR_ALL), which is what Subdivision Surface does with corner data other than UV maps;
  byte colours in their stored (sRGB) values, as Blender interpolates them. The channel's
  topology does not depend on the values, so painting re-evaluates it without a new plan.
* Face attributes (any type): copied from the cage face each limit face lies on (face_origin).
* Edge attributes (any type, e.g. 4.x's `bevel_weight_edge`) and UV seams: each limit edge that
  lies on a cage edge gets that edge's value, the edges inside cage faces none (0 / False), as
  on Subdivision Surface's result (corner_edge_origin).
Not carried: point and corner attributes of integer or boolean type, `sharp_edge` (the limit's
normals are set by Normals), Blender's internal layers (names starting with "."), position, the tap
marker, creases, `sharp_face` (the limit is shaded smooth, its normals set by Normals) and
`material_index` (proxies.py copies it). UVs and attributes do not depend on positions: a move
rewrites neither. All bulk data goes through foreach_get / foreach_set and numpy.
"""
import hashlib

import numpy as np

from . import compat

KEY_PROP = "ccnurbs_attr_key"     # on the proxy mesh: the key of the UVs / attributes written
NAMES_PROP = "ccnurbs_attr_names"  # on the proxy mesh: the attributes this module wrote
SEAM_PROP = "ccnurbs_seams"        # on the proxy mesh: UV seams were written
TAP_ATTR, LIMIT_ATTR = "ccn_co", "ccn_limit"
SKIP = {"position", TAP_ATTR, LIMIT_ATTR, "crease_vert", "crease_edge", "sharp_face",
        "material_index", "knot_interval", "custom_normal", "sharp_edge"}
# data type -> (foreach property, components, numpy type)
TYPES = {'FLOAT': ('value', 1, np.float32), 'FLOAT2': ('vector', 2, np.float32),
         'FLOAT_VECTOR': ('vector', 3, np.float32), 'FLOAT_COLOR': ('color', 4, np.float32),
         'BYTE_COLOR': ('color', 4, np.float32), 'INT': ('value', 1, np.int32),
         'INT8': ('value', 1, np.int32), 'BOOLEAN': ('value', 1, bool),
         'INT32_2D': ('value', 2, np.int32), 'QUATERNION': ('value', 4, np.float32),
         'FLOAT4X4': ('value', 16, np.float32)}
POINT_TYPES = ('FLOAT', 'FLOAT2', 'FLOAT_VECTOR', 'FLOAT_COLOR', 'BYTE_COLOR')  # interpolated
MAX_WIDTH = 64  # CCN_FVAR_MAX_WIDTH: per-vertex data is evaluated in groups of this many


class Extras:
    """What a cage carries besides its geometry: UV maps, point and face attributes."""
    __slots__ = ("uv_names", "uv_active", "uv_render", "uvs", "point", "face", "corner",
                 "edge", "seam")


def _prop(data_type, domain):
    """The foreach property of an attribute's values: byte colours on corners in their stored
    sRGB values (Blender interpolates those), the others as TYPES says."""
    return 'color_srgb' if data_type == 'BYTE_COLOR' and domain == 'CORNER' else TYPES[data_type][0]


def _read_attr(att, n):
    _, k, dt = TYPES[att.data_type]
    prop = _prop(att.data_type, att.domain)
    a = np.empty(n * k, dt)
    att.data.foreach_get(prop, a)
    return a.reshape(n, k)


def read(me, perm=None):
    """UV maps (per face corner, in the cage's corner order: `perm` reorders Blender's loops),
    point and face attributes of a mesh."""
    x = Extras()
    nl, nv, nf = len(me.loops), len(me.vertices), len(me.polygons)
    layers = me.uv_layers
    x.uv_names = [u.name for u in layers]
    x.uv_active = layers.active_index if len(layers) else -1
    x.uv_render = next((i for i, u in enumerate(layers) if u.active_render), -1)
    x.uvs = []
    for u in layers:
        a = np.empty(2 * nl, np.float32)
        compat.get_uv(me, u, a)
        a = a.reshape(nl, 2)
        x.uvs.append(a[perm] if perm is not None else a)
    x.point, x.face, x.corner, x.edge = [], [], [], []
    ne = len(me.edges)
    seam = np.zeros(ne, bool)
    if ne:
        me.edges.foreach_get("use_seam", seam)
    x.seam = seam if seam.any() else None
    uv_names = set(x.uv_names)
    for att in me.attributes:
        name = att.name
        if name.startswith(".") or name in SKIP or name in uv_names or att.data_type not in TYPES:
            continue
        if att.domain == 'POINT' and att.data_type in POINT_TYPES and len(att.data) == nv:
            x.point.append((name, att.data_type, _read_attr(att, nv)))
        elif att.domain == 'FACE' and len(att.data) == nf:
            x.face.append((name, att.data_type, _read_attr(att, nf)))
        elif att.domain == 'EDGE' and len(att.data) == ne:
            x.edge.append((name, att.data_type, _read_attr(att, ne)))
        elif att.domain == 'CORNER' and att.data_type in POINT_TYPES and len(att.data) == nl:
            a = _read_attr(att, nl)
            x.corner.append((name, att.data_type, a[perm] if perm is not None else a))
    return x


def _hash(parts):
    h = hashlib.blake2b(digest_size=16)
    for p in parts:
        h.update(p if isinstance(p, bytes) else np.ascontiguousarray(p).tobytes())
        h.update(b"|")
    return h.hexdigest()


UV_CONNECT_LIMIT = 1e-4  # Blender's STD_UV_CONNECT_LIMIT: UVs of one vertex this close are one


def _weld_close(uniq, inv):
    """The distinct (vertex, u, v) rows of a UV map, with the rows of one vertex whose UVs lie
    within UV_CONNECT_LIMIT (in u and in v) of a group's first row merged into it, as Blender's
    Subdivision Surface connects them (Unwrap leaves UVs one float step apart at shared
    vertices; kept apart they were a seam). Greedy in row order, as Blender's UV vertex map."""
    verts = uniq[:, 0]
    starts = np.flatnonzero(np.r_[True, verts[1:] != verts[:-1]])
    counts = np.diff(np.r_[starts, len(verts)])
    multi = starts[counts > 1]
    if not len(multi):
        return uniq, inv
    uv = uniq[:, 1:].astype(np.uint32).view(np.float32)
    target = np.arange(len(uniq))
    for s0, c in zip(multi, counts[counts > 1]):
        reps = []
        for r in range(s0, s0 + c):
            for q in reps:
                if abs(uv[r, 0] - uv[q, 0]) < UV_CONNECT_LIMIT and abs(uv[r, 1] - uv[q, 1]) < UV_CONNECT_LIMIT:
                    target[r] = q
                    break
            else:
                reps.append(r)
    if (target == np.arange(len(uniq))).all():
        return uniq, inv
    keep = np.flatnonzero(target == np.arange(len(uniq)))
    new_index = np.full(len(uniq), -1, np.int64)
    new_index[keep] = np.arange(len(keep))
    return uniq[keep], new_index[target[inv]]


def uv_channels(ost, x, face_verts):
    """Each UV map as (values (N, 2) f64, value index per face corner), and the key of their
    topology (seams): cached in the object's state `ost` (state.py) while the UVs are
    unchanged."""
    if x is None or not x.uvs:
        return [], ""
    data = _hash([face_verts] + x.uvs + [repr(x.uv_names).encode()])
    cached = ost.uv
    if cached is not None and cached[0] == data:
        return cached[1]
    chans = []
    for a in x.uvs:
        key = np.empty((len(a), 3), np.int64)
        key[:, 0] = face_verts
        key[:, 1:] = a.view(np.uint32)
        uniq, inv = np.unique(key, axis=0, return_inverse=True)
        inv = np.asarray(inv, np.int64).ravel()
        uniq, inv = _weld_close(uniq, inv)
        values = uniq[:, 1:].astype(np.uint32).view(np.float32).astype(np.float64)
        chans.append((np.ascontiguousarray(values), np.asarray(inv, np.int32).ravel()))
    res = (chans, _hash([repr(x.uv_names).encode()] + [c[1] for c in chans]))
    ost.uv = (data, res)
    return res


def corner_layout(x):
    """Key of the corner attributes' channels (their names, types and corner count): a plan has
    one channel per corner attribute, so it is rebuilt when the layout changes, not when values
    do."""
    if x is None or not x.corner:
        return ""
    return "|corners:" + repr([(n, t, len(a)) for n, t, a in x.corner])


def add_corner_channels(plan, x):
    """The plan's channel index of each corner attribute: one value per cage corner, bilinear."""
    if x is None:
        return []
    return [plan.add_fvar(a.astype(np.float64), np.arange(len(a), dtype=np.int32), "NONE")
            for _, _, a in x.corner]


def data_key(x, uv_smooth):
    """Key of everything written by `write` besides topology: UV values, attribute data."""
    if x is None:
        return "-"
    parts = [repr((x.uv_names, x.uv_active, x.uv_render, uv_smooth,
                   [(n, t) for n, t, _ in x.point], [(n, t) for n, t, _ in x.face],
                   [(n, t) for n, t, _ in x.corner], [(n, t) for n, t, _ in x.edge],
                   x.seam is not None)).encode()]
    parts += x.uvs + [a for _, _, a in x.point] + [a for _, _, a in x.face]
    parts += [a for _, _, a in x.corner] + [a for _, _, a in x.edge]
    parts += [x.seam] if x.seam is not None else []
    return _hash(parts)


def add_channels(plan, chans, uv_smooth):
    """The plan's channel index of each UV map."""
    return [plan.add_fvar(values, idx, uv_smooth) for values, idx in chans]


def attribute(me, name, data_type, domain):
    """The attribute of that name, type and domain on me, made (or made again) if needed."""
    a = me.attributes.get(name)
    if a is not None and (a.data_type != data_type or a.domain != domain):
        me.attributes.remove(a)
        a = None
    return a if a is not None else me.attributes.new(name, data_type, domain)


def needs_edge_origin(x):
    return x is not None and (bool(x.edge) or x.seam is not None)


def edge_origin(me, corner_edge_origin, cage_loop_edges):
    """Per edge of the limit mesh `me`: the cage edge it lies on, -1 inside a cage face (from the
    plan's corner_edge_origin: the cage corner whose edge each output corner's edge lies on)."""
    origin = np.asarray(corner_edge_origin).ravel()
    loop_edge = np.empty(len(me.loops), np.int32)
    compat.get_array(me, "corner_edges", loop_edge)
    out = np.full(len(me.edges), -1, np.int64)
    on = origin >= 0
    out[loop_edge[on]] = np.asarray(cage_loop_edges)[origin[on]]
    return out


def write(me, x, plan, chans, channel_ids, face_origin, corner_ids=None, edge_from=None):
    """UV maps, point, corner, face and edge attributes (and UV seams) of the limit mesh `me`
    (the proxy, its topology just written or unchanged), with the plan's channels; edge_from:
    edge_origin() of me, when needs_edge_origin(x)."""
    names = x.uv_names if x is not None else []
    if [u.name for u in me.uv_layers] != names:
        while len(me.uv_layers):
            me.uv_layers.remove(me.uv_layers[0])
        for n in names:
            me.uv_layers.new(name=n)
    layers = me.uv_layers
    for i, (cid, (values, _)) in enumerate(zip(channel_ids, chans)):
        out, fv = plan.evaluate_fvar(cid, values)
        compat.set_uv(me, layers[i], out[fv.ravel()].astype(np.float32).ravel())
    if x is not None and x.uv_active >= 0 and len(layers):
        layers.active_index = x.uv_active
    if x is not None and x.uv_render >= 0 and len(layers):
        layers[x.uv_render].active_render = True
    written = []
    if x is not None and x.point:
        data = np.concatenate([a.astype(np.float64) for _, _, a in x.point], axis=1)
        out = np.concatenate([plan.evaluate_vertex_data(data[:, c:c + MAX_WIDTH])
                              for c in range(0, data.shape[1], MAX_WIDTH)], axis=1)
        col = 0
        for name, t, a in x.point:
            k = a.shape[1]
            vals = out[:, col:col + k]
            col += k
            if t == 'BYTE_COLOR':
                vals = np.clip(vals, 0.0, 1.0)
            att = attribute(me, name, t, 'POINT')
            att.data.foreach_set(TYPES[t][0], vals.astype(np.float32).ravel())
            written.append(name)
    for (name, t, a), cid in zip(x.corner if x is not None else [], corner_ids or []):
        out, fv = plan.evaluate_fvar(cid, a.astype(np.float64))
        vals = out[fv.ravel()]
        if t == 'BYTE_COLOR':
            vals = np.clip(vals, 0.0, 1.0)
        attribute(me, name, t, 'CORNER').data.foreach_set(_prop(t, 'CORNER'),
                                                           vals.astype(np.float32).ravel())
        written.append(name)
    if x is not None and x.face:
        origin = np.clip(face_origin, 0, len(x.face[0][2]) - 1)
        for name, t, a in x.face:
            attribute(me, name, t, 'FACE').data.foreach_set(TYPES[t][0], a[origin].ravel())
            written.append(name)
    if needs_edge_origin(x) and edge_from is not None:
        on = edge_from >= 0
        for name, t, a in x.edge:
            vals = np.zeros((len(me.edges), a.shape[1]), a.dtype)
            vals[on] = a[edge_from[on]]
            attribute(me, name, t, 'EDGE').data.foreach_set(TYPES[t][0], vals.ravel())
            written.append(name)
    if x is not None and (x.seam is not None or me.get(SEAM_PROP)):
        seam = np.zeros(len(me.edges), bool)
        if x.seam is not None and edge_from is not None:
            seam[edge_from >= 0] = x.seam[edge_from[edge_from >= 0]]
        me.edges.foreach_set("use_seam", seam)
        me[SEAM_PROP] = bool(seam.any())
    for name in me.get(NAMES_PROP, []):  # written before, gone from the cage now
        a = me.attributes.get(name)
        if name not in written and a is not None:
            me.attributes.remove(a)
    me[NAMES_PROP] = written
