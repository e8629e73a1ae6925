"""The CCNURBS modifier: a Geometry Nodes modifier whose group shows a proxy mesh and hands its
own input to Python.

Python cannot define modifier types, so `object.ccnurbs_add` adds a Nodes modifier named
"CCNURBS" with a per-cage group:

    Group Input ─ Separate Components ─ Mesh ─┬─ Store "ccn_co" ─ Geometry to Instance
                                              │    ─ Scale Instances (0) ─────────────────── Join → Output
                                              │                                              ↑
    Object Info(viewport proxy) ┐             └──────────────────────────────┐ (no limit yet)│
    Object Info(render proxy) ──┴ Switch(Is Viewport; own proxy, else the other) ┴ Switch ───┤
                                      other components (curves, points, instances) ──────────┘

* **The input tap.** The group's input is the cage as evaluated by every modifier above CCNURBS
  (Mirror, Armature, shape keys, Lattice, Array, Solidify, Displace, Geometry Nodes...), with its
  attributes (`knot_interval`, creases) propagated by Blender. The group outputs that mesh as one
  instance scaled to zero (it draws and renders as nothing; the instance reference keeps the
  true geometry), marked by the point attribute "ccn_co". Python (tap.py) reads it from the
  evaluated object after each evaluation: no second evaluation of the stack, no copy of the
  modifiers. Apply drops instances, so the applied mesh is the limit only. The input's own
  instances are dropped (the tap is the only instance); curves, points and volumes pass.
* **The output.** The viewport proxy (`levels`) in the viewport; in a render the render proxy
  (`render_levels`), written per frame during the render (handlers.py); each falls back to the
  other when empty (files keep at most the render mesh); the input mesh itself while there is
  no valid limit (e.g. a file opened without the add-on), and at Levels 0 (a proxy of one point
  and no face), as Subdivision Surface shows its input at Levels 0.

Rejected designs (measured or tried headless on 3.4, 4.5 and 5.0; README "Design notes"):
reading `obj.data` (ignores the stack); toggling the modifier off to evaluate the stack (a second
full evaluation and an update loop per change); a hidden object with copies of the modifiers
above (evaluates the stack twice and cannot follow drivers or modifier edits reliably); a
fingerprint switch that passes the input through while the proxy is stale (no exact hash of a
mesh in Geometry Nodes 3.4; a collision shows a stale surface).

Ownership: a group records its cage (`group["ccnurbs_owner"]`) and is used by that cage only; the
proxies are the objects its Object Info nodes name (no pointer on the cage, so deleting a cage
leaves nothing holding them). hygiene.py gives duplicates and copied modifiers their own group
and proxies and deletes whatever no live cage uses.
"""
import bpy

from . import compat

MOD_NAME = "CCNURBS"
GROUP_TAG = "ccnurbs_group"
OWNER_PROP = "ccnurbs_owner"
GROUP_VERSION = 2  # the GROUP_TAG value; 2: a proxy without faces shows the input (Levels 0)
TAP_ATTR = "ccn_co"
VIEW_NODE, RENDER_NODE = "Viewport Proxy", "Render Proxy"
FALLBACK_NODE, PROXY_SWITCH = "Limit or Cage", "Proxy"
VG_NODE, VG_PREFIX, VG_PROP = "VG ", "ccn_vg_", "ccnurbs_vertex_groups"  # set_vertex_groups
PROXY_PREFIX = {'VIEW_PROXY': ".CCNURBS view ", 'RENDER_PROXY': ".CCNURBS render "}


def is_group(group):
    return group is not None and bool(group.get(GROUP_TAG))


def get_modifier(obj):
    """The object's CCNURBS modifier: a Nodes modifier using one of our groups (any name), or
    the one named CCNURBS."""
    if obj is None or obj.type != 'MESH':
        return None
    for mod in obj.modifiers:
        if mod.type == 'NODES' and is_group(mod.node_group):
            return mod
    mod = obj.modifiers.get(MOD_NAME)
    return mod if mod is not None and mod.type == 'NODES' else None


