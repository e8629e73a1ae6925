"""A regular torus cage with random (seeded) ring intervals, and the same surface as the
OpenCASCADE B-spline the cage defines, for the packed-export check (run_export.sh).

  python3 nu_torus.py SEED out.obj out_build.txt

The cage: vertex (i, j) = index i*NV + j (i around the axis, j around the tube), face
(i,j) (i+1,j) (i+1,j+1) (i,j+1) first, so the pack built from face 0 has u along i, v along
j and its parameter origin at vertex (0, 0). Ring intervals du[i] (edges (i,j)-(i+1,j)) and
dv[j] as '# knot' lines. The build file (occt_read --build) is written from the cage alone:
OpenCASCADE's periodic form, knots 0, du[0], du[0]+du[1], ... (the period) and the distinct
poles in the order that periodic form uses for that origin: vertex column NU-1 first (the
pole whose basis function starts one span before the origin), then 0 .. NU-2; likewise in v.
"""
import math
import random
import sys

NU, NV, R, r = 8, 6, 2.0, 0.7


def main():
    seed, obj, build = int(sys.argv[1]), sys.argv[2], sys.argv[3]
    rnd = random.Random(seed)
    du = [round(rnd.uniform(0.4, 2.0), 3) for _ in range(NU)]
    dv = [round(rnd.uniform(0.4, 2.0), 3) for _ in range(NV)]
    V = []
    for i in range(NU):
        a = 2 * math.pi * i / NU
        for j in range(NV):
            b = 2 * math.pi * j / NV
            V.append(((R + r * math.cos(b)) * math.cos(a), (R + r * math.cos(b)) * math.sin(a), r * math.sin(b)))
    idx = lambda i, j: (i % NU) * NV + (j % NV)
    with open(obj, "w") as f:
        f.write("# torus %dx%d, random ring intervals (seed %d)\n" % (NU, NV, seed))
        for p in V:
            f.write("v %.17g %.17g %.17g\n" % p)
        for i in range(NU):
            for j in range(NV):
                f.write("f %d %d %d %d\n" % (idx(i, j) + 1, idx(i + 1, j) + 1, idx(i + 1, j + 1) + 1, idx(i, j + 1) + 1))
        for i in range(NU):
            for j in range(NV):
                f.write("# knot %d %d %r\n" % (idx(i, j) + 1, idx(i + 1, j) + 1, du[i]))
                f.write("# knot %d %d %r\n" % (idx(i, j) + 1, idx(i, j + 1) + 1, dv[j]))
    def cum(d):
        t = [0.0]
        for x in d:
            t.append(t[-1] + x)
        return t
    with open(build, "w") as f:
        f.write("degree 3 3\npoles %d %d\nperiodic 1 1\n" % (NU, NV))
        for name, d in (("u", du), ("v", dv)):
            t = cum(d)
            f.write("%sknots %d %s\n" % (name, len(t), " ".join("%.17g" % x for x in t)))
            f.write("%smults %d %s\n" % (name, len(t), " ".join("1" for _ in t)))
        order_u = [NU - 1] + list(range(NU - 1))
        order_v = [NV - 1] + list(range(NV - 1))
        for i in order_u:
            for j in order_v:
                f.write("%.17g %.17g %.17g\n" % V[idx(i, j)])


main()
