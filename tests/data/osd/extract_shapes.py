#!/usr/bin/env python3
"""Rebuilds OBJ files from OpenSubdiv's regression shapes and classifies them.

    extract_shapes.py SRC OUTDIR        write OUTDIR/catmark_*.obj (+ LICENSE.txt)
    extract_shapes.py --table SRC       print the README table (markdown) to stdout
    extract_shapes.py --scope SRC       print the in-scope shape names, one a line
    extract_shapes.py --refused SRC     print the shapes ccnurbs must refuse: a face that
                                        repeats a vertex (a degenerate face, which no mesh
                                        editor keeps)

SRC is either OpenSubdiv's regression/shapes directory (catmark_*.h, each a C/C++ string
literal holding the OBJ text, possibly split into std::string(...) + std::string(...)
pieces) or a directory of catmark_*.obj files already extracted.

The OBJ text is written exactly as the string literal holds it (escapes \\n \\" \\\\ \\t
decoded), after one header comment naming the source and licence; nothing is dropped, so
`v`, `vt`, `vn`, `f a/b/c` and the `t name nints/nfloats/nstrings ...` tag lines are as in
OpenSubdiv. LICENSE.txt is copied from SRC/../../LICENSE.txt when it is there.

Scope: a shape is in scope when its tags are only crease, corner, interpolateboundary,
creasemethod (facevaryinginterpolateboundary is allowed too: it changes face-varying data
only) and no face repeats a vertex. Non-manifold topology is in scope (ccnurbs reads it as
OpenSubdiv does: edges with more than two faces or used twice in one direction, bowtie
vertices, vertices no face uses); the table names it.
"""
import os
import re
import sys
from collections import defaultdict

ALLOWED_TAGS = {"crease", "corner", "interpolateboundary", "creasemethod",
                "facevaryinginterpolateboundary"}
EDIT_TAGS = {"vertexedit", "edgeedit", "faceedit"}

_STR = re.compile(r'"((?:[^"\\\n]|\\.)*)"')
_ESC = {"n": "\n", "t": "\t", '"': '"', "\\": "\\", "'": "'"}


def header_text(path):
    """The OBJ text held by the string literals of an OpenSubdiv shape header."""
    body = []
    with open(path, encoding="utf-8") as f:
        for line in f:
            if line.lstrip().startswith("//"):
                continue
            body.append(line)
    text = "".join(body)
    start = text.find("=")
    if start < 0:
        raise ValueError(f"{path}: no '=' (not a shape header?)")
    out = []
    for m in _STR.finditer(text, start):
        s = m.group(1)
        out.append(re.sub(r"\\(.)", lambda e: _ESC.get(e.group(1), "\\" + e.group(1)), s))
    if not out:
        raise ValueError(f"{path}: no string literal")
    return "".join(out)


def load_shapes(src):
    """{name: obj_text} for every catmark_* shape in src (.h preferred over .obj)."""
    shapes = {}
    names = sorted(os.listdir(src))
    for fn in names:
        if fn.startswith("catmark_") and fn.endswith(".h"):
            shapes[fn[:-2]] = header_text(os.path.join(src, fn))
    if not shapes:
        for fn in names:
            if fn.startswith("catmark_") and fn.endswith(".obj"):
                with open(os.path.join(src, fn), encoding="utf-8") as f:
                    shapes[fn[:-4]] = f.read()
    return shapes


def parse(text):
    """(nverts, nvt, faces as 0-based vertex lists, face token forms, tags)."""
    nv = nvt = 0
    faces, forms, tags = [], set(), []
    for line in text.splitlines():
        tok = line.split()
        if not tok:
            continue
        if tok[0] == "v":
            nv += 1
        elif tok[0] == "vt":
            nvt += 1
        elif tok[0] == "f":
            face = []
            for t in tok[1:]:
                parts = t.split("/")
                labels = ("v", "vt", "vn")
                forms.add("/".join(labels[i] if p else "" for i, p in enumerate(parts[:3])))
                i = int(parts[0])
                face.append(i - 1 if i > 0 else nv + i)
            faces.append(face)
        elif tok[0] == "t" and len(tok) >= 3:
            counts = [int(c) for c in tok[2].split("/")]
            ni, nf = counts[0], counts[1]
            ns = counts[2] if len(counts) > 2 else 0
            args = tok[3:]
            tags.append((tok[1], [int(a) for a in args[:ni]],
                         [float(a) for a in args[ni:ni + nf]], args[ni + nf:ni + nf + ns]))
    return nv, nvt, faces, forms, tags