DEFORM_ONLY = {'ARMATURE', 'CAST', 'CURVE', 'DISPLACE', 'HOOK', 'LAPLACIANDEFORM', 'LATTICE',
               'MESH_DEFORM', 'SHRINKWRAP', 'SIMPLE_DEFORM', 'SMOOTH', 'CORRECTIVE_SMOOTH',
               'LAPLACIANSMOOTH', 'SURFACE_DEFORM', 'WARP', 'WAVE'}


def _enabled_around(obj):
    """(above, below): the modifiers enabled in the viewport before and after CCNURBS (all of
    them above when the object has no CCNURBS)."""
    ours, above, below, past = get_modifier(obj), [], [], False
    for m in obj.modifiers:
        if m == ours:
            past = True
        elif m.show_viewport:
            (below if past else above).append(m)
    return above, below


def stack_keeps_topology(obj):
    """Does every enabled modifier above CCNURBS only move vertices (so the cage the library
    sees has the object's own elements, in their order)?"""
    return all(m.type in DEFORM_ONLY for m in _enabled_around(obj)[0])


SUBDIVIDED_NOTE = ("\"%s\" above CCNURBS subdivides the cage first: this is the limit of the "
                   "subdivided cage (remove or disable it for the cage's own limit)")


def subdivisions_above(obj):
    """Names of the enabled Subdivision Surface / Multiresolution modifiers above CCNURBS: they
    subdivide the cage before CCNURBS sees it (an object that had Subsurf when CCNURBS was
    added), which the panel and the Add operator point out."""
    return [m.name for m in _enabled_around(obj)[0] if m.type in ('SUBSURF', 'MULTIRES')]


VGROUP_NOTE = ("\"%s\" below CCNURBS deforms by the vertex groups of its bones, which the limit "
               "mesh does not carry: move it above CCNURBS")


def _vertex_group_settings(m):
    """The vertex-group names a modifier's settings give (its STRING properties named
    *vertex_group*, Cloth's and Soft Body's pin groups), empty ones left out."""
    names = [getattr(m, p.identifier) for p in m.bl_rna.properties
             if p.type == 'STRING' and "vertex_group" in p.identifier and getattr(m, p.identifier, "")]
    settings = getattr(m, "settings", None)
    for prop in ("vertex_group_mass", "vertex_group_goal"):
        if settings is not None and getattr(settings, prop, ""):
            names.append(getattr(settings, prop))
    return names


def groups_needed_below(obj):
    """Names of the object's vertex groups that modifiers below CCNURBS name in their settings:
    the limit mesh carries these (set_vertex_groups)."""
    names = {n for m in _enabled_around(obj)[1] for n in _vertex_group_settings(m) if n in obj.vertex_groups}
    return sorted(names)


def vertex_groups_below(obj):
    """Names of the Armature modifiers below CCNURBS that deform by vertex groups: the bone
    groups are not carried to the limit mesh (only groups named in settings are)."""
    return [m.name for m in _enabled_around(obj)[1] if m.type == 'ARMATURE' and m.use_vertex_groups]


def is_cage(obj):
    return (obj is not None and obj.type == 'MESH' and obj.ccnurbs.role == 'CAGE'
            and get_modifier(obj) is not None)


def cages(objects=None):
    return [o for o in (bpy.data.objects if objects is None else objects) if is_cage(o)]


def group_proxies(group):
    """(viewport, render) proxy objects named by one of our groups."""
    view = render = None
    if group is None:
        return view, render
    for node in group.nodes:
        if node.bl_idname == 'GeometryNodeObjectInfo':
            if node.name == VIEW_NODE:
                view = node.inputs[0].default_value
            elif node.name == RENDER_NODE:
                render = node.inputs[0].default_value
    return view, render


def proxies(obj):
    mod = get_modifier(obj)
    return group_proxies(mod.node_group if mod is not None else None)


def proxy(obj, kind):
    view, render = proxies(obj)
    return view if kind == 'VIEW' else render


def proxy_name(role, owner_name):
    return PROXY_PREFIX[role] + owner_name


def new_proxy(owner_name, role):
    name = proxy_name(role, owner_name)
    me = bpy.data.meshes.new(name)
    p = bpy.data.objects.new(name, me)
    p.ccnurbs.role = role
    p.ccnurbs.owner_name = owner_name
    return p


def _link(links, a, b):
    links.new(a, b)


