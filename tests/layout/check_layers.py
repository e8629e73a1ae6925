#!/usr/bin/env python3
"""The source tree's shape, checked: layers, no dependency circles, file sizes.

C (csrc/): a module is a stem inside a layer folder, X.c and X.h together ("surface/plan"); a
header without a .c of its name is a module of its own. Module A depends on module B when a
file of A #includes a header of B, or when A's object file uses a symbol that B's object file
defines (every file is compiled here with the project's flags and read with `nm`, so calls
through macros, inline code and function pointers count too). Checked:
  1. the dependency graph among modules has no cycle (every strongly connected component is
     one module);
  2. a module depends only on modules of its own layer or of layers below it, in the order of
     LAYERS (csrc/README.md); csrc/include/ccnurbs.h (the public header) may be used by all;
     the CLI (tools) may include only the public header and its own headers;
  3. object file names are unique across the library (static archives keep basenames only);
  4. no file in csrc/ or addon/ has more than MAX_LINES lines.
Python (addon/): module A depends on B when A imports B anywhere (also inside functions):
  5. no import cycle among the add-on's modules.
Prints one line per check and "N passed, N failed"; exit status 1 on any failure.
Usage: check_layers.py [--root TREE] (default: this checkout).
"""
import ast
import collections
import os
import re
import subprocess
import sys
import tempfile

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
if len(sys.argv) == 3 and sys.argv[1] == "--root":  # another tree (the self-test in run_layout.sh)
    ROOT = os.path.abspath(sys.argv[2])
CSRC = os.path.join(ROOT, "csrc")
ADDON = os.path.join(ROOT, "addon")
LAYERS = ["base", "topology", "rules", "refine", "bi5", "fill", "surface", "io", "tools"]
PUBLIC = "include/ccnurbs"
MAX_LINES = 800
CC = os.environ.get("CC", "cc")
CFLAGS = ["-std=c11", "-D_POSIX_C_SOURCE=200809L", "-O0", "-I" + os.path.join(CSRC, "include"),
          "-I" + CSRC]

results = []


def report(ok, label, detail=""):
    results.append(ok)
    print("%-4s %-34s %s" % ("ok" if ok else "FAIL", label, detail))


def c_files():
    out = []
    for layer in LAYERS + ["include"]:
        d = os.path.join(CSRC, layer)
        if not os.path.isdir(d):
            continue
        for f in sorted(os.listdir(d)):
            if f.endswith((".c", ".h")):
                out.append(layer + "/" + f)
    return out


def module_of(rel):
    return os.path.splitext(rel)[0]


def layer_of(mod):
    return mod.split("/")[0]


INCLUDE_RE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.M)


def include_edges(files):
    edges = collections.defaultdict(set)
    problems = []
    for rel in files:
        text = open(os.path.join(CSRC, rel), encoding="utf-8").read()
        for inc in INCLUDE_RE.findall(text):
            cand = [os.path.normpath(os.path.join(os.path.dirname(rel), inc)), inc,
                    "include/" + inc]
            target = next((c for c in cand if os.path.isfile(os.path.join(CSRC, c))), None)
            if target is None:
                problems.append("%s includes \"%s\", which is not in csrc/" % (rel, inc))
                continue
            if module_of(target) != module_of(rel):
                edges[module_of(rel)].add(module_of(target))
    return edges, problems


def symbol_edges(files):
    """Compiles every .c file and maps undefined symbols to the module defining them."""
    defs, uses, problems = {}, collections.defaultdict(set), []
    with tempfile.TemporaryDirectory() as tmp:
        for rel in files:
            if not rel.endswith(".c"):
                continue
            obj = os.path.join(tmp, rel.replace("/", "__") + ".o")
            r = subprocess.run([CC] + CFLAGS + ["-c", os.path.join(CSRC, rel), "-o", obj],
                               capture_output=True, text=True)
            if r.returncode:
                problems.append("%s does not compile: %s" % (rel, r.stderr.strip()[:300]))
                continue
            nm = subprocess.run(["nm", obj], capture_output=True, text=True).stdout
            for line in nm.splitlines():
                p = line.split()
                if len(p) == 3 and p[1] in "TDBRC":
                    if p[2] in defs and defs[p[2]] != module_of(rel):
                        problems.append("%s is defined in %s and %s" % (p[2], defs[p[2]], rel))
                    defs[p[2]] = module_of(rel)
                elif len(p) == 2 and p[0] == "U":
                    uses[module_of(rel)].add(p[1])
    edges = collections.defaultdict(set)
    for mod, syms in uses.items():
        for s in syms:
            if s in defs and defs[s] != mod:
                edges[mod].add(defs[s])
    return edges, problems


