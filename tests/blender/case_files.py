"""File hygiene: after Apply, Remove, delete, rename, Copy Modifiers, Copy to Selected, Shift+D,
Alt+D, append into a new file and undo, a saved file holds exactly what its scene uses; Apply's
file is as small as Subsurf's; saving a 50k-face cage costs what saving it with Subsurf costs."""
import shutil
import time

from bltest import *  # noqa: F401,F403


def file_ids(path):
    """Names of the objects, meshes and node groups stored in a .blend (read without loading;
    from a copy: 4.x refuses to read the open file as a library)."""
    copy = path + ".read.blend"
    shutil.copyfile(path, copy)
    with bpy.data.libraries.load(copy) as (src, dst):
        return {"objects": set(src.objects), "meshes": set(src.meshes),
                "node_groups": set(src.node_groups)}


def expected_ids(scene):
    """What the scene uses: its objects, the proxies their groups name, their meshes, groups.
    A viewport proxy is written with one shared empty mesh instead of its limit mesh."""
    objs, groups, meshes = set(), set(), set()
    for o in scene.objects:
        objs.add(o)
        for m in o.modifiers:
            if m.type == 'NODES' and m.node_group is not None:
                groups.add(m.node_group)
                objs.update(p for p in ccn.modifier.group_proxies(m.node_group) if p)
    for o in objs:
        if o.type != 'MESH':
            continue
        swapped = o.ccnurbs.role == 'VIEW_PROXY' and len(o.data.vertices)
        meshes.add(ccn.proxies.EMPTY_NAME if swapped else o.data.name)
    return {"objects": {o.name for o in objs}, "meshes": meshes,
            "node_groups": {g.name for g in groups}}


def save(name):
    path = os.path.join(TMP, name + ".blend")
    bpy.context.preferences.filepaths.save_version = 0
    bpy.ops.wm.save_as_mainfile(filepath=path)
    return path


def select_only(*objs):
    for o in bpy.context.view_layer.objects:
        o.select_set(False)
    for o in objs:
        o.select_set(True)
    bpy.context.view_layer.objects.active = objs[0]



def from_library(stem, name, link):
    """Saves the scene as library STEM_lib.blend, starts a new file and appends or links
    object NAME from it into the scene; returns that object (evaluated once)."""
    save(stem + "_src")
    src = os.path.join(TMP, stem + "_lib.blend")
    shutil.copyfile(os.path.join(TMP, stem + "_src.blend"), src)
    reset_scene()
    with bpy.data.libraries.load(src, link=link) as (data_from, data_to):
        data_to.objects = [name]
    ob = data_to.objects[0]
    bpy.context.scene.collection.objects.link(ob)
    update()
    return ob