def topology_problems(nv, faces):
    """Reasons the mesh is not a manifold (empty list if it is)."""
    probs = []
    edge_faces = defaultdict(list)       # undirected edge -> [(face, directed?)]
    vert_faces = defaultdict(list)
    rep = [fi for fi, f in enumerate(faces) if len(set(f)) != len(f)]
    if rep:
        probs.append(f"{len(rep)} face(s) repeating a vertex (e.g. face {rep[0] + 1})")
    for fi, f in enumerate(faces):
        for k, a in enumerate(f):
            b = f[(k + 1) % len(f)]
            edge_faces[(min(a, b), max(a, b))].append((fi, a < b))
            vert_faces[a].append(fi)
    bad_e = [e for e, fs in edge_faces.items() if len(fs) > 2]
    if bad_e:
        probs.append(f"{len(bad_e)} edge(s) with more than 2 faces "
                     f"(e.g. {bad_e[0][0] + 1}-{bad_e[0][1] + 1})")
    flip = [e for e, fs in edge_faces.items() if len(fs) == 2 and fs[0][1] == fs[1][1]]
    if flip:
        probs.append(f"{len(flip)} edge(s) used twice in the same direction "
                     f"(e.g. {flip[0][0] + 1}-{flip[0][1] + 1})")
    unused = [v for v in range(nv) if v not in vert_faces]
    if unused:
        probs.append(f"{len(unused)} vertex/vertices used by no face (e.g. {unused[0] + 1})")
    # bowtie: the faces around a vertex, joined through shared edges at that vertex, must form
    # one connected fan
    bow = []
    for v, fs in vert_faces.items():
        fs = sorted(set(fs))
        parent = {f: f for f in fs}

        def find(x):
            while parent[x] != x:
                parent[x] = parent[parent[x]]
                x = parent[x]
            return x
        for f in fs:
            face = faces[f]
            k = face.index(v)
            for w in (face[k - 1], face[(k + 1) % len(face)]):
                for g, _ in edge_faces[(min(v, w), max(v, w))]:
                    if g in parent:
                        parent[find(g)] = find(f)
        if len({find(f) for f in fs}) > 1:
            bow.append(v)
    if bow:
        probs.append(f"{len(bow)} bowtie vertex/vertices (e.g. {bow[0] + 1})")
    return probs


def interior_valence2(nv, faces):
    """Interior vertices with exactly 2 edges (and 2 faces)."""
    edges = defaultdict(set)
    vf = defaultdict(int)
    ef = defaultdict(int)
    for f in faces:
        for k, a in enumerate(f):
            b = f[(k + 1) % len(f)]
            edges[a].add(b)
            edges[b].add(a)
            vf[a] += 1
            ef[(min(a, b), max(a, b))] += 1
    out = []
    for v in range(nv):
        if len(edges[v]) == 2 and vf[v] == 2 and \
                all(ef[(min(v, w), max(v, w))] == 2 for w in edges[v]):
            out.append(v)
    return out


