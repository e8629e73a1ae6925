#!/usr/bin/env python3
"""The tear box (a test cage of the CAD export and the cap fairness harness): the surface of a cube
with 3 x 3 quads per side, x scaled by 1.4 and z by 0.8; the ring of x-parallel edges in the
slab of largest x has interval 0.25, the ring of z-parallel edges of the middle z slab 3 (all
others 1). Standard library only.   make_tearbox.py out.obj
"""
import sys

def main(path):
    n = 3
    idx, V = {}, []
    def vid(p):
        if p not in idx:
            idx[p] = len(V)
            V.append(p)
        return idx[p]
    F = []
    for axis in range(3):
        for side in (0, n):
            a, b = (axis + 1) % 3, (axis + 2) % 3
            for i in range(n):
                for j in range(n):
                    q = []
                    for (di, dj) in ((0, 0), (1, 0), (1, 1), (0, 1)):
                        p = [0, 0, 0]
                        p[axis] = side
                        p[a] = i + di
                        p[b] = j + dj
                        q.append(vid(tuple(p)))
                    if side == 0:  # outward: (a, b, axis) is right-handed, so reverse at side 0
                        q.reverse()
                    F.append(q)
    knots = []
    seen = set()
    for f in F:
        for k in range(4):
            u, w = V[f[k]], V[f[(k + 1) % 4]]
            key = (min(f[k], f[(k + 1) % 4]), max(f[k], f[(k + 1) % 4]))
            if key in seen:
                continue
            seen.add(key)
            d = [w[c] - u[c] for c in range(3)]
            if d[1] == 0 and d[2] == 0 and min(u[0], w[0]) == n - 1:
                knots.append((key, 0.25))
            if d[0] == 0 and d[1] == 0 and min(u[2], w[2]) == 1:
                knots.append((key, 3.0))
    with open(path, "w") as o:
        o.write("# tear box: cube 3x3 per side, x*1.4, z*0.8, x-ring of the last x slab 0.25, "
                "z-ring of the middle z slab 3\n")
        for p in V:
            x, y, z = (2.0 * c / n - 1 for c in p)
            o.write("v %.17g %.17g %.17g\n" % (1.4 * x, y, 0.8 * z))
        for f in F:
            o.write("f %s\n" % " ".join(str(i + 1) for i in f))
        for (a, b), d in knots:
            o.write("# knot %d %d %g\n" % (a + 1, b + 1, d))

if __name__ == "__main__":
    main(sys.argv[1])
