#!/usr/bin/env python3
"""The exported faces, evaluated by OpenCASCADE, against `ccnurbs limit` and `ccnurbs patches`
(test-only; numpy). Independent of the export: the limit samples' parameters come from the
documented order of ccn_plan_evaluate's output (each level's faces are the previous level's
faces' corners in order: face q at level l >= 2 is corner q % 4 of face q // 4; at level 1 the
corners of the cage faces in order), the patches' values from a Bernstein evaluation here.

  export_check.py --cage C.obj --limit C.lim.obj --map C.map [--patches C.bv]
                  [--fallback FACES] --occt build/occt_read FILE.step|FILE.igs ...

occt_read runs once per file, with --eval and (--fallback FACES) its full report, which is
written to FILE.rep for the caller's checks.

For every limit vertex, every place (cage face, sub-quad, s, t) it has; the face map's cells
containing it give the face and its (u, v); OpenCASCADE evaluates those (occt_read --eval)
and the distance to the limit sample is taken, apart for fill faces (counted fallbacks).
Patch faces (the plan's own bicubic / bi-5 patches) are also evaluated on a 4x4 grid against
the Bernstein form of `ccnurbs patches`' control points. Prints "key: value" per file.
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
    level, V, N, F = read_limit(a.limit)
    places = limit_places(sizes, level, F)
    faces = read_map(a.map)
    req, matched = requests(faces, places)
    size = float(np.linalg.norm(V.max(axis=0) - V.min(axis=0)))
    kind = {f["index"]: f["kind"] for f in faces}
    pats = read_bv(a.patches) if a.patches else []
    G = [0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0]
    preq = [(f["index"], u, v, f["patch"]) for f in faces if f["patch"] >= 0 for u in G for v in G]
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
            cmd = [a.occt] + (["--fallback", a.fallback] if a.fallback else []) + ["--eval", rq, "--out", rs, path]
            with open(path + ".rep", "w") as rep:
                p = subprocess.run(cmd, stdout=rep, stderr=subprocess.DEVNULL)
            tag = "iges" if path.endswith((".igs", ".iges")) else "step"
            if p.returncode != 0:
                print("%s_eval: failed" % tag)
                continue
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
