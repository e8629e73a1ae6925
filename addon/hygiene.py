"""File hygiene: which groups and proxies belong to which live cage; everything else goes.

A *live* cage is a local mesh object the file keeps (in a scene, in a collection that an
instance draws, or with a fake user) with a CCNURBS modifier using one of our groups. One pass over bpy.data (`collect`, O(objects + groups), run on save, load, undo, and
after updates that change the object or group count or touch a cage whose ownership is off):

* a group used by several live objects (Shift+D, Alt+D, Copy Modifiers, Copy to Selected) stays
  with its owner (`group["ccnurbs_owner"]`); every other user gets its own group and proxies
  (and the owner's settings if it had none);
* a group whose owner name is gone but which one live object uses was renamed with it (rename,
  append with a new name): the group, its proxies and their names follow;
* two live groups naming the same proxy (a duplicated node tree): the proxy stays with the
  group whose owner it records; the other cage gets new proxies;
* one CCNURBS per object: a second one (the modifier panel's Duplicate, Copy to Selected or Copy
  Modifiers onto a cage, a Nodes modifier given one of our groups) is removed, the first in the
  stack stays, and the panel says so (the state's `removed_note`, state.py). Two would share a group and its proxies:
  the second would read the first's limit as its cage and write the limit of the limit into the
  same proxy, growing at every edit;
* a cage whose modifier is gone (Apply, X) stops being a cage; an applied limit loses its
  marker attribute (and, 4.4+, the custom normals: the mesh Subsurf's Apply would give);
* groups no live cage uses, proxies no live group names, and our empty/scratch meshes are
  deleted, so a saved file holds only what its scenes use.
"""
import bpy
import numpy as np

from . import compat, modifier, proxies, state

REMOVED_NOTE = ("A second CCNURBS modifier (\"%s\") was removed: one per object. To subdivide "
                "the limit again, apply this one first.")

SETTINGS = ("levels", "render_levels", "scheme", "cap", "boundary_smooth", "uv_smooth",
            "normals", "use_creases", "store_render_mesh", "curvature",
            "cap_status")
PROXY_ROLES = ('VIEW_PROXY', 'RENDER_PROXY')


def is_live(obj):
    """A local object the file keeps: in a scene, in a collection (a collection instance draws
    it without it being in any scene: assets, characters), or with a fake user. An object with
    no user is gone at the next save, and so are its group and proxies."""
    return obj.library is None and obj.users > 0


def ours(obj):
    """The object's CCNURBS modifiers (Nodes modifiers using one of our groups), in stack order."""
    return [m for m in obj.modifiers if m.type == 'NODES' and modifier.is_group(m.node_group)]


def suspicious(obj):
    """Cheap per-object test the update handler runs on updated objects: does this need a
    collect()? (copied modifier, shared group, renamed cage, applied modifier, a second one)."""
    if obj.type != 'MESH' or obj.library is not None:
        return False
    if len(ours(obj)) > 1:
        return True
    mod = modifier.get_modifier(obj)
    if mod is None:
        return obj.ccnurbs.role == 'CAGE'
    group = mod.node_group
    return (obj.ccnurbs.role != 'CAGE' or not modifier.is_group(group) or group.users > 1
            or modifier.owner_of(group) != obj.name_full
            or group.get(modifier.GROUP_TAG) != modifier.GROUP_VERSION)


def _copy_settings(src, dst):
    for name in SETTINGS:
        setattr(dst.ccnurbs, name, getattr(src.ccnurbs, name))


def _adopt(group, obj):
    """obj (renamed, or appended under a new name) keeps its group and proxies."""
    group[modifier.OWNER_PROP] = obj.name_full
    group.name = "CCNURBS " + obj.name_full
    for role, p in zip(PROXY_ROLES, modifier.group_proxies(group)):
        if p is not None and p.library is None:
            p.ccnurbs.owner_name = obj.name_full
            p.name = modifier.proxy_name(role, obj.name_full)
            if p.data is not None and p.data.users == 1 and p.data.library is None:
                p.data.name = p.name