class TestFileHygiene(AddonTestCase):
    def assertClean(self, path, msg=""):
        got, want = file_ids(path), expected_ids(bpy.context.scene)
        for k in want:
            self.assertEqual(got[k], want[k], "%s: %s in the file differ from what the scene "
                             "uses %s" % (msg, k, sorted(got[k] ^ want[k])))

    def assertOwnSurface(self, ob):
        P = evaluated_positions(ob)
        R, _ = reference(ob)
        self.assertEqual(P.shape, R.shape, ob.name)
        self.assertLessEqual(np.abs(P - R).max(), POS_TOL, ob.name)

    def test_apply_remove_delete(self):
        for action in ("apply", "remove", "delete", "x-button"):
            with self.subTest(action=action):
                reset_scene()
                ob = add_modifier(grid(4, "G"))
                grid(2, "Other")
                select_only(ob)
                mod = ccn.modifier.get_modifier(ob)
                if action == "apply":
                    bpy.ops.object.modifier_apply(modifier=mod.name)
                elif action == "remove":
                    bpy.ops.object.ccnurbs_remove()
                elif action == "x-button":
                    bpy.ops.object.modifier_remove(modifier=mod.name)
                else:
                    bpy.ops.object.delete()
                update()
                path = save("hyg_" + action)
                self.assertClean(path, action)
                got = file_ids(path)
                self.assertFalse(any(n.startswith(".CCNURBS") for n in got["objects"]), action)
                self.assertEqual({"Other"} | ({"G"} if action != "delete" else set()),
                                 got["objects"])

    def test_apply_file_size_like_subsurf(self):
        sizes, raws = {}, {}
        for kind in ("SUBSURF", "CCNURBS"):
            reset_scene()
            ob = grid(16, "Apply" + kind)
            if kind == "SUBSURF":
                m = ob.modifiers.new("Subsurf", 'SUBSURF')
                m.levels = 2
            else:
                add_modifier(ob, levels=2)
                m = ccn.modifier.get_modifier(ob)
            select_only(ob)
            update()
            bpy.ops.object.modifier_apply(modifier=m.name)
            sizes[kind] = os.path.getsize(save("apply_" + kind))
            if bpy.app.version >= (5, 0, 0):  # saves compressed: also the uncompressed size
                raw = os.path.join(TMP, "apply_raw_" + kind + ".blend")
                bpy.ops.wm.save_as_mainfile(filepath=raw, copy=True, compress=False)
                raws[kind] = os.path.getsize(raw)
            n = len(ob.data.vertices)
            # the applied limit keeps its exact normals: encoded custom normals before 4.5
            # (2 int16 per face corner), which Subdivision Surface's mesh does not have
            if kind == "CCNURBS" and not ccn.compat.FREE_NORMALS and \
                    ccn.compat.has_custom_normals(ob.data):
                normal_bytes = 4 * len(ob.data.loops)
            elif kind == "CCNURBS":
                normal_bytes = 0
        print("measure apply-file: Subsurf %d bytes, CCNURBS %d bytes (%.3f), %d vertices"
              % (sizes["SUBSURF"], sizes["CCNURBS"], sizes["CCNURBS"] / sizes["SUBSURF"], n))
        if raws:
            # Blender 5.0's compressed size of the same file varies between runs (measured on
            # this cage: Subsurf 178.7k-180.6k, CCNURBS 180.7k-199.0k under load, the content
            # being identical: uncompressed 749,278 / 749,630 bytes in every run), so the
            # content is asserted uncompressed and the compressed file with a margin
            print("measure apply-file uncompressed: Subsurf %d bytes, CCNURBS %d bytes (%.4f)"
                  % (raws["SUBSURF"], raws["CCNURBS"], raws["CCNURBS"] / raws["SUBSURF"]))
            self.assertLessEqual(raws["CCNURBS"], 1.10 * raws["SUBSURF"])
            self.assertLessEqual(sizes["CCNURBS"], 1.25 * sizes["SUBSURF"])
        else:
            self.assertLessEqual(sizes["CCNURBS"], 1.10 * sizes["SUBSURF"] + normal_bytes)

    def test_rename_keeps_proxies_and_status(self):
        ob = add_modifier(grid(3, "Old"))
        view = ccn.modifier.proxy(ob, 'VIEW')
        ob.name = "New"
        ob.data.vertices[0].co.z = 0.5
        ob.data.update()
        update()
        self.assertIs(ccn.modifier.proxy(ob, 'VIEW'), view, "rename made new proxies")
        self.assertEqual(view.name, ".CCNURBS view New")
        st = ccn.sync.status(ob)
        self.assertIsNotNone(st, "status lost after rename")
        self.assertIn("Limit:", " ".join(ccn.ui.status_lines(ob)))
        self.assertOwnSurface(ob)
        path = save("hyg_rename")
        self.assertClean(path, "rename")
        bpy.ops.wm.open_mainfile(filepath=path)
        self.assertOwnSurface(bpy.data.objects["New"])

    def test_state_follows_the_object_not_its_name(self):
        """The add-on's memory of a cage (plans, status, notes) is keyed by the object, not its
        name: a rename keeps the plan (no new one is made), swapping two cages' names swaps
        nothing, a copy starts with its own, and a deleted cage's state is dropped."""
        a = add_modifier(grid(3, "A"), levels=1)
        b = add_modifier(grid(4, "B"), levels=2)
        plan_a = ccn.state.of(a).plans['VIEW'][1]
        plan_b = ccn.state.of(b).plans['VIEW'][1]
        made = ccn.sync.stats["rebuilds"]
        a.name, b.name = "Tmp", "A"
        a.name = "B"  # the two names swapped
        for ob in (a, b):
            ob.data.vertices[0].co.z += 0.25
            ob.data.update()
        update()
        self.assertIs(ccn.state.of(a).plans['VIEW'][1], plan_a, "a rename made a new plan")
        self.assertIs(ccn.state.of(b).plans['VIEW'][1], plan_b, "a rename made a new plan")
        self.assertEqual(ccn.sync.stats["rebuilds"], made, "a rename rebuilt a proxy")
        self.assertEqual(ccn.sync.status(a).levels, 1)
        self.assertEqual(ccn.sync.status(b).levels, 2)
        self.assertOwnSurface(a)
        self.assertOwnSurface(b)
        select_only(a)
        bpy.ops.object.duplicate()
        copy = bpy.context.object
        update()
        self.assertIsNot(ccn.state.of(copy), ccn.state.of(a), "a copy shares its source's state")
        self.assertOwnSurface(copy)
        gone = ccn.state.key(b)
        bpy.data.objects.remove(b)
        update()
        self.assertNotIn(gone, [k for k, _ in ccn.state.items()], "a deleted cage's state stays")

    def test_copies_get_their_own_surface(self):
        for how in ("shift-d", "alt-d", "copy-modifiers", "copy-to-selected"):
            with self.subTest(how=how):
                reset_scene()
                src = add_modifier(grid(2, "Src"), levels=1, scheme='NURSS')
                if how in ("shift-d", "alt-d"):
                    select_only(src)
                    bpy.ops.object.duplicate(linked=how == "alt-d")
                    dst = bpy.context.view_layer.objects.active
                    dst.location.x += 5
                else:
                    dst = load_cage("Dst", os.path.join(DATA, "fan5.obj"))
                    select_only(src, dst)
                    bpy.context.view_layer.objects.active = src
                    if how == "copy-modifiers":
                        bpy.ops.object.make_links_data(type='MODIFIERS')
                    else:
                        mod = ccn.modifier.get_modifier(src)
                        with bpy.context.temp_override(object=src, active_object=src,
                                                       selected_objects=[src, dst]):
                            bpy.ops.object.modifier_copy_to_selected(modifier=mod.name)
                update()
                self.assertIsNot(dst, src)
                self.assertTrue(ccn.modifier.is_cage(dst), how)
                self.assertEqual(dst.ccnurbs.scheme, 'NURSS', "settings follow the modifier")
                self.assertFalse(set(ccn.modifier.proxies(dst)) & set(ccn.modifier.proxies(src)),
                                 how + ": the copy shares a proxy")
                self.assertIsNot(ccn.modifier.proxy(dst, 'VIEW'),
                                 ccn.modifier.proxy(src, 'VIEW'), how)
                if how != "alt-d":
                    dst.data.vertices[0].co.z += 1.0
                    dst.data.update()
                update()
                self.assertOwnSurface(src)
                self.assertOwnSurface(dst)
                self.assertClean(save("hyg_" + how), how)

    def test_append_into_new_file(self):
        add_modifier(grid(3, "Appended"))
        from_library("hyg_append", "Appended", link=False)
        ob = bpy.data.objects["Appended"]
        self.assertOwnSurface(ob)
        self.assertClean(save("hyg_append_dst"), "append")

    def test_linked_cage_says_it_shows_the_cage(self):
        """A cage linked (not appended) from a library file that stores no render mesh cannot
        get its limit written (its proxies are the library's, read-only): it shows its cage and
        the panel says so, with what to do, instead of nothing."""
        ob = add_modifier(grid(3, "Linked"))
        self.assertGreater(len(evaluated_positions(ob)), len(ob.data.vertices))
        lo = from_library("hyg_link", "Linked", link=True)
        self.assertIsNotNone(lo.library)
        st = ccn.sync.status(lo)
        self.assertIsNotNone(st, "a linked cage gets no status")
        self.assertIn("linked from hyg_link_lib.blend, which stores no render mesh: the add-on "
                      "cannot write", st.error or "")
        self.assertEqual(st.showing, "cage")
        self.assertEqual(len(evaluated_positions(lo)), len(lo.data.vertices))
        for way in ("Library Override > Make", "File > Append", "Make Local",
                    "Store Render Mesh in File"):
            self.assertIn(way, ccn.errors.advice(st))
        bpy.context.view_layer.objects.active = lo
        self.assertIn("the add-on cannot write the limit surface",
                      labels(draw_panel(ccn.ui.DATA_PT_ccnurbs_modifier)))
        local = lo.make_local()  # what the advice says: the surface appears
        update()
        self.assertIsNone(local.library)
        self.assertIsNone(ccn.sync.status(local).error)
        self.assertOwnSurface(local)

    def test_undo_leaves_nothing_stale(self):
        ob = grid(3, "Undo")
        bpy.ops.ed.undo_push(message="start")
        add_modifier(ob)
        ob = bpy.data.objects["Undo"]
        ob.data.vertices[5].co.z = 1.0
        ob.data.update()
        bpy.ops.ed.undo_push(message="moved")
        update()
        bpy.ops.ed.undo()
        ob = bpy.data.objects["Undo"]
        update()
        self.assertOwnSurface(ob)
        path = save("hyg_undo")
        self.assertClean(path, "undo")
        bpy.ops.wm.open_mainfile(filepath=path)
        self.assertOwnSurface(bpy.data.objects["Undo"])


    def test_save_leaves_the_proxies_as_they_were(self):
        """The save writes the viewport proxy with the empty mesh and gives it its limit mesh
        back (through the Python API: nothing is written into Blender's memory, so the proxy
        is evaluated again), also with materials; the file holds no limit mesh."""
        ob = add_modifier(grid(4, "Saved"))
        for name in ("Red", "Blue"):
            ob.data.materials.append(bpy.data.materials.new(name))
        ob.data.polygons[3].material_index = 1
        ob.data.update()
        update()
        p = ccn.modifier.proxy(ob, 'VIEW')
        me, users = p.data, p.data.users
        self.assertEqual(len(p.material_slots), 2)
        path = save("hyg_save_swap")
        update()
        self.assertEqual(p.data, me, "the proxy keeps its limit mesh")
        self.assertEqual(me.users, users)
        empty = bpy.data.meshes.get(ccn.proxies.EMPTY_NAME)
        self.assertTrue(empty is None or empty.users == 0)
        bpy.data.orphans_purge()
        self.assertEqual(p.data, me, "purging orphans keeps the limit mesh")
        self.assertEqual(me.users, users)
        self.assertOwnSurface(ob)
        self.assertClean(path, "save")
        bpy.ops.wm.open_mainfile(filepath=path)
        ob = bpy.data.objects["Saved"]
        update()
        self.assertOwnSurface(ob)
        p = ccn.modifier.proxy(ob, 'VIEW')
        self.assertEqual([m.name for m in p.data.materials], ["Red", "Blue"])
        self.assertEqual(len(p.material_slots), 2)

    def _instanced_positions(self, name):
        """The positions a collection instance draws for object `name` (evaluated)."""
        dg = update()
        found = None
        for inst in dg.object_instances:  # to its end: a walk left early leaks its dupli list
            if inst.is_instance and inst.instance_object and inst.instance_object.original.name == name:
                found = cagelib.mesh_positions(inst.instance_object.data) if found is None else found
        return found

    def test_collection_instance_shows_the_surface(self):
        """A cage inside a collection that an Empty instances (Add > Collection Instance; how
        assets and characters are reused), the collection itself in no scene: the instance
        shows the cage's limit, follows its edits, and keeps it after save and reopen."""
        coll = bpy.data.collections.new("Asset")
        bpy.context.scene.collection.children.link(coll)
        ob = load_cage("Piece", os.path.join(DATA, "fan5.obj"))
        for c in list(ob.users_collection):
            c.objects.unlink(ob)
        coll.objects.link(ob)
        d = ob.modifiers.new("Displace", 'DISPLACE')
        d.strength = 0.0
        d.keyframe_insert("strength", frame=1)
        d.strength = 0.5
        d.keyframe_insert("strength", frame=5)
        bpy.context.scene.frame_set(1)
        add_modifier(ob)
        bpy.context.scene.collection.children.unlink(coll)
        emp = bpy.data.objects.new("Instance", None)
        emp.instance_type = 'COLLECTION'
        emp.instance_collection = coll
        bpy.context.scene.collection.objects.link(emp)
        update()
        ob.data.vertices[0].co.z += 0.4  # an edit of the cage (Tab into it, or a script)
        ob.data.update()
        update()
        for step in ("edited", "reopened"):
            P = self._instanced_positions("Piece")
            R, _ = reference(bpy.data.objects["Piece"])
            self.assertIsNotNone(P, "%s: no instance drawn" % step)
            self.assertEqual(P.shape, R.shape, "%s: the instance shows the cage, not its limit" % step)
            self.assertLessEqual(np.abs(P - R).max(), POS_TOL, step)
            if step == "edited":
                # an animated cage in the instance follows the frames (Displace above CCNURBS)
                bpy.context.scene.frame_set(5)
                P5 = self._instanced_positions("Piece")
                bpy.context.scene.frame_set(1)
                P1 = self._instanced_positions("Piece")
                self.assertGreater(np.abs(P5 - P1).max(), 0.1, "the instance did not follow the frame")
                self.assertLessEqual(np.abs(P1 - R).max(), POS_TOL, "frame 1")
                path = save("hyg_instance")
                bpy.ops.wm.open_mainfile(filepath=path)

    def test_fake_user_cage_outside_scenes_keeps_its_surface(self):
        """An object kept with a fake user and in no scene keeps its group and proxies on save."""
        ob = add_modifier(grid(3, "Kept"))
        ob.use_fake_user = True
        for c in list(ob.users_collection):
            c.objects.unlink(ob)
        update()
        path = save("hyg_fake_user")
        bpy.ops.wm.open_mainfile(filepath=path)
        ob = bpy.data.objects["Kept"]
        self.assertIsNotNone(ccn.modifier.get_modifier(ob))
        self.assertTrue(ccn.modifier.is_group(ccn.modifier.get_modifier(ob).node_group),
                        "the group was deleted on save")
        self.assertTrue(all(ccn.modifier.proxies(ob)), "the proxies were deleted on save")

    def test_no_write_into_blenders_memory(self):
        """The add-on's modules hold no ctypes access to Blender's memory."""
        import pkgutil
        pkg = sys.modules[type(ccn).module]
        for info in pkgutil.iter_modules(pkg.__path__):
            mod = sys.modules.get(pkg.__name__ + "." + info.name)
            if mod is None or info.name == "native":  # native: the library through ctypes, by design
                continue
            src = open(mod.__file__).read()
            self.assertNotIn("from_address", src, "%s reads or writes Blender's memory" % info.name)


    def test_exit_frees_every_block(self):
        """A Blender that used the modifier (edits, a frame change, a render, a save, a disable)
        exits without "Not freed memory blocks"."""
        if AS_MODULE and bpy.app.version[:2] == (4, 2):
            # bpy 4.2 as a module crashes at interpreter exit once any add-on with a panel was
            # enabled (bpy_class_free after Python is finalized): no exit report to read
            self.skipTest("bpy 4.2 as a module cannot exit normally with an add-on enabled")
        script = os.path.join(TMP, "exit_check.py")
        with open(script, "w") as fh:
            fh.write(EXIT_SCRIPT % {"module": module_name(), "tmp": TMP})
        run = subprocess.run(blender_command(script), timeout=300, stdout=subprocess.PIPE,
                             stderr=subprocess.STDOUT, text=True)
        self.assertIn("exit check: done", run.stdout, run.stdout[-2000:])
        self.assertNotIn("Not freed memory blocks", run.stdout, run.stdout[-2000:])


