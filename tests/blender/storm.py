"""A seeded random storm of what artists do to cages, checked after every step (run inside
Blender's Python; used by case_storm.py in `make test` and by long_storm.sh for long runs).

Operations: add a cage (cube, grid, Suzanne, cylinder) with CCNURBS; remove CCNURBS; duplicate
the modifier; Copy to Selected; Copy Modifiers; move vertices (Object and Edit Mode); change the
topology in Edit Mode; set a ring's interval with the add-on's operator; set creases; change
levels, scheme, cap and boundary; add Mirror, Array or Displace above CCNURBS; animate a
Displace and change frames; apply CCNURBS; duplicate (Shift+D, Alt+D); join; separate by loose
parts; rename; undo; redo; save and reopen.

After every step, for every object with a CCNURBS modifier in the scene (independently of the
add-on's own reading): the cage the modifier sees is the object evaluated with CCNURBS and
everything below it turned off; the surface shown is the object evaluated with everything
below CCNURBS turned off. It must equal `ccnurbs limit` of that cage (the CLI, same settings)
to float32 rounding (<= 1e-6 of the cage's size), or, where the CLI refuses the cage, the
add-on must show an error; every evaluated coordinate is finite; the add-on printed no
traceback (handlers never raise). After a save and reopen the file holds no group or proxy
the scene does not use.

A failing sequence is shortened (delta debugging over the list of steps, each replayed from
an empty scene) and printed as the shortest sequence that still fails.
"""
import io
import os
import random
import sys
import traceback

import bmesh
import bpy
import numpy as np

import cagelib

TOL = 1e-6


class _Tee(io.TextIOBase):
    """sys.stderr that also counts Python tracebacks printed through it."""

    def __init__(self, inner):
        self.inner, self.tracebacks = inner, 0

    def write(self, s):
        if "Traceback (most recent call last)" in s:
            self.tracebacks += 1
        return self.inner.write(s)

    def flush(self):
        self.inner.flush()