def classify(name, text):
    nv, nvt, faces, forms, tags = parse(text)
    names = [t[0] for t in tags]
    reasons = []
    if "hole" in names:
        reasons.append("holes")
    if EDIT_TAGS & set(names):
        reasons.append("hierarchical edits")
    if "smoothtriangles" in names:
        reasons.append("smoothtriangles")
    other = sorted(set(names) - ALLOWED_TAGS - EDIT_TAGS - {"hole", "smoothtriangles"})
    if other:
        reasons.append("tags " + ", ".join(other))
    probs = topology_problems(nv, faces)
    degenerate = [p for p in probs if "repeating a vertex" in p]
    if degenerate:
        reasons.append("degenerate: " + "; ".join(probs))
    info = {
        "nv": nv, "nf": len(faces), "nvt": nvt,
        "forms": sorted(forms, key=len),
        "sizes": sorted({len(f) for f in faces}),
        "val2": len(interior_valence2(nv, faces)),
        "tags": tags,
        "reasons": reasons,
        "nonmanifold": [] if degenerate else probs,
    }
    return info


def tag_summary(tags):
    count = defaultdict(int)
    detail = {}
    for name, ints, floats, strs in tags:
        count[name] += 1
        if name == "interpolateboundary":
            mode = {0: "none", 1: "edge-and-corner", 2: "edge-only"}.get(ints[0] if ints else -1, "?")
            detail[name] = f"interpolateboundary {ints[0] if ints else '?'} ({mode})"
        elif name == "facevaryinginterpolateboundary":
            detail[name] = f"fvarinterpolateboundary {ints[0] if ints else '?'}"
        elif name == "creasemethod":
            detail[name] = f"creasemethod {strs[0] if strs else '?'}"
    parts = []
    for name in sorted(count):
        if name in detail:
            parts.append(detail[name])
        else:
            s = sorted({x for t in tags if t[0] == name for x in t[2]})
            sh = (" s=" + ",".join(f"{x:g}" for x in s)) if s else ""
            parts.append(f"{name} x{count[name]}{sh}")
    return "; ".join(parts) if parts else "-"


def main(argv):
    mode = "write"
    if argv and argv[0] in ("--table", "--scope", "--refused"):
        mode = argv.pop(0)
    if (mode == "write" and len(argv) != 2) or (mode != "write" and len(argv) != 1):
        sys.stderr.write(__doc__)
        return 2
    src = argv[0]
    shapes = load_shapes(src)
    if not shapes:
        sys.stderr.write(f"extract_shapes: no catmark_*.h or catmark_*.obj in {src}\n")
        return 2
    if mode == "write":
        out = argv[1]
        os.makedirs(out, exist_ok=True)
        for name, text in shapes.items():
            with open(os.path.join(out, name + ".obj"), "w", encoding="utf-8") as f:
                f.write(f"# {name}: OpenSubdiv regression/shapes/{name}.h, Copyright 2013 Pixar,"
                        " Modified Apache 2.0 License (LICENSE.txt)\n")
                f.write(text)
        lic = os.path.join(src, "..", "..", "LICENSE.txt")
        if os.path.isfile(lic):
            with open(lic, encoding="utf-8") as f, \
                    open(os.path.join(out, "LICENSE.txt"), "w", encoding="utf-8") as g:
                g.write(f.read())
        print(f"extract_shapes: {len(shapes)} shapes written to {out}")
        return 0
    rows = {name: classify(name, text) for name, text in shapes.items()}
    if mode == "--scope":
        for name, r in rows.items():
            if not r["reasons"]:
                print(name)
        return 0
    if mode == "--refused":
        for name, text in shapes.items():
            nv, nvt, faces, forms, tags = parse(text)
            if any("repeating a vertex" in p for p in topology_problems(nv, faces)):
                print(name)
        return 0
    print("| shape | verts | faces | face sizes | `f` forms | vt | interior val-2 | tags | in scope |")
    print("|---|---|---|---|---|---|---|---|---|")
    for name, r in rows.items():
        scope = "yes" if not r["reasons"] else "no: " + "; ".join(r["reasons"])
        if not r["reasons"] and r["nonmanifold"]:
            scope += " (non-manifold: " + "; ".join(r["nonmanifold"]) + ")"
        print(f"| {name} | {r['nv']} | {r['nf']} | {','.join(map(str, r['sizes']))} | "
              f"{' '.join(r['forms'])} | {r['nvt']} | {r['val2'] or '-'} | "
              f"{tag_summary(r['tags'])} | {scope} |")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