EXIT_SCRIPT = '''import os, addon_utils, bpy
addon_utils.enable(%(module)r, default_set=True, handle_error=None)
bpy.ops.mesh.primitive_cube_add()
ob = bpy.context.object
bpy.ops.object.ccnurbs_add()
ob.ccnurbs.levels = 2
bpy.context.view_layer.update()
ob.data.vertices[0].co.x += 0.25
ob.data.update()
bpy.context.view_layer.update()
d = ob.modifiers.new("Disp", 'DISPLACE')
d.strength = 0.0
d.keyframe_insert("strength", frame=1)
d.strength = 1.0
d.keyframe_insert("strength", frame=2)
bpy.context.scene.frame_set(2)
sc = bpy.context.scene
cam = bpy.data.objects.new("Cam", bpy.data.cameras.new("Cam"))
sc.collection.objects.link(cam)
cam.location = (0.0, -6.0, 0.0)
cam.rotation_euler = (1.5708, 0.0, 0.0)
sc.camera = cam
sc.render.engine = 'BLENDER_WORKBENCH'
sc.render.resolution_x = sc.render.resolution_y = 16
sc.render.filepath = os.path.join(%(tmp)r, "exit_check.png")
bpy.ops.render.render(write_still=True)
bpy.ops.wm.save_as_mainfile(filepath=os.path.join(%(tmp)r, "exit_check.blend"))
addon_utils.disable(%(module)r, default_set=True)
print("exit check: done")
'''