def _store_vector_sockets(node):
    node.data_type = 'FLOAT_VECTOR'
    node.domain = 'POINT'
    name = node.inputs["Name"]
    value = [s for s in node.inputs if s.type == 'VECTOR' and s.enabled][0]
    return name, value


def _first_nonempty(nodes, links, first, second, location):
    """Switch node output: `first` if it has points, else `second`."""
    x, y = location
    size = nodes.new('GeometryNodeAttributeDomainSize')
    size.location = (x - 340, y - 80)
    _link(links, first, size.inputs[0])
    full = nodes.new('ShaderNodeMath')
    full.operation = 'GREATER_THAN'
    full.inputs[1].default_value = 0.5
    full.location = (x - 170, y - 80)
    _link(links, size.outputs['Point Count'], full.inputs[0])
    sw = nodes.new('GeometryNodeSwitch')
    sw.location = (x, y)
    s, f_in, t_in, out = compat.switch_geometry_sockets(sw)
    _link(links, full.outputs[0], s)
    _link(links, second, f_in)
    _link(links, first, t_in)
    return out


def build_group(owner_name, view, render):
    group = bpy.data.node_groups.new("CCNURBS " + owner_name, 'GeometryNodeTree')
    group[GROUP_TAG] = GROUP_VERSION
    group[OWNER_PROP] = owner_name
    compat.new_group_socket(group, "Geometry", 'INPUT', 'NodeSocketGeometry')
    compat.new_group_socket(group, "Geometry", 'OUTPUT', 'NodeSocketGeometry')
    nodes, links = group.nodes, group.links
    gin = nodes.new('NodeGroupInput')
    gin.location = (-900, 0)
    gout = nodes.new('NodeGroupOutput')
    gout.location = (1100, 0)
    sep = nodes.new('GeometryNodeSeparateComponents')
    sep.name = sep.label = "Separate"
    sep.location = (-700, 0)
    _link(links, gin.outputs[0], sep.inputs[0])
    mesh_in = sep.outputs["Mesh"]
    # the tap: the input mesh as one instance scaled to zero (draws and renders as nothing; its
    # reference keeps true positions); "ccn_co" marks it (and keeps the positions once more)
    store = nodes.new('GeometryNodeStoreNamedAttribute')
    store.name = store.label = "Tap"
    store.location = (-450, -350)
    name_in, value_in = _store_vector_sockets(store)
    name_in.default_value = TAP_ATTR
    pos = nodes.new('GeometryNodeInputPosition')
    pos.location = (-650, -450)
    _link(links, mesh_in, store.inputs["Geometry"])
    _link(links, pos.outputs[0], value_in)
    inst = nodes.new('GeometryNodeGeometryToInstance')
    inst.location = (-250, -350)
    _link(links, store.outputs[0], inst.inputs[0])
    hide = nodes.new('GeometryNodeScaleInstances')
    hide.location = (-50, -350)
    _link(links, inst.outputs[0], hide.inputs["Instances"])
    hide.inputs["Scale"].default_value = (0.0, 0.0, 0.0)
    # the output: a proxy, or the input mesh while there is no limit
    infos = []
    for i, (name, ob) in enumerate(((VIEW_NODE, view), (RENDER_NODE, render))):
        info = nodes.new('GeometryNodeObjectInfo')
        info.name = info.label = name
        info.transform_space = 'ORIGINAL'
        info.inputs[0].default_value = ob
        info.location = (-450, 450 - 250 * i)
        infos.append(info)
    # each depsgraph shows its own proxy if it has points, else the other one (a file saved with
    # its render mesh but without the viewport one shows the render mesh in the viewport too)
    view_geo, render_geo = infos[0].outputs['Geometry'], infos[1].outputs['Geometry']
    view_or_render = _first_nonempty(nodes, links, view_geo, render_geo, (-80, 450))
    render_or_view = _first_nonempty(nodes, links, render_geo, view_geo, (-80, 150))
    isview = nodes.new('GeometryNodeIsViewport')
    isview.location = (100, 450)
    vsw = nodes.new('GeometryNodeSwitch')
    vsw.name = vsw.label = PROXY_SWITCH
    vsw.location = (300, 300)
    s, f_in, t_in, proxy_out = compat.switch_geometry_sockets(vsw)
    _link(links, isview.outputs[0], s)
    _link(links, render_or_view, f_in)
    _link(links, view_or_render, t_in)
    # a proxy without faces shows the input mesh: no limit yet (empty), or Levels 0 (one point,
    # proxies.show_cage; not empty, so the other proxy is not taken instead)
    size = nodes.new('GeometryNodeAttributeDomainSize')
    size.location = (500, 200)
    _link(links, proxy_out, size.inputs[0])
    nonempty = nodes.new('ShaderNodeMath')
    nonempty.operation = 'GREATER_THAN'
    nonempty.inputs[1].default_value = 0.5
    nonempty.location = (650, 200)
    _link(links, size.outputs['Face Count'], nonempty.inputs[0])
    fallback = nodes.new('GeometryNodeSwitch')
    fallback.name = fallback.label = FALLBACK_NODE
    fallback.location = (800, 50)
    s, cage_in, limit_in, out = compat.switch_geometry_sockets(fallback)
    _link(links, nonempty.outputs[0], s)
    _link(links, mesh_in, cage_in)
    _link(links, proxy_out, limit_in)
    join = nodes.new('GeometryNodeJoinGeometry')
    join.location = (950, 0)
    _link(links, out, join.inputs[0])
    for sock in sep.outputs:  # curves, points, volumes pass through (the input's instances do
        if sock.name not in ("Mesh", "Instances"):  # not: the tap is the only instance)
            _link(links, sock, join.inputs[0])
    _link(links, hide.outputs[0], join.inputs[0])
    _link(links, join.outputs[0], gout.inputs[0])
    return group


