"""The package: build/ccnurbs.zip installs as a legacy add-on (3.x) and with the 4.2+ extension
API (test_addon.install), and validates as an extension: Blender's own validator where this
Blender ships it (4.2+, the code behind `blender --command extension validate`), and the layout
checked here on every version (one top folder, manifest keys, native libraries for the declared
platform, permissions); a broken manifest is refused by the validator (the check can fail)."""
import glob
import tomllib
import zipfile

from bltest import *  # noqa: F401,F403


def validator():
    """Blender's extension CLI script (bl_pkg/cli/blender_ext.py), or None before 4.2."""
    root = bpy.utils.system_resource('SCRIPTS')
    hits = glob.glob(os.path.join(root, "addons_core", "bl_pkg", "cli", "blender_ext.py"))
    return hits[0] if hits else None


def validate(path):
    """Runs the validator with this Blender's Python (the module's interpreter)."""
    return subprocess.run([sys.executable, validator(), "validate", path], capture_output=True,
                          text=True, timeout=120)


class TestPackage(unittest.TestCase):
    def test_layout_and_manifest(self):
        with zipfile.ZipFile(ZIP) as z:
            names = z.namelist()
            manifest = tomllib.loads(z.read("ccnurbs/blender_manifest.toml").decode())
            init = z.read("ccnurbs/__init__.py").decode()
        self.assertEqual({n.split("/")[0] for n in names}, {"ccnurbs"}, "one top folder")
        for f in ("__init__.py", "libccnurbs.so", "modifier.py", "tap.py", "objio.py"):
            self.assertIn("ccnurbs/" + f, names)
        self.assertIn("bl_info", init)  # legacy install (3.x)
        for key in ("schema_version", "id", "version", "name", "tagline", "maintainer", "type",
                    "blender_version_min", "license", "platforms"):
            self.assertIn(key, manifest)
        self.assertEqual(manifest["id"], "ccnurbs")
        self.assertEqual(manifest["platforms"], ["linux-x64"], "native libraries are linux-x64")
        self.assertIn("files", manifest.get("permissions", {}), "OBJ import/export reads files")
        libs = [n for n in names if n.endswith(".so") or ".so." in n]
        self.assertTrue(all(n.count("/") == 1 for n in libs), libs)

    def test_blender_validator(self):
        if validator() is None:
            self.assertLess(bpy.app.version, (4, 2, 0), "4.2+ must ship the validator")
            return  # 3.x has no extension platform; the layout test covers the package
        r = validate(ZIP)
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        bad = os.path.join(TMP, "bad_manifest.zip")
        with zipfile.ZipFile(ZIP) as src, zipfile.ZipFile(bad, "w") as dst:
            for item in src.infolist():
                data = src.read(item)
                if item.filename.endswith("blender_manifest.toml"):
                    data = data.replace(b'id = "ccnurbs"', b'id = "not a valid id!"')
                dst.writestr(item, data)
        r = validate(bad)
        self.assertNotEqual(r.returncode, 0, "a broken manifest passed validation")

    def test_installed_as(self):
        name = sys.modules[type(ccn).module].__name__
        if EXTENSIONS:
            self.assertEqual(name, "bl_ext.user_default.ccnurbs")
        else:
            self.assertEqual(name, "ccnurbs")


class TestSources(unittest.TestCase):
    """Python standards of the add-on, checked on the shipped sources: no module over 800
    lines, no import cycle among its modules (imports inside functions included)."""

    def _sources(self):
        with zipfile.ZipFile(ZIP) as z:
            return {n.split("/")[1][:-3]: z.read(n).decode() for n in z.namelist()
                    if n.endswith(".py")}

    def test_small_modules(self):
        for name, text in self._sources().items():
            self.assertLessEqual(text.count("\n"), 800, name)

    def test_no_import_cycles(self):
        import ast
        src = self._sources()
        graph = {}
        for name, text in src.items():
            deps = set()
            for node in ast.walk(ast.parse(text)):
                if isinstance(node, ast.ImportFrom) and node.level == 1:
                    if node.module:
                        deps.add(node.module.split(".")[0])
                    else:
                        deps.update(a.name for a in node.names)
            graph[name] = deps & set(src) - {name}
        graph.pop("__init__", None)
        state = {}

        def visit(n, path):
            state[n] = 1
            for d in graph.get(n, ()):
                if state.get(d) == 1:
                    self.fail("import cycle: " + " -> ".join(path + [n, d]))
                if d not in state:
                    visit(d, path + [n])
            state[n] = 2
        for n in graph:
            if n not in state:
                visit(n, [])
