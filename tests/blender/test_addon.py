"""Headless tests of the CCNURBS Blender add-on (unittest inside Blender's Python), one file that
runs the same way in Blender the program and in Blender the `bpy` module:

    blender --background --factory-startup --python-exit-code 1 \
            --python tests/blender/test_addon.py -- build/ccnurbs.zip build/ccnurbs TMPDIR
    python tests/blender/test_addon.py build/ccnurbs.zip build/ccnurbs TMPDIR   # venv with bpy

(tests/blender/run_blender.sh runs it on every installed version with throw-away user dirs.)
As a module there is no --factory-startup: factory settings are loaded first. Installs the add-on
from the zip (3.x: legacy add-on install; 4.2+: the extension API, after validating the package),
then runs the case_*.py modules in order; TestZ* last. Prints "N passed, N failed".
"""
import os
import sys
import time
import unittest

import bpy

if not bpy.app.binary_path:  # the bpy module: no command line, so reset to factory settings here
    bpy.ops.wm.read_factory_settings(use_empty=True)
print("CCNURBS test Blender %s" % bpy.app.version_string.split()[0])
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bltest  # noqa: E402

CASES = ("case_package", "case_knots", "case_modifier", "case_creases", "case_primitives",
         "case_stack", "case_animation", "case_files", "case_scenes", "case_objio", "case_values",
         "case_uv",
         "case_cad_export", "case_storm", "case_zenable")


class _Result(unittest.TestResult):
    """Collects (status, test id, traceback) for the summary printed after the run."""

    def __init__(self, *a, **kw):
        super().__init__(*a, **kw)
        self.rows = []
        self.secs = {}  # test id -> wall seconds (printed with its line: the slow ones show)
        self._t0 = 0.0

    def startTest(self, test):
        super().startTest(test)
        self._t0 = time.perf_counter()

    def stopTest(self, test):
        self.secs[test.id()] = time.perf_counter() - self._t0
        super().stopTest(test)

    def addSuccess(self, test):
        super().addSuccess(test)
        self.rows.append(("ok", test, ""))

    def addFailure(self, test, err):
        super().addFailure(test, err)
        self.rows.append(("FAIL", test, self.failures[-1][1]))

    def addError(self, test, err):
        super().addError(test, err)
        self.rows.append(("ERROR", test, self.errors[-1][1]))

    def addSubTest(self, test, subtest, err):
        super().addSubTest(test, subtest, err)
        if err is not None:
            kind, lst = ("FAIL", self.failures) if issubclass(err[0], test.failureException) \
                else ("ERROR", self.errors)
            self.rows.append((kind, subtest, lst[-1][1]))


def _tests(suite):
    for t in suite:
        if isinstance(t, unittest.TestSuite):
            yield from _tests(t)
        else:
            yield t


def main():
    bltest.install()
    loader = unittest.defaultTestLoader
    suite = unittest.TestSuite()
    only = os.environ.get("CCN_CASES")  # e.g. "case_creases": run only these (development)
    for name in (only.split(",") if only else CASES):
        try:
            mod = __import__(name)
        except ImportError as e:
            if getattr(e, "name", None) == name:  # a case module not written yet
                continue
            raise
        suite.addTests(loader.loadTestsFromModule(mod))
    pick = os.environ.get("CCN_TEST")  # e.g. "test_linked": only tests whose id holds it
    if pick:
        suite = unittest.TestSuite(t for t in _tests(suite) if pick in t.id())
    result = _Result()
    suite.run(result)
    failed_ids = {t.id() for k, t, _ in result.rows if k != "ok"}
    print("== CCNURBS blender tests ==")
    for kind, test, tb in result.rows:
        name = test.id().replace("__main__.", "")
        if kind == "ok" and test.id() in failed_ids:
            continue  # a test with a failing subtest is reported as failing
        secs = result.secs.get(test.id())
        print("%-5s %s%s" % (kind, name, " (%.1f s)" % secs if secs is not None else ""))
        if tb:
            print("      " + tb.rstrip().replace("\n", "\n      "))
    failed = len({t.id() for k, t, _ in result.rows if k != "ok"} |
                 {t.id() for t, _ in result.failures + result.errors})
    print("%d passed, %d failed" % (result.testsRun - min(failed, result.testsRun), failed))
    sys.stdout.flush()
    sys.stderr.flush()
    if bpy.app.binary_path:
        if failed:
            raise SystemExit(1)
        return
    # the module: no Blender exit code to set; and bpy 4.2 frees the UI classes add-ons
    # registered in its C++ exit handlers, after Python is finalized (bpy_class_free ->
    # PyGILState_Ensure on no interpreter: SIGSEGV, with any add-on that has a panel), which
    # os._exit skips
    os._exit(1 if failed else 0)


main()