def _vg_node(nodes, kind, tag, location):
    node = nodes.new(kind)
    node.name = node.label = VG_NODE + tag
    node.location = location
    return node


def _float_store(nodes, name, tag, location):
    """A Store Named Attribute of float point values `name`: (node, its value socket)."""
    node = _vg_node(nodes, 'GeometryNodeStoreNamedAttribute', tag, location)
    node.data_type = 'FLOAT'
    node.domain = 'POINT'
    node.inputs["Name"].default_value = name
    return node, [s for s in node.inputs if s.type == 'VALUE' and s.enabled][0]


def _named_float(nodes, name, tag, location):
    node = _vg_node(nodes, 'GeometryNodeInputNamedAttribute', tag, location)
    node.data_type = 'FLOAT'
    node.inputs["Name"].default_value = name
    return [s for s in node.outputs if s.enabled and s.type == 'VALUE'][0]


def set_vertex_groups(group, names):
    """The vertex groups the limit mesh carries (those modifiers below CCNURBS use). On the
    tap side each group becomes the float attribute VG_PREFIX + name (vertex groups are no
    attributes to Python), interpolated like any point attribute (attrs.py) onto the proxy; on
    the output side each such attribute is stored back into the group of that name, which the
    proxies hold (names only: ensure_proxy_groups), and removed, so the result carries real
    vertex groups for the modifiers below. Returns False if the group predates these chains."""
    nodes, links = group.nodes, group.links
    tap, fallback = nodes.get("Tap"), nodes.get(FALLBACK_NODE)
    if tap is None or fallback is None or "Separate" not in nodes or PROXY_SWITCH not in nodes:
        return False
    for n in [n for n in nodes if n.name.startswith(VG_NODE)]:
        nodes.remove(n)  # their links go with them; the chain ends are relinked below
    _, _, limit_in, _ = compat.switch_geometry_sockets(fallback)
    mesh_src = nodes["Separate"].outputs["Mesh"]
    proxy_src = compat.switch_geometry_sockets(nodes[PROXY_SWITCH])[3]
    for k, name in enumerate(names):
        store, value = _float_store(nodes, VG_PREFIX + name, "in " + name, (-650, -700 - 150 * k))
        _link(links, _named_float(nodes, name, "read " + name, (-850, -750 - 150 * k)), value)
        _link(links, mesh_src, store.inputs["Geometry"])
        mesh_src = store.outputs[0]
        back, bvalue = _float_store(nodes, name, "out " + name, (550, -300 - 150 * k))
        _link(links, _named_float(nodes, VG_PREFIX + name, "limit " + name, (350, -350 - 150 * k)),
              bvalue)
        _link(links, proxy_src, back.inputs["Geometry"])
        drop = _vg_node(nodes, 'GeometryNodeRemoveAttribute', "drop " + name, (750, -300 - 150 * k))
        drop.inputs["Name"].default_value = VG_PREFIX + name
        _link(links, back.outputs[0], drop.inputs["Geometry"])
        proxy_src = drop.outputs[0]
    _link(links, mesh_src, tap.inputs["Geometry"])
    _link(links, proxy_src, limit_in)
    group[VG_PROP] = list(names)
    return True