def _applied(me):
    """An applied limit (it carries the limit marker) keeps positions and faces like Subsurf's
    Apply: the marker goes, and so do the custom normals where Python can remove them (4.4+),
    so the mesh is what Subsurf's Apply would store (README: file size)."""
    if me is None or me.library is not None:
        return
    a = me.attributes.get(proxies.LIMIT_ATTR)
    if a is None:
        return
    me.attributes.remove(a)
    if compat.drop_custom_normals(me):  # and the all-False sharp_edge custom normals made
        e = me.attributes.get("sharp_edge")
        if e is not None and e.domain == 'EDGE' and e.data_type == 'BOOLEAN':
            v = np.empty(len(e.data), bool)
            e.data.foreach_get("value", v)
            if not v.any():
                me.attributes.remove(e)


def _one_per_object(obj):
    """Removes every CCNURBS modifier of obj but the first; the note says which went. Returns
    True if one went (the object's evaluation, and its tap, are stale until the next one)."""
    extra = ours(obj)[1:]
    for m in extra:
        name = m.name
        obj.modifiers.remove(m)
        state.of(obj).removed_note = REMOVED_NOTE % name
        print("CCNURBS: %s: %s" % (obj.name_full, REMOVED_NOTE % name))
    return bool(extra)


def collect():
    """One hygiene pass. Returns (renamed [(old, new)], fresh [objects: new groups, or a second
    modifier removed; their taps are read after a new evaluation], removed count)."""
    users, trimmed = {}, []
    for o in bpy.data.objects:
        if o.type != 'MESH' or o.library is not None:
            continue
        if len(o.modifiers) > 1 and _one_per_object(o):
            trimmed.append(o)
        mod = modifier.get_modifier(o)
        if mod is None:
            if o.ccnurbs.role == 'CAGE':
                o.ccnurbs.role = 'NONE'  # applied or removed by hand
                _applied(o.data)
            continue
        if is_live(o) and modifier.is_group(mod.node_group):
            users.setdefault(mod.node_group, []).append(o)
    renamed, fresh, keepers = [], [], {}
    for group, objs in users.items():
        owner = modifier.owner_of(group)
        keeper = next((o for o in objs if o.name_full == owner), None)
        if keeper is None:
            keeper = min(objs, key=lambda o: o.name_full)
            renamed.append((owner, keeper.name_full))
            _adopt(group, keeper)
        keepers[group] = keeper
        fresh += [(o, keeper) for o in objs if o is not keeper]
    claimed = {}
    for group, keeper in keepers.items():
        if group.get(modifier.GROUP_TAG) != modifier.GROUP_VERSION:
            fresh.append((keeper, keeper))  # a group an older add-on built: built again
    for group, keeper in keepers.items():  # a proxy named by two live groups
        for p in modifier.group_proxies(group):
            if p is None:
                continue
            other = claimed.get(p)
            if other is None:
                claimed[p] = keeper
            elif p.ccnurbs.owner_name == keeper.name_full:
                claimed[p] = keeper
                fresh.append((other, other))
            else:
                fresh.append((keeper, keeper))
    made = []
    for obj, src in fresh:
        if obj in made:
            continue
        if obj.ccnurbs.role != 'CAGE' and src is not obj:
            _copy_settings(src, obj)
        modifier.ensure(obj, fresh=True)
        made.append(obj)
    made += [o for o in trimmed if o not in made]  # evaluated again before their taps are read
    return renamed, made, _remove_unused()


def _remove_unused():
    live_groups, named = set(), set()
    for o in bpy.data.objects:
        if o.type == 'MESH' and o.library is None and is_live(o):
            mod = modifier.get_modifier(o)
            if mod is not None and modifier.is_group(mod.node_group):
                live_groups.add(mod.node_group)
                named.update(p for p in modifier.group_proxies(mod.node_group) if p)
    removed = 0
    for g in [g for g in bpy.data.node_groups if modifier.is_group(g)]:
        if g.library is None and g not in live_groups:
            bpy.data.node_groups.remove(g)
            removed += 1
    for p in [o for o in bpy.data.objects if o.ccnurbs.role in PROXY_ROLES]:
        if p.library is None and p not in named:
            modifier.remove_proxy(p)
            removed += 1
    # the add-on's two session meshes have no user and are never saved: the edit-mode scratch
    # (cage.py) and the empty mesh of saves (proxies.py). They stay: removing one re-creates it
    # at the next edit or save, and each removal or creation rebuilds the depsgraph relations
    # (in Edit Mode that was every update)
    return removed


def counts():
    """What the update handler compares to notice deletions, appends and links cheaply."""
    return len(bpy.data.objects), len(bpy.data.node_groups), len(bpy.data.meshes)