class TestSaveCost(AddonTestCase):
    def test_save_50k_cage_like_subsurf(self):
        n = 224  # 50,176 faces
        V = np.array([(x, y, 0.0) for y in range(n + 1) for x in range(n + 1)], float)
        F = [(y * (n + 1) + x, y * (n + 1) + x + 1, (y + 1) * (n + 1) + x + 1,
              (y + 1) * (n + 1) + x) for y in range(n) for x in range(n)]
        times, sizes, raws = {}, {}, {}  # kind -> (save_pre..save_post, the operator call)
        for kind in ("SUBSURF", "CCNURBS"):
            reset_scene()
            ob = load_cage("Big", V=V, F=F, K={})
            if kind == "SUBSURF":
                m = ob.modifiers.new("Subsurf", 'SUBSURF')
                m.levels = 2
            else:
                add_modifier(ob, levels=2)
            update()
            path = save("save50k_" + kind)
            best = []
            marks = {}

            def pre(*a):
                marks["pre"] = time.perf_counter()

            def post(*a):
                marks["post"] = time.perf_counter()
            bpy.app.handlers.save_pre.insert(0, pre)  # before the add-on's: all of the save
            bpy.app.handlers.save_post.append(post)
            try:
                for r in range(3):
                    ob.data.vertices[r].co.z += 0.25  # a vertex move, then Ctrl+S
                    ob.data.update()
                    update()
                    t0 = time.perf_counter()
                    bpy.ops.wm.save_mainfile(filepath=path)
                    t1 = time.perf_counter()
                    update()  # whatever the save left for the next redraw
                    t2 = time.perf_counter()
                    best.append((marks["post"] - marks["pre"], t1 - t0, t2 - t0))
            finally:
                bpy.app.handlers.save_pre.remove(pre)
                bpy.app.handlers.save_post.remove(post)
            times[kind] = min(best)
            sizes[kind] = os.path.getsize(path)
            if bpy.app.version >= (5, 0, 0):  # saves compressed: also the uncompressed size
                raw = os.path.join(TMP, "save50k_raw_" + kind + ".blend")
                bpy.ops.wm.save_as_mainfile(filepath=raw, copy=True, compress=False)
                raws[kind] = os.path.getsize(raw)
            if kind == "CCNURBS":
                self.assertEqual(len(evaluated_positions(ob)), (4 * n + 1) ** 2)
        ratio = times["CCNURBS"][0] / times["SUBSURF"][0]
        ratio_next = times["CCNURBS"][1] / times["SUBSURF"][1]
        print("measure save50k: save_pre..save_post Subsurf %.4f s, CCNURBS %.4f s (%.2fx); the "
              "operator call %.4f / %.4f s (%.2fx); with the next redraw's evaluation %.4f / "
              "%.4f s (%.2fx); files %d / %d bytes"
              % (times["SUBSURF"][0], times["CCNURBS"][0], ratio, times["SUBSURF"][1],
                 times["CCNURBS"][1], ratio_next, times["SUBSURF"][2], times["CCNURBS"][2],
                 times["CCNURBS"][2] / times["SUBSURF"][2], sizes["SUBSURF"], sizes["CCNURBS"]))
        if raws:
            # Blender 5.0's compressed size varies between runs with the same content (this
            # cage: Subsurf 1.23-1.43 MB, CCNURBS 1.32-1.51 MB), as in
            # test_apply_file_size_like_subsurf: the content is asserted uncompressed
            print("measure save50k uncompressed: Subsurf %d bytes, CCNURBS %d bytes (%.4f)"
                  % (raws["SUBSURF"], raws["CCNURBS"], raws["CCNURBS"] / raws["SUBSURF"]))
            self.assertLessEqual(raws["CCNURBS"], 1.2 * raws["SUBSURF"], "the file holds more")
            self.assertLessEqual(sizes["CCNURBS"], 1.5 * sizes["SUBSURF"], "the file holds more")
        else:
            self.assertLessEqual(sizes["CCNURBS"], 1.2 * sizes["SUBSURF"], "the file holds more")
        # the write itself, generous margin against millisecond noise (target 1.2x)
        self.assertLessEqual(times["CCNURBS"][0], 3.0 * times["SUBSURF"][0] + 0.05,
                             "saving is far slower than with Subsurf (target 1.2x)")
        # what the save leaves for the next redraw (the proxies evaluated again: the swap goes
        # through the Python API) is measured above, not asserted: performance is `make bench`'s