class Storm:
    def __init__(self, pkg, cli, tmp):
        self.ccn, self.cli, self.tmp = pkg, cli, tmp

    # ---- scene helpers -------------------------------------------------------------------

    def ours(self, ob):
        return [m for m in ob.modifiers if m.type == 'NODES' and self.ccn.modifier.is_group(m.node_group)]

    def meshes(self):
        return sorted((o for o in bpy.context.scene.objects if o.type == 'MESH' and o.library is None
                       and o.ccnurbs.role not in ('VIEW_PROXY', 'RENDER_PROXY')), key=lambda o: o.name)

    def cages(self):
        return [o for o in self.meshes() if self.ours(o)]

    def select_only(self, objs, active=None):
        if bpy.context.object is not None and bpy.context.object.mode != 'OBJECT':
            bpy.ops.object.mode_set(mode='OBJECT')
        for o in bpy.context.view_layer.objects:
            o.select_set(False)
        for o in objs:
            o.select_set(True)
        bpy.context.view_layer.objects.active = active or (objs[0] if objs else None)

    def update(self):
        bpy.context.view_layer.update()
        return bpy.context.evaluated_depsgraph_get()

    # ---- the operations (each picks its targets with its own rng from the scene) ---------

    def op_add_cage(self, r):
        if len(self.meshes()) >= 8:
            return
        kind = r.choice(["cube", "grid", "monkey", "cylinder"])
        self.select_only([])
        if kind == "cube":
            bpy.ops.mesh.primitive_cube_add(size=2, location=(r.uniform(-4, 4), r.uniform(-4, 4), 0))
            if r.random() < 0.5:
                bpy.ops.object.mode_set(mode='EDIT')
                bpy.ops.mesh.select_all(action='SELECT')
                bpy.ops.mesh.subdivide(number_cuts=1)
                bpy.ops.object.mode_set(mode='OBJECT')
        elif kind == "grid":
            bpy.ops.mesh.primitive_grid_add(x_subdivisions=4, y_subdivisions=3, size=2)
        elif kind == "monkey":
            bpy.ops.mesh.primitive_monkey_add(size=1.5)
        else:
            bpy.ops.mesh.primitive_cylinder_add(vertices=6, depth=2)
        ob = bpy.context.object
        ob.name = "%s%d" % (kind.capitalize(), r.randrange(1000))
        bpy.ops.object.ccnurbs_add('EXEC_DEFAULT', True)
        ob.ccnurbs.levels = r.choice([1, 2])

    def pick(self, r, cages_only=True):
        objs = self.cages() if cages_only else self.meshes()
        return r.choice(objs) if objs else None

    MAX_FACES = 1500  # cages stay small: an applied limit that gets CCNURBS again grows 4^levels

    def small(self, *objs):
        return sum(len(o.data.polygons) for o in objs) <= self.MAX_FACES

    def op_remove(self, r):
        ob = self.pick(r)
        if ob is not None:
            self.select_only([ob])
            bpy.ops.object.ccnurbs_remove('EXEC_DEFAULT', True)

    def op_add_to_plain(self, r):
        plain = [o for o in self.meshes() if not self.ours(o) and self.small(o)]
        if plain:
            self.select_only([r.choice(plain)])
            bpy.ops.object.ccnurbs_add('EXEC_DEFAULT', True)

    def op_dup_modifier(self, r):
        ob = self.pick(r)
        if ob is not None:
            self.select_only([ob])
            bpy.ops.object.modifier_copy(modifier=self.ours(ob)[0].name)

    def op_copy_to_selected(self, r):
        cs = self.cages()
        if len(cs) >= 2 and hasattr(bpy.ops.object, "modifier_copy_to_selected"):
            src, dst = r.sample(cs, 2)
            self.select_only([src, dst], active=src)
            bpy.ops.object.modifier_copy_to_selected(modifier=self.ours(src)[0].name)

    def op_copy_modifiers(self, r):
        ms = self.meshes()
        if len(ms) >= 2:
            src, dst = r.sample(ms, 2)
            self.select_only([src, dst], active=src)
            bpy.ops.object.make_links_data(type='MODIFIERS')

    def op_move(self, r):
        ob = self.pick(r, cages_only=False)
        if ob is None or ob.data.users > 1 and r.random() < 0.5:
            return
        if r.random() < 0.5:
            self.select_only([ob])
            for v in r.sample(list(ob.data.vertices), min(3, len(ob.data.vertices))):
                v.co.z += r.uniform(-0.3, 0.3)
            ob.data.update()
        else:
            self.select_only([ob])
            bpy.ops.object.mode_set(mode='EDIT')
            bm = bmesh.from_edit_mesh(ob.data)
            for v in r.sample(list(bm.verts), min(3, len(bm.verts))):
                v.co.x += r.uniform(-0.3, 0.3)
            bmesh.update_edit_mesh(ob.data)
            self.update()
            bpy.ops.object.mode_set(mode='OBJECT')

    def op_topology(self, r):
        ob = self.pick(r, cages_only=False)
        if ob is None or not self.small(ob):
            return
        self.select_only([ob])
        bpy.ops.object.mode_set(mode='EDIT')
        bm = bmesh.from_edit_mesh(ob.data)
        what = r.choice(["subdivide", "extrude", "delete"])
        if what == "subdivide" and bm.edges:
            bmesh.ops.subdivide_edges(bm, edges=[r.choice(list(bm.edges))], cuts=1, use_grid_fill=True)
        elif what == "extrude" and bm.faces:
            f = r.choice(list(bm.faces))
            res = bmesh.ops.extrude_discrete_faces(bm, faces=[f])
            for g in res["faces"]:
                bmesh.ops.translate(bm, verts=list(g.verts), vec=g.normal * 0.3)
        elif what == "delete" and len(bm.faces) > 4:
            bmesh.ops.delete(bm, geom=[r.choice(list(bm.faces))], context='FACES_ONLY')
        bmesh.update_edit_mesh(ob.data)
        bpy.ops.object.mode_set(mode='OBJECT')

    def op_interval(self, r):
        ob = self.pick(r)
        if ob is None or not ob.data.edges:
            return
        self.select_only([ob])
        bpy.ops.object.mode_set(mode='EDIT')
        bpy.context.tool_settings.mesh_select_mode = (False, True, False)
        bm = bmesh.from_edit_mesh(ob.data)
        for e in bm.edges:
            e.select_set(False)
        bm.edges.ensure_lookup_table()
        e = bm.edges[r.randrange(len(bm.edges))]
        e.select_set(True)
        bm.select_history.add(e)
        bmesh.update_edit_mesh(ob.data)
        value = float(np.float32(np.exp(r.uniform(np.log(0.2), np.log(5.0)))))
        bpy.ops.mesh.ccnurbs_set_knot_interval('EXEC_DEFAULT', True, value=value)
        bpy.ops.object.mode_set(mode='OBJECT')

    def op_crease(self, r):
        ob = self.pick(r)
        if ob is None or not ob.data.edges:
            return
        vals = self.ccn.compat.edge_creases(ob.data)
        vals = np.zeros(len(ob.data.edges)) if vals is None else vals.copy()
        vals[r.randrange(len(vals))] = r.choice([0.0, 0.3, 0.7, 1.0])
        self.ccn.compat.set_edge_creases(ob.data, vals.astype(np.float32))
        ob.data.update()

    def op_settings(self, r):
        ob = self.pick(r)
        if ob is None:
            return
        s = ob.ccnurbs
        what = r.choice(["levels", "scheme", "cap", "boundary_smooth", "use_creases"])
        if what == "levels":
            s.levels = r.choice([0, 1, 2])
        elif what == "scheme":
            s.scheme = r.choice(['EIGEN', 'NURSS', 'CATMULL_CLARK'])
        elif what == "cap":
            s.cap = r.choice(['GUIDED_BI5', 'REFINE'])
        elif what == "boundary_smooth":
            s.boundary_smooth = r.choice(['ALL', 'PRESERVE_CORNERS'])
        else:
            s.use_creases = not s.use_creases

    def op_above(self, r):
        ob = self.pick(r)
        if ob is None or len(ob.modifiers) > 4:
            return
        kind = r.choice(['MIRROR', 'ARRAY', 'DISPLACE'])
        m = ob.modifiers.new(kind.title(), kind)
        if kind == 'ARRAY':
            m.count = 2
        if kind == 'DISPLACE':
            m.strength = r.uniform(-0.3, 0.3)
            if r.random() < 0.5:  # animated: frame changes move the cage
                m.keyframe_insert("strength", frame=1)
                m.strength += 0.5
                m.keyframe_insert("strength", frame=10)
        self.select_only([ob])
        while ob.modifiers[0] != m:
            bpy.ops.object.modifier_move_up(modifier=m.name)

    def op_frame(self, r):
        bpy.context.scene.frame_set(r.randrange(1, 12))

    def op_apply(self, r):
        ob = self.pick(r)
        if ob is not None and ob.data.users == 1 and len(ob.data.polygons) * 4 ** ob.ccnurbs.levels <= self.MAX_FACES:
            self.select_only([ob])
            bpy.ops.object.modifier_apply(modifier=self.ours(ob)[0].name)

    def op_duplicate(self, r):
        ob = self.pick(r, cages_only=False)
        if ob is not None and len(self.meshes()) < 8:
            self.select_only([ob])
            bpy.ops.object.duplicate(linked=r.random() < 0.3)
            bpy.ops.transform.translate(value=(r.uniform(-2, 2), r.uniform(-2, 2), 0))

    def op_join(self, r):
        ms = [o for o in self.meshes() if o.data.users == 1]
        if len(ms) >= 2:
            a, b = r.sample(ms, 2)
            if self.small(a, b):
                self.select_only([a, b], active=a)
                bpy.ops.object.join()

    def op_separate(self, r):
        ob = self.pick(r, cages_only=False)
        if ob is not None and ob.data.users == 1:
            self.select_only([ob])
            bpy.ops.object.mode_set(mode='EDIT')
            bpy.ops.mesh.select_all(action='SELECT')
            bpy.ops.mesh.separate(type='LOOSE')
            bpy.ops.object.mode_set(mode='OBJECT')

    def op_rename(self, r):
        ob = self.pick(r, cages_only=False)
        if ob is not None:
            ob.name = "R%d" % r.randrange(10000)

    def op_undo(self, r):
        bpy.ops.ed.undo()

    def op_redo(self, r):
        bpy.ops.ed.redo()

    def op_save_reopen(self, r):
        path = os.path.join(self.tmp, "storm.blend")
        bpy.ops.wm.save_as_mainfile(filepath=path)
        bpy.ops.wm.open_mainfile(filepath=path)
        self.check_hygiene()

    OPS = (("add_cage", 4), ("remove", 1), ("add_to_plain", 1), ("dup_modifier", 2),
           ("copy_to_selected", 2), ("copy_modifiers", 1), ("move", 6), ("topology", 3),
           ("interval", 5), ("crease", 2), ("settings", 3), ("above", 2), ("frame", 2),
           ("apply", 1), ("duplicate", 2), ("join", 1), ("separate", 1), ("rename", 2),
           ("undo", 3), ("redo", 1), ("save_reopen", 1))

    # ---- the checks ----------------------------------------------------------------------

    def check_hygiene(self):
        live = [o for o in bpy.data.objects if o.library is None and o.type == 'MESH' and self.ours(o)
                and len(o.users_scene) > 0]
        groups = {m.node_group for o in live for m in self.ours(o)}
        ours = [g for g in bpy.data.node_groups if self.ccn.modifier.is_group(g)]
        assert len(ours) == len(groups), "%d of our groups in the file, %d used" % (len(ours), len(groups))
        proxies = [o for o in bpy.data.objects if o.ccnurbs.role in ('VIEW_PROXY', 'RENDER_PROXY')]
        assert len(proxies) <= 2 * len(groups), "%d proxies for %d groups" % (len(proxies), len(groups))

    def _evaluated(self, ob, upto_ours):
        """The object's mesh evaluated with CCNURBS (upto_ours False) or with it too (True)
        turned off and everything below; returns a temporary mesh (caller removes it)."""
        mods = list(ob.modifiers)
        k = mods.index(self.ours(ob)[0])
        saved = [(m, m.show_viewport) for m in mods[k + (1 if upto_ours else 0):]]
        for m, _ in saved:
            m.show_viewport = False
        try:
            dg = self.update()
            me = bpy.data.meshes.new_from_object(ob.evaluated_get(dg), preserve_all_data_layers=True,
                                                 depsgraph=dg)
        finally:
            for m, v in saved:
                m.show_viewport = v
            self.update()
        return me

    def check_cage(self, ob):
        mod = self.ours(ob)[0]
        if not mod.show_viewport:
            return
        cage = self._evaluated(ob, upto_ours=False)
        shown = self._evaluated(ob, upto_ours=True)
        try:
            P = cagelib.mesh_positions(shown)
            assert np.isfinite(P).all(), "%s: non-finite coordinates shown" % ob.name
            s = ob.ccnurbs
            C = cagelib.mesh_positions(cage)
            size = float(np.linalg.norm(C.max(0) - C.min(0))) if len(C) else 1.0
            if s.levels == 0:  # Levels 0 shows the cage, as Subdivision Surface
                assert P.shape == C.shape and np.array_equal(P, C), \
                    "%s: Levels 0 does not show the cage" % ob.name
                return
            try:
                R, _ = cagelib.cli_limit(self.cli, cage, s.levels, s.scheme, s.cap, s.boundary_smooth,
                                         creases=s.use_creases)
            except RuntimeError:
                st = self.ccn.sync.status(ob, 'VIEW')
                assert st is not None and st.error, "%s: the CLI refuses the cage, the add-on shows no error" % ob.name
                return
            # the loose part follows the limit's vertices: vertices in no face, and 2^levels - 1
            # more per edge in no face (Subdivision Surface's; case_creases compares them)
            lv = np.empty(len(cage.loops), np.int64)
            cage.loops.foreach_get("vertex_index", lv)
            le = np.empty(len(cage.loops), np.int64)
            cage.loops.foreach_get("edge_index", le)
            n_free = len(cage.vertices) - len(np.unique(lv))
            n_loose_edges = len(cage.edges) - len(np.unique(le))
            extra = n_free + (2 ** s.levels - 1) * n_loose_edges
            assert len(P) == len(R) + extra, "%s: %d vertices shown, `ccnurbs limit` gives %d (+%d loose)" % (
                ob.name, len(P), len(R), extra)
            P = P[:len(R)]
            err = float(np.abs(P - R).max()) / max(size, 1e-30)
            assert err <= TOL, "%s: shown surface differs from `ccnurbs limit` by %.3g of the size" % (ob.name, err)
        finally:
            bpy.data.meshes.remove(cage)
            bpy.data.meshes.remove(shown)

    def check(self):
        if bpy.context.object is not None and bpy.context.object.mode != 'OBJECT':
            bpy.ops.object.mode_set(mode='OBJECT')
        self.update()
        for ob in self.cages():
            assert len(self.ours(ob)) == 1, "%s: %d CCNURBS modifiers" % (ob.name, len(self.ours(ob)))
            self.check_cage(ob)

    # ---- running -------------------------------------------------------------------------

    def reset(self):
        if bpy.context.object is not None and bpy.context.object.mode != 'OBJECT':
            bpy.ops.object.mode_set(mode='OBJECT')
        bpy.ops.wm.read_homefile(use_empty=True)

    @classmethod
    def plan(cls, seed, steps):
        r = random.Random(seed)
        names = [n for n, _ in cls.OPS]
        weights = [w for _, w in cls.OPS]
        ops = [("add_cage", r.randrange(1 << 30))]
        ops += [(r.choices(names, weights)[0], r.randrange(1 << 30)) for _ in range(steps - 1)]
        return ops

    def run(self, ops, stop_at_failure=True):
        """Replays ops from an empty scene, checking after each; returns (index, message) of the
        first failure, or None."""
        self.reset()
        tee = _Tee(sys.stderr)
        old, sys.stderr = sys.stderr, tee
        try:
            for i, (name, seed) in enumerate(ops):
                before = self.ccn.sync.stats["internal_errors"]
                try:
                    getattr(self, "op_" + name)(random.Random(seed))
                    bpy.ops.ed.undo_push(message="storm %s" % name)
                except (RuntimeError, ReferenceError, AttributeError, ValueError, IndexError,
                        TypeError):
                    pass  # an operator Blender refused (poll, context): the storm goes on
                try:
                    self.check()
                except AssertionError as e:
                    return i, str(e)
                except Exception:
                    return i, "checker failed: " + traceback.format_exc().splitlines()[-1]
                if tee.tracebacks or self.ccn.sync.stats["internal_errors"] != before:
                    return i, "the add-on printed a traceback (handlers must never raise)"
        finally:
            sys.stderr = old
        return None

    def shortest(self, ops):
        """Delta debugging: a shortest (1-minimal) sublist of ops that still fails."""
        fail = self.run(ops)
        if fail is None:
            return ops, None
        ops = ops[:fail[0] + 1]
        n = 2
        while len(ops) >= 2:
            chunk = max(1, len(ops) // n)
            reduced = False
            for start in range(0, len(ops), chunk):
                cand = ops[:start] + ops[start + chunk:]
                f = self.run(cand) if cand else None
                if f is not None:
                    ops, fail, n, reduced = cand[:f[0] + 1], f, max(n - 1, 2), True
                    break
            if not reduced:
                if n >= len(ops):
                    break
                n = min(len(ops), 2 * n)
        return ops, fail
