"""The CCNURBS modifier: a Geometry Nodes modifier whose group reads hidden proxy objects.

Python cannot define modifier types, so `object.ccnurbs_add` adds a Nodes modifier named
"CCNURBS" with a per-cage group

    Object Info(viewport proxy) ─┐
    Object Info(render proxy)  ──┤ Switch(Is Viewport) ─┬──────────────────────┐
    Is Viewport ─────────────────┘                      └ Domain Size > 0 ─ Switch → Output
    Group Input (the cage) ─────────────────────────────────────────────────┘

(an empty proxy — no valid limit yet — shows the cage itself instead of nothing).

The proxies are mesh objects linked to no scene, written by the depsgraph handler (sync.py) at
`levels` (viewport proxy) and `render_levels` (render proxy). They are saved in the .blend, so a
file shows and renders its limit surface even where the add-on is not installed.
"""
import bpy

from . import compat

MOD_NAME = "CCNURBS"
GROUP_TAG = "ccnurbs_group"


def get_modifier(obj):
    mod = obj.modifiers.get(MOD_NAME) if obj is not None else None
    return mod if mod is not None and mod.type == 'NODES' else None


def is_cage(obj):
    return (obj is not None and obj.type == 'MESH' and obj.ccnurbs.role == 'CAGE'
            and get_modifier(obj) is not None)


def cages(objects=None):
    return [o for o in (bpy.data.objects if objects is None else objects) if is_cage(o)]


def _new_proxy(obj, role):
    name = (".CCNURBS view " if role == 'VIEW_PROXY' else ".CCNURBS render ") + obj.name
    me = bpy.data.meshes.new(name)
    proxy = bpy.data.objects.new(name, me)
    proxy.ccnurbs.role = role
    proxy.ccnurbs.owner_name = obj.name
    return proxy


def _group_proxies(group):
    """(viewport, render) objects referenced by one of our node groups."""
    view = render = None
    for node in group.nodes:
        if node.bl_idname == 'GeometryNodeObjectInfo':
            ob = node.inputs[0].default_value
            if node.name == "Viewport Proxy":
                view = ob
            elif node.name == "Render Proxy":
                render = ob
    return view, render


def _build_group(obj, view, render):
    group = bpy.data.node_groups.new("CCNURBS " + obj.name, 'GeometryNodeTree')
    group[GROUP_TAG] = 1
    compat.new_group_socket(group, "Geometry", 'INPUT', 'NodeSocketGeometry')
    compat.new_group_socket(group, "Geometry", 'OUTPUT', 'NodeSocketGeometry')
    nodes, links = group.nodes, group.links
    gin = nodes.new('NodeGroupInput')
    gin.location = (-600, 0)
    gout = nodes.new('NodeGroupOutput')
    gout.location = (300, 0)
    infos = []
    for i, (name, ob) in enumerate((("Viewport Proxy", view), ("Render Proxy", render))):
        info = nodes.new('GeometryNodeObjectInfo')
        info.name = info.label = name
        info.transform_space = 'ORIGINAL'
        info.inputs[0].default_value = ob
        info.location = (-300, 150 - 250 * i)
        infos.append(info)
    isview = nodes.new('GeometryNodeIsViewport')
    isview.location = (-300, 300)
    switch = nodes.new('GeometryNodeSwitch')
    switch.location = (0, 0)
    sw, false_in, true_in, proxy_out = compat.switch_geometry_sockets(switch)
    links.new(isview.outputs[0], sw)
    links.new(infos[0].outputs['Geometry'], true_in)
    links.new(infos[1].outputs['Geometry'], false_in)
    size = nodes.new('GeometryNodeAttributeDomainSize')
    size.location = (200, 200)
    links.new(proxy_out, size.inputs[0])
    nonempty = nodes.new('ShaderNodeMath')
    nonempty.operation = 'GREATER_THAN'
    nonempty.inputs[1].default_value = 0.5
    nonempty.location = (400, 200)
    links.new(size.outputs['Point Count'], nonempty.inputs[0])
    fallback = nodes.new('GeometryNodeSwitch')
    fallback.location = (600, 0)
    sw2, cage_in, limit_in, out = compat.switch_geometry_sockets(fallback)
    links.new(nonempty.outputs[0], sw2)
    links.new(gin.outputs[0], cage_in)
    links.new(proxy_out, limit_in)
    gout.location = (850, 0)
    links.new(out, gout.inputs[0])
    return group


def ensure(obj, context=None):
    """Creates or repairs the modifier, its node group and the two proxies of a cage.
    A duplicated cage (sharing its original's group) gets its own group and proxies."""
    s = obj.ccnurbs
    if s.role != 'CAGE':
        s.role = 'CAGE'
    mod = get_modifier(obj)
    group = mod.node_group if mod is not None else None
    view, render = s.proxy, s.render_proxy
    if not _owned(view, obj):
        view = s.proxy = _new_proxy(obj, 'VIEW_PROXY')
    if not _owned(render, obj):
        render = s.render_proxy = _new_proxy(obj, 'RENDER_PROXY')
    if (group is None or not group.get(GROUP_TAG) or group.users > 1
            or _group_proxies(group) != (view, render)):
        group = _build_group(obj, view, render)
    if mod is None:
        mod = obj.modifiers.new(MOD_NAME, 'NODES')
        mod.show_in_editmode = True
        try:
            compat.move_modifier_first(obj, mod, context)
        except (RuntimeError, TypeError):
            pass  # stays last: still correct when no modifier before it changes geometry
    if mod.node_group != group:
        mod.node_group = group
    return mod


def _owned(proxy, obj):
    """A proxy belongs to the cage whose name it records: a duplicated or renamed cage gets
    new proxies instead of sharing (and overwriting) another cage's."""
    return (proxy is not None and proxy.type == 'MESH' and proxy.library is None
            and proxy.ccnurbs.owner_name == obj.name)


def needs_repair(obj):
    s = obj.ccnurbs
    mod = get_modifier(obj)
    group = mod.node_group if mod is not None else None
    return (not _owned(s.proxy, obj) or not _owned(s.render_proxy, obj) or group is None
            or not group.get(GROUP_TAG) or group.users > 1
            or _group_proxies(group) != (s.proxy, s.render_proxy))


def remove(obj):
    """Removes the modifier, its group and the proxies; keeps the cage and its intervals."""
    s = obj.ccnurbs
    mod = get_modifier(obj)
    group = mod.node_group if mod is not None else None
    if mod is not None:
        obj.modifiers.remove(mod)
    if group is not None and group.users == 0 and group.get(GROUP_TAG):
        bpy.data.node_groups.remove(group)
    for attr in ("proxy", "render_proxy"):
        p = getattr(s, attr)
        setattr(s, attr, None)
        if p is not None and p.ccnurbs.owner_name == obj.name and p.users == 0:
            me = p.data
            bpy.data.objects.remove(p)
            if me is not None and me.users == 0:
                bpy.data.meshes.remove(me)
    s.role = 'NONE'
