#!/usr/bin/env python3
"""The exported faces, evaluated by OpenCASCADE, against `ccnurbs limit` and `ccnurbs patches`
(test-only; numpy). Independent of the export: the limit samples' parameters come from the
documented order of ccn_plan_evaluate's output (each level's faces are the previous level's
faces' corners in order: face q at level l >= 2 is corner q % 4 of face q // 4; at level 1 the
corners of the cage faces in order), the patches' values from a Bernstein evaluation here.

  export_check.py --cage C.obj --limit C.lim.obj --map C.map [--patches C.bv]
                  [--fallback FACES] --occt build/occt_read FILE.step|FILE.igs ...

occt_read runs once per file, with --eval and (--fallback FACES) its full report, which is
written to FILE.rep for the caller's checks (its warnings to FILE.rep.warn).

For every limit vertex, every place (cage face, sub-quad, s, t) it has; the face map's cells
containing it give the face and its (u, v); OpenCASCADE evaluates those (occt_read --eval)
and the distance to the limit sample is taken, apart for fill faces (counted fallbacks).
Patch faces (the plan's own bicubic / bi-5 patches) are also evaluated on a 4x4 grid against
the Bernstein form of `ccnurbs patches`' control points.

Creases: every edge OpenCASCADE has with two faces (occt_read --edges: the uv of its middle on
each face and its normal angles) is located on the cage through the face map; an edge lying on
a cage edge that the cage file makes infinitely sharp (`# crease i j s` or OpenSubdiv's
`t crease`, s >= 10) is a crease: C0 by design, its angles reported apart (smallest, largest),
not as G1 deviations. smooth_angle_max covers the other edges except those of fill faces,
fill_angle_max the fill faces' (per side of a crease). Prints "key: value" per file.
"""
import argparse
import os
import subprocess
import sys
import tempfile

import numpy as np

UNIT = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
FILL = 4  # CCN_EXPORT_FACE_FILL


def read_cage_sizes(path):
    sizes = []
    for line in open(path):
        if line.startswith("f "):
            sizes.append(len(line.split()) - 1)
    return sizes