def cycles(nodes, edges):
    """Strongly connected components with more than one node (Tarjan)."""
    index, low, stack, on, out, counter = {}, {}, [], set(), [], [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in sorted(edges.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    sys.setrecursionlimit(10000)
    for v in sorted(nodes):
        if v not in index:
            visit(v)
    return out


def check_c():
    files = c_files()
    inc, p1 = include_edges(files)
    sym, p2 = symbol_edges(files)
    report(not p1, "C includes resolve", "; ".join(p1))
    report(not p2, "C files compile, symbols unique", "; ".join(p2))
    edges = collections.defaultdict(set)
    for e in (inc, sym):
        for a, bs in e.items():
            edges[a] |= bs
    mods = {module_of(f) for f in files}
    cyc = cycles(mods, edges)
    report(not cyc, "no C dependency circle",
           "; ".join(" <-> ".join(c) for c in cyc) or "%d modules" % len(mods))
    bad = []
    for a in sorted(edges):
        for b in sorted(edges[a]):
            la, lb = layer_of(a), layer_of(b)
            if b == PUBLIC:
                continue
            if la == "include":
                bad.append("%s (public header) uses %s" % (a, b))
            elif la == "tools" and lb != "tools" and b in inc.get(a, set()):
                bad.append("%s includes the internal header %s" % (a, b))
            elif lb not in LAYERS or LAYERS.index(lb) > LAYERS.index(la):
                bad.append("%s (layer %s) uses %s (layer %s, above it)" % (a, la, b, lb))
    report(not bad, "C layers point downwards", "; ".join(bad) or " < ".join(LAYERS))
    lib = [f for f in files if f.endswith(".c") and layer_of(f) != "tools"]
    names = collections.Counter(os.path.basename(f) for f in lib)
    dup = sorted(n for n, k in names.items() if k > 1)
    report(not dup, "library object names unique", ", ".join(dup))
    return edges


def check_sizes():
    big = []
    for base in (CSRC, ADDON):
        for d, _, fs in os.walk(base):
            for f in fs:
                if f.endswith((".c", ".h", ".py")):
                    p = os.path.join(d, f)
                    with open(p, encoding="utf-8") as fh:
                        n = sum(1 for _ in fh)
                    if n > MAX_LINES:
                        big.append("%s: %d lines" % (os.path.relpath(p, ROOT), n))
    report(not big, "files <= %d lines" % MAX_LINES, "; ".join(big))


def check_addon():
    mods = {f[:-3] for f in os.listdir(ADDON) if f.endswith(".py")}
    edges = collections.defaultdict(set)
    for m in mods:
        tree = ast.parse(open(os.path.join(ADDON, m + ".py"), encoding="utf-8").read())
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom) and node.level >= 1:
                if node.module:
                    target = node.module.split(".")[0]
                    if target in mods:
                        edges[m].add(target)
                else:
                    for a in node.names:
                        if a.name in mods:
                            edges[m].add(a.name)
    for m in edges:
        edges[m].discard(m)
    cyc = cycles(mods, edges)
    report(not cyc, "no add-on import circle",
           "; ".join(" <-> ".join(c) for c in cyc) or "%d modules" % len(mods))


def main():
    check_c()
    check_sizes()
    check_addon()
    fails = results.count(False)
    print("%d passed, %d failed" % (len(results) - fails, fails))
    return 1 if fails else 0


if __name__ == "__main__":
    sys.exit(main())
