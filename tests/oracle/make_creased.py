#!/usr/bin/env python3
"""Creased test cages for the CAD export (run_export.sh, test-only). Usage:
    make_creased.py DIR
writes DIR/cube_sharp.obj (the unit cube, all 12 edges infinitely sharp: six flat faces meeting
C0), DIR/cube_semi.obj (the same edges at sharpness 1.5: sharp one level, blended the next) and
DIR/dart_corner.obj: a box of 3 x 3 quads per side (56 vertices, 54 faces) with one ring of
knot interval 2.5, an infinitely sharp polyline of two edges inside the top side, lifted into a
ridge (a dart at each end, a crease vertex turning 90 degrees between them), the three box edges
at one corner
infinitely sharp (that corner has three sharp edges and one-face sectors; their other ends are
darts) and a vertex sharpness (# corner, a cone point) at a vertex pushed into the bottom side.
"""
import itertools
import os
import sys


def cube():
    V = [(x, y, z) for z in (0, 1) for y in (0, 1) for x in (0, 1)]
    F = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    return V, F


def edges(F):
    E = set()
    for f in F:
        for a, b in zip(f, f[1:] + f[:1]):
            E.add((min(a, b), max(a, b)))
    return sorted(E)


def box(n):
    """The surface of [0,n]^3 in unit quads, outward oriented."""
    V, index, F = [], {}, []

    def vid(p):
        if p not in index:
            index[p] = len(V)
            V.append(p)
        return index[p]
    for axis, side in itertools.product(range(3), (0, n)):
        u, w = [a for a in range(3) if a != axis]
        for i, j in itertools.product(range(n), range(n)):
            quad = []
            for di, dj in ((0, 0), (1, 0), (1, 1), (0, 1)):
                p = [0, 0, 0]
                p[axis], p[u], p[w] = side, i + di, j + dj
                quad.append(vid(tuple(p)))
            a, b, c = (V[quad[k]] for k in range(3))  # outward: the normal's axis component
            e1 = [b[k] - a[k] for k in range(3)]
            e2 = [c[k] - b[k] for k in range(3)]
            nrm = e1[(axis + 1) % 3] * e2[(axis + 2) % 3] - e1[(axis + 2) % 3] * e2[(axis + 1) % 3]
            if (nrm > 0) != (side > 0):
                quad.reverse()
            F.append(tuple(quad))
    return V, F, index


def write(path, V, F, lines):
    with open(path, "w") as o:
        o.write("# %s: creased test cage of tests/oracle/make_creased.py\n" % os.path.basename(path))
        for p in V:
            o.write("v %g %g %g\n" % p)
        for f in F:
            o.write("f %s\n" % " ".join(str(i + 1) for i in f))
        for line in lines:
            o.write(line + "\n")


def main():
    out = sys.argv[1]
    V, F = cube()
    for name, s in (("cube_sharp", 10), ("cube_semi", 1.5)):
        write(os.path.join(out, name + ".obj"), V, F,
              ["# crease %d %d %g" % (a + 1, b + 1, s) for a, b in edges(F)])
    V, F, at = box(3)
    for p, dz in (((1, 1, 3), 0.4), ((2, 1, 3), 0.5), ((2, 2, 3), 0.4), ((2, 1, 0), -0.5)):
        V[at[p]] = (p[0], p[1], p[2] + dz)  # a ridge along the top crease, a pit at the cone
    lines = ["# knot %d %d 2.5" % (at[(0, 0, 0)] + 1, at[(1, 0, 0)] + 1)]
    for p, q in (((1, 1, 3), (2, 1, 3)), ((2, 1, 3), (2, 2, 3)),   # top: dart - crease - dart
                 ((0, 0, 0), (1, 0, 0)), ((0, 0, 0), (0, 1, 0)), ((0, 0, 0), (0, 0, 1))):
        lines.append("# crease %d %d 10" % (at[p] + 1, at[q] + 1))
    lines.append("# corner %d 10" % (at[(2, 1, 0)] + 1))   # a cone point inside the bottom
    write(os.path.join(out, "dart_corner.obj"), V, F, lines)


if __name__ == "__main__":
    main()
