#!/usr/bin/env python3
# usage: make_tearbox.py [out.obj] -- tear box (tests/c/cap_fair.h tear_box) as an OBJ
# the tear box as an OBJ with knot intervals
verts = {}; pos = []
for x in range(4):
    for y in range(4):
        for z in range(4):
            if 0 < x < 3 and 0 < y < 3 and 0 < z < 3: continue
            verts[(x, y, z)] = len(pos)
            pos.append((1.4 * (x - 1.5), y - 1.5, 0.8 * (z - 1.5)))
faces = []
for ax in range(3):
    for side in (0, 3):
        for a in range(3):
            for b in range(3):
                q = []
                for du, dv in ((0, 0), (1, 0), (1, 1), (0, 1)):
                    p = [0, 0, 0]; p[ax] = side; p[(ax + 1) % 3] = a + du; p[(ax + 2) % 3] = b + dv
                    q.append(verts[tuple(p)])
                if side == 0: q = [q[0], q[3], q[2], q[1]]
                faces.append(q)
edges = {}
for q in faces:
    for j in range(4):
        a, b = q[j], q[(j + 1) % 4]
        k = (min(a, b), max(a, b))
        if k in edges: continue
        pa, pb = pos[a], pos[b]
        gx = (pa[0] + pb[0]) / 2 / 1.4 + 1.5; gz = (pa[2] + pb[2]) / 2 / 0.8 + 1.5
        d = 1
        if abs(pa[0] - pb[0]) > 1e-9 and gx > 2: d = 0.25
        if abs(pa[2] - pb[2]) > 1e-9 and 1 < gz < 2: d = 3
        edges[k] = d
import sys
with open(sys.argv[1] if len(sys.argv) > 1 else 'tear_box.obj', 'w') as f:
    f.write('# tear box: cube 3x3 quads per side, x*1.4, z*0.8; x-parallel ring of the largest-x slab 0.25, z-parallel ring of the middle z slab 3\n')
    for p in pos: f.write('v %.17g %.17g %.17g\n' % p)
    for q in faces: f.write('f %s\n' % ' '.join(str(i + 1) for i in q))
    for (a, b), d in sorted(edges.items()):
        if d != 1: f.write('# knot %d %d %g\n' % (a + 1, b + 1, d))