def read_cage_creases(path):
    """Face vertex lists (0-based) and the infinitely sharp edges {(a, b)} of an OBJ cage."""
    faces, sharp, nv = [], set(), 0

    def num(x):
        return float("inf") if x.lower() in ("inf", "+inf") else float(x)
    for line in open(path):
        w = line.split()
        if not w:
            continue
        if w[0] == "v":
            nv += 1
        elif w[0] == "f":
            idx = [int(t.split("/")[0]) for t in w[1:]]
            faces.append([i - 1 if i > 0 else nv + i for i in idx])
        elif w[0] == "#" and len(w) >= 5 and w[1] == "crease" and w[2].lstrip("-").isdigit():
            if num(w[4]) >= 10:
                a, b = int(w[2]) - 1, int(w[3]) - 1
                sharp.add((min(a, b), max(a, b)))
        elif w[0] == "t" and len(w) >= 3 and w[1] == "crease":
            ni, nf = [int(x) for x in w[2].split("/")[:2]]
            ints, vals = [int(x) for x in w[3:3 + ni]], [num(x) for x in w[3 + ni:3 + ni + nf]]
            for k in range(ni // 2):
                if (vals[k] if nf > 1 else vals[0]) >= 10:
                    a, b = ints[2 * k], ints[2 * k + 1]
                    sharp.add((min(a, b), max(a, b)))
    return faces, sharp


def cage_edge_at(faces, c, sub, st, tol=1e-6):
    """The cage edge (a, b) that the local point st of place (c, sub) lies on, or None."""
    f, n = faces[c], len(faces[c])
    s, t = st
    if sub < 0:  # quad: t=0 side 0, s=1 side 1, t=1 side 2, s=0 side 3
        side = 0 if abs(t) < tol else 1 if abs(s - 1) < tol else 2 if abs(t - 1) < tol else 3 if abs(s) < tol else -1
    elif abs(t) < tol:  # corner 0 (the cage vertex) to 1: half-edge sub
        side = sub
    elif abs(s) < tol:  # corner 3 to 0: the previous half-edge
        side = (sub + n - 1) % n
    else:
        side = -1
    if side < 0:
        return None
    a, b = f[side], f[(side + 1) % n]
    return (min(a, b), max(a, b))


def place_in_face(face, u, v, tol=1e-6):
    """(cage face, sub, local st) of parameter (u, v) of a mapped export face: the cell that
    contains it, or is nearest to it within tol x the cell's size (OpenCASCADE's pcurves of
    edges lie within its tolerance of the face's parameter range: measured 2.6e-9 outside)."""
    best, bd = None, float("inf")
    for (c, sub, uv, st) in face["cells"]:
        x = (u - uv[0]) / (uv[1] - uv[0])
        y = (v - uv[2]) / (uv[3] - uv[2])
        d = max(0.0, -x, x - 1, -y, y - 1)
        if d < bd:
            best, bd = (c, sub, st, min(max(x, 0.0), 1.0), min(max(y, 0.0), 1.0)), d
    if best is None or bd > tol:
        return None
    c, sub, st, x, y = best
    return c, sub, st[0] + x * (st[1] - st[0]) + y * (st[2] - st[0])


def edge_report(tag, path, faces, cage_faces, sharp, kind):
    """Crease edges and normal angles from occt_read --edges."""
    byidx = {f["index"]: f for f in faces}
    n_crease, cmin, cmax, smooth, fill, bad = 0, float("inf"), 0.0, 0.0, 0.0, 0
    for line in open(path):
        w = line.split()
        fa, fb = int(w[0]), int(w[1])
        ua, va, ub, vb, amax, amin = [float(x) for x in w[2:8]]
        on = []
        for (fi, u, v) in ((fa, ua, va), (fb, ub, vb)):
            p = place_in_face(byidx[fi], u, v) if fi in byidx else None
            on.append(cage_edge_at(cage_faces, p[0], p[1], p[2]) if p else None)
        if on[0] != on[1]:
            bad += 1
        if on[0] is not None and on[0] in sharp:
            n_crease += 1
            cmin, cmax = min(cmin, amin), max(cmax, amax)
        elif kind.get(fa) == FILL or kind.get(fb) == FILL:
            fill = max(fill, amax)
        else:
            smooth = max(smooth, amax)
    print("%s_crease_edges: %d\n%s_crease_angle_min: %.6e\n%s_crease_angle_max: %.6e\n"
          "%s_smooth_angle_max: %.6e\n%s_fill_angle_max: %.6e\n%s_edges_located_apart: %d" % (
              tag, n_crease, tag, cmin if n_crease else 0.0, tag, cmax, tag, smooth, tag, fill, tag, bad))


def read_limit(path):
    level, V, N, F = None, [], [], []
    for line in open(path):
        if line.startswith("# ccnurbs limit level"):
            level = int(line.split()[4].rstrip(":"))
        elif line.startswith("v "):
            V.append([float(x) for x in line.split()[1:4]])
        elif line.startswith("vn "):
            N.append([float(x) for x in line.split()[1:4]])
        elif line.startswith("f "):
            F.append([int(x.split("/")[0]) - 1 for x in line.split()[1:]])
    return level, np.array(V), np.array(N), np.array(F, dtype=np.int64)


def limit_places(sizes, level, F):
    """Per limit vertex, its places {(cage face, sub): [(s, t), ...]} from every face around it."""
    if level < 1:
        raise SystemExit("export_check: the limit must be of level >= 1")
    start = np.concatenate([[0], np.cumsum(sizes)])
    places = {}
    for q in range(len(F)):
        chain, f = [], q
        for _ in range(level, 1, -1):
            chain.append(f % 4)
            f //= 4
        c = int(np.searchsorted(start, f, side="right") - 1)
        j1 = f - start[c]
        chain.reverse()
        if sizes[c] == 4:
            sub, p = -1, np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
            chain = [j1] + chain
        else:
            sub, p = int(j1), np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
        for j in chain:
            A = lambda x: p[0] + x[0] * (p[1] - p[0]) + x[1] * (p[2] - p[0])
            a, b, d = UNIT[j], UNIT[(j + 1) % 4], UNIT[(j + 3) % 4]
            p = np.array([A(a), A((a + b) / 2), A((a + d) / 2)])
        corners = [p[0], p[1], p[1] + p[2] - p[0], p[2]]
        for k in range(4):
            key = (c, sub)
            places.setdefault(key, {})
            places[key][(round(corners[k][0] * 2.0**40), round(corners[k][1] * 2.0**40))] = (F[q][k], corners[k])
    return places


def read_map(path):
    faces, cur = [], None
    for line in open(path):
        w = line.split()
        if w[0] == "F":
            cur = {"index": int(w[1]), "kind": int(w[2]), "patch": int(w[3]), "cells": []}
            faces.append(cur)
        else:
            cur["cells"].append((int(w[1]), int(w[2]), [float(x) for x in w[3:7]],
                                 np.array([float(x) for x in w[7:13]]).reshape(3, 2)))
    return faces


def read_bv(path):
    tok = open(path).read().split()
    i, pats = 0, []
    while i < len(tok):
        assert tok[i] == "4"
        d = int(tok[i + 1])
        n = (d + 1) ** 2
        pts = np.array([float(x) for x in tok[i + 2:i + 2 + 3 * n]]).reshape(d + 1, d + 1, 3)
        pats.append(pts)
        i += 2 + 3 * n
    return pats


def bernstein(d, t):
    from math import comb
    return np.array([comb(d, k) * t**k * (1 - t) ** (d - k) for k in range(d + 1)])


def requests(faces, places):
    """(face, u, v, vertex) for every limit vertex place inside a cell."""
    cells = {}
    for f in faces:
        for (c, sub, uv, st) in f["cells"]:
            cells.setdefault((c, sub), []).append((f["index"], uv, st))
    req, matched = [], set()
    for key, pts in places.items():
        if key not in cells:
            continue
        S = np.array([p[1] for p in pts.values()])
        vid = np.array([p[0] for p in pts.values()])
        for (fi, uv, st) in cells[key]:
            e1, e2 = st[1] - st[0], st[2] - st[0]
            M = np.array([[e1[0], e2[0]], [e1[1], e2[1]]])
            xy = np.linalg.solve(M, (S - st[0]).T).T
            ok = np.all((xy > -1e-9) & (xy < 1 + 1e-9), axis=1)
            for i in np.nonzero(ok)[0]:
                x, y = np.clip(xy[i], 0, 1)
                req.append((fi, uv[0] + x * (uv[1] - uv[0]), uv[2] + y * (uv[3] - uv[2]), int(vid[i])))
                matched.add(int(vid[i]))
    return req, matched


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--cage", required=True)
    ap.add_argument("--limit", required=True)
    ap.add_argument("--map", required=True)
    ap.add_argument("--patches")
    ap.add_argument("--occt", required=True)
    ap.add_argument("--fallback")
    ap.add_argument("files", nargs="+")
    a = ap.parse_args()
    sizes = read_cage_sizes(a.cage)
    cage_faces, sharp = read_cage_creases(a.cage)
    level, V, N, F = read_limit(a.limit)
    places = limit_places(sizes, level, F)
    faces = read_map(a.map)
    req, matched = requests(faces, places)
    size = float(np.linalg.norm(V.max(axis=0) - V.min(axis=0)))
    kind = {f["index"]: f["kind"] for f in faces}
    pats = read_bv(a.patches) if a.patches else []
    G = [0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0]
    preq = [(f["index"], u, v, f["patch"]) for f in faces if f["patch"] >= 0 and f["patch"] < len(pats)
            for u in G for v in G]
    sampled = {r[0] for r in req}
    print("limit_level: %d\nlimit_vertices: %d\nunmatched_vertices: %d\nsize: %.9g" % (
        level, len(V), len(V) - len(matched), size))
    print("faces: %d\nfaces_with_samples: %d\nfaces_patch_checked: %d\nfaces_unchecked: %d" % (
        len(faces), len(sampled), len({r[0] for r in preq}),
        len([f for f in faces if f["index"] not in sampled and f["patch"] < 0])))
    with tempfile.TemporaryDirectory() as T:
        rq = os.path.join(T, "req")
        with open(rq, "w") as o:
            for r in req + [(p[0], p[1], p[2], -1) for p in preq]:
                o.write("%d %.17g %.17g\n" % (r[0], r[1], r[2]))
        for path in a.files:
            rs = os.path.join(T, "res")
            ed = os.path.join(T, "edges")
            cmd = [a.occt] + (["--fallback", a.fallback] if a.fallback else []) + ["--eval", rq, "--out", rs,
                                                                                    "--edges", ed, path]
            with open(path + ".rep", "w") as rep, open(path + ".rep.warn", "w") as warn:
                p = subprocess.run(cmd, stdout=rep, stderr=warn)
            tag = "iges" if path.endswith((".igs", ".iges")) else "step"
            if p.returncode != 0:
                print("%s_eval: failed" % tag)
                continue
            edge_report(tag, ed, faces, cage_faces, sharp, kind)
            R = np.loadtxt(rs, ndmin=2)
            n = len(req)
            X = R[:n, 3:6]
            L = V[[r[3] for r in req]]
            d = np.linalg.norm(X - L, axis=1)
            isfill = np.array([kind[r[0]] == FILL for r in req], dtype=bool)
            nrm = R[:n, 6:9]
            good = (np.linalg.norm(nrm, axis=1) > 0.5) & ~isfill
            LN = N[[r[3] for r in req]]
            cr = np.linalg.norm(np.cross(nrm[good], LN[good]), axis=1)
            ang = np.arctan2(cr, np.sum(nrm[good] * LN[good], axis=1)) if good.any() else np.zeros(1)
            print("%s_samples: %d\n%s_max_dist: %.3e\n%s_max_rel_dist: %.3e\n%s_fill_samples: %d\n"
                  "%s_fill_max_rel_dist: %.3e\n%s_max_normal_angle: %.3e" % (
                      tag, int((~isfill).sum()), tag, d[~isfill].max() if (~isfill).any() else 0.0,
                      tag, (d[~isfill].max() if (~isfill).any() else 0.0) / size, tag, int(isfill.sum()),
                      tag, (d[isfill].max() if isfill.any() else 0.0) / size, tag, float(ang.max())))
            if preq:
                P = R[n:, 3:6]
                err = 0.0
                for i, (fi, u, v, pi) in enumerate(preq):
                    B = pats[pi]
                    dd = B.shape[0] - 1
                    x = np.einsum("i,j,ijk->k", bernstein(dd, u), bernstein(dd, v), B)
                    err = max(err, float(np.linalg.norm(P[i] - x)))
                print("%s_patch_max_rel_dist: %.3e" % (tag, err / size))


if __name__ == "__main__":
    main()
