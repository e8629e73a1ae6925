#!/usr/bin/env python3
"""Benchmark cages (standard library only): a quad cube-sphere (6 x 37 x 37 = 8214 faces),
a 50k-face one (6 x 91 x 91), a production-like cage with valences 3-6 (>= 1500 faces, built by
one Catmull-Clark-style split of a mixed cage), a cage with non-uniform knot intervals and
Blender's default 32-sided cylinder with one ring of intervals set to 3. Each has a UV map (`vt`,
`f v/vt`): six charts, one per direction of the face centres (a box unwrap), seams between
them."""
import math, os, random, sys

def box_uvs(V, F):
    """A box unwrap: each face's chart is the dominant axis (and sign) of its centre; a
    corner's UV is the vertex's other two coordinates, placed in the chart's tile."""
    vt, ids, FT = [], {}, []
    for q in F:
        c = [sum(V[v][i] for v in q) / len(q) for i in range(3)]
        ax = max(range(3), key=lambda i: abs(c[i]))
        chart = 2 * ax + (c[ax] < 0)
        a, b = [i for i in range(3) if i != ax]
        ft = []
        for v in q:
            if (v, chart) not in ids:
                ids[(v, chart)] = len(vt)
                vt.append(((chart % 3) + 0.25 * (V[v][a] + 1.5), (chart // 3) + 0.25 * (V[v][b] + 1.5)))
            ft.append(ids[(v, chart)])
        FT.append(ft)
    return vt, FT

def write(path, V, F, knots=None):
    vt, FT = box_uvs(V, F)
    with open(path, "w") as f:
        for v in V: f.write("v %.9f %.9f %.9f\n" % tuple(v))
        for t in vt: f.write("vt %.9f %.9f\n" % t)
        for q, t in zip(F, FT): f.write("f " + " ".join("%d/%d" % (i + 1, j + 1) for i, j in zip(q, t)) + "\n")
        for (a, b, d) in knots or []: f.write("# knot %d %d %.6g\n" % (a + 1, b + 1, d))

def cube_sphere(n):
    V, F, idx = [], [], {}
    def vid(p):
        key = tuple(round(c * 1e6) for c in p)
        if key not in idx:
            idx[key] = len(V); V.append(p)
        return idx[key]
    axes = [(0, 1, 2, 1), (0, 1, 2, -1), (1, 2, 0, 1), (1, 2, 0, -1), (2, 0, 1, 1), (2, 0, 1, -1)]
    for (a, b, c, s) in axes:
        for i in range(n):
            for j in range(n):
                quad = []
                for (di, dj) in ((0, 0), (1, 0), (1, 1), (0, 1)) if s > 0 else ((0, 0), (0, 1), (1, 1), (1, 0)):
                    p = [0.0, 0.0, 0.0]
                    p[a] = -1 + 2 * (i + di) / n; p[b] = -1 + 2 * (j + dj) / n; p[c] = s
                    l = math.sqrt(sum(x * x for x in p))
                    quad.append(vid([x / l for x in p]))
                F.append(quad)
    return V, F

def split_once(V, F):
    """Linear quad split (face point, edge points): all-quad cage, valences of V kept."""
    V = [list(v) for v in V]; emap = {}; NF = []
    def ep(a, b):
        k = (min(a, b), max(a, b))
        if k not in emap:
            emap[k] = len(V); V.append([(V[a][i] + V[b][i]) / 2 for i in range(3)])
        return emap[k]
    for f in F:
        c = len(V); V.append([sum(V[v][i] for v in f) / len(f) for i in range(3)])
        n = len(f)
        for j in range(n):
            NF.append([f[j], ep(f[j], f[(j + 1) % n]), c, ep(f[(j - 1) % n], f[j])])
    return V, NF

def car_like():
    """A rounded box with a few poles: cube sphere 5x5 per face with some faces triangulated
    and a pentagon, then split twice -> valences 3, 4, 5, 6, >= 1500 quads."""
    V, F = cube_sphere(5)
    random.seed(3)
    out = []
    for k, f in enumerate(F):
        if k % 17 == 3: out += [[f[0], f[1], f[2]], [f[0], f[2], f[3]]]  # valence 5/6 poles
        else: out.append(f)
    V, F = split_once(V, out)
    V, F = split_once(V, F)
    V = [[x * (1.8 if i == 0 else 1.0) + 0.01 * random.uniform(-1, 1) for i, x in enumerate(v)] for v in V]
    return V, F

def nonuniform(V, F):
    random.seed(7)
    knots = []
    for f in F:
        for j in range(len(f)):
            if random.random() < 0.3:
                knots.append((f[j], f[(j + 1) % len(f)], 10 ** random.uniform(-1, 1)))
    return knots

def cylinder32():
    """Blender's default cylinder (32 vertices, N-gon caps, radius 1, depth 2)."""
    n = 32
    V = [[math.cos(2 * math.pi * i / n), math.sin(2 * math.pi * i / n), z] for z in (-1, 1) for i in range(n)]
    F = [[i, (i + 1) % n, n + (i + 1) % n, n + i] for i in range(n)]
    F += [list(range(n))[::-1], [n + i for i in range(n)]]
    return V, F

if __name__ == "__main__":
    out = sys.argv[1] if len(sys.argv) > 1 else "."
    os.makedirs(out, exist_ok=True)
    V, F = cube_sphere(37); write(os.path.join(out, "sphere8k.obj"), V, F)
    V, F = car_like(); write(os.path.join(out, "carlike.obj"), V, F)
    write(os.path.join(out, "carlike_knots.obj"), V, F, nonuniform(V, F))
    V, F = cube_sphere(91); write(os.path.join(out, "sphere50k.obj"), V, F)
    # the rebuild case: one ring of the default cylinder set to 3 -- the ring of the 32
    # side edges (every rim vertex gets spoke ratio 3) and the ring of one rim edge pair (the
    # 32-gon centres get one spoke of 3)
    V, F = cylinder32()
    write(os.path.join(out, "cyl32_side3.obj"), V, F, [(i, 32 + i, 3.0) for i in range(32)])
    write(os.path.join(out, "cyl32_rim3.obj"), V, F, [(0, 1, 3.0), (32, 33, 3.0)])
    print("sphere8k: %d faces, sphere50k: %d faces" % (6 * 37 * 37, 6 * 91 * 91))