def _node_group(obj):
    mod = get_modifier(obj)
    return mod.node_group if mod is not None else None


def carried_groups(obj):
    """The vertex groups the object's limit mesh carries (set_vertex_groups)."""
    group = _node_group(obj)
    return list(group.get(VG_PROP, [])) if group is not None else []


def ensure_proxy_groups(p, names):
    """Proxy p holds exactly the vertex groups `names` (names only, no weights)."""
    if p is None:
        return
    have = [g.name for g in p.vertex_groups]
    if have == list(names):
        return
    for g in [g for g in p.vertex_groups if g.name not in names]:
        p.vertex_groups.remove(g)
    for name in names:
        if name not in have:
            p.vertex_groups.new(name=name)


def carry_vertex_groups(obj):
    """Keeps the group's chains and the proxies' group names in step with the vertex groups
    that modifiers below CCNURBS use (a no-op while that set is unchanged); a group from
    before the chains is replaced by a fresh one. Returns True if anything changed."""
    group = _node_group(obj)
    if group is None:
        return False
    names = groups_needed_below(obj)
    if list(group.get(VG_PROP, [])) == names:
        return False
    if not set_vertex_groups(group, names):
        group = ensure(obj, fresh=True).node_group
        set_vertex_groups(group, names)
    for p in group_proxies(group):
        ensure_proxy_groups(p, names)
    return True


def owner_of(group):
    return group.get(OWNER_PROP, "") if group is not None else ""


def new_group_and_proxies(obj):
    """A fresh group and two fresh proxies for obj (duplicates, copied modifiers, new cages)."""
    view = new_proxy(obj.name_full, 'VIEW_PROXY')
    render = new_proxy(obj.name_full, 'RENDER_PROXY')
    return build_group(obj.name_full, view, render)


def ensure(obj, fresh=False):
    """Creates or repairs the modifier, its node group and the two proxies of a cage. fresh=True
    replaces a group that another object owns (a duplicate or a copied modifier)."""
    s = obj.ccnurbs
    if s.role != 'CAGE':
        s.role = 'CAGE'
    mod = get_modifier(obj)
    group = mod.node_group if mod is not None else None
    view, render = group_proxies(group)
    if (fresh or not is_group(group) or view is None or render is None
            or owner_of(group) != obj.name_full or group.get(GROUP_TAG) != GROUP_VERSION):
        group = new_group_and_proxies(obj)  # hygiene.collect() deletes the old one if unused
    created = mod is None
    if created:
        mod = obj.modifiers.new(MOD_NAME, 'NODES')
        mod.show_in_editmode = True
    if mod.node_group != group:
        mod.node_group = group  # before anything that may run the handlers (and hygiene)
    # a new CCNURBS goes where Blender puts any new modifier, last (before a modifier pinned
    # last, 4.2+), so that Mirror, Armature, shape keys... already on the object are above it
    # and count, as with Subdivision Surface
    return mod


def remove_proxy(p):
    if p is None or p.library is not None:
        return
    me = p.data
    bpy.data.objects.remove(p)
    if me is not None and me.users == 0 and me.library is None:
        bpy.data.meshes.remove(me)


def remove(obj):
    """Removes the modifier, its group and the proxies; keeps the cage and its intervals."""
    mod = get_modifier(obj)
    group = mod.node_group if mod is not None else None
    view, render = group_proxies(group)
    if mod is not None:
        obj.modifiers.remove(mod)
    if group is not None and group.users == 0 and is_group(group):
        bpy.data.node_groups.remove(group)
        for p in (view, render):
            if p is not None and p.users == 0:
                remove_proxy(p)
    obj.ccnurbs.role = 'NONE'
