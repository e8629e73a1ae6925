#!/usr/bin/env python3
"""Writes the binary seed inputs of corpus_mesh/ and corpus_plan/ (layout: fuzz_mesh.c,
fuzz_cage.h, fuzz_plan.c). Deterministic; run from anywhere."""
import os

HERE = os.path.dirname(os.path.abspath(__file__))


def grid(nx, ny, tri=0, dele=0, verts=None):
    b = [2, nx - 1, ny - 1] + list(tri.to_bytes(4, "big")) + list(dele.to_bytes(2, "big"))
    nv = (nx + 1) * (ny + 1)
    return b + (verts or [140] * nv)


def fan(k, closed, verts=None):
    return [3, (k - 3) | (0x40 if closed else 0)] + (verts or [140] * (1 + 2 * k))


def raw(nv, faces, coords, flags=0):
    b = [flags, nv, len(faces)] + [len(f) for f in faces]
    for f in faces:
        b += [i + 1 for i in f]
    return b + coords


def edges(pairs):  # pairs of (corner index, knot byte)
    b = [len(pairs)]
    for c, k in pairs:
        b += [(c >> 8) & 0x7f, c & 0xff, k]
    return b


# knot bytes: < 128 special (fz_special), >= 128 ratio 10^((b-192)*9/64)
SPECIAL = {"nan": 4, "inf": 5, "1e300": 7, "1e-300": 9, "neg": 2, "zero": 0, "1e9r": 255}
mesh_seeds = {
    "grid3_uniform": grid(3, 3) + edges([]) + [0],
    "grid4_knots": grid(4, 4) + edges([(0, 200), (5, 150), (9, SPECIAL["nan"])]) + [1],
    "grid_tri_holes": grid(5, 4, tri=0x00F0F00F, dele=0x8421) + edges([(3, 220)]) + [1],
    "grid_extreme_knots": grid(3, 3) + edges([(0, SPECIAL["1e300"]), (1, SPECIAL["1e-300"]),
                                              (2, SPECIAL["neg"]), (3, SPECIAL["zero"])]) + [1],
    "grid_ratio1e9": grid(3, 2) + edges([(0, 255), (4, 128)]) + [1],
    "fan5_closed": fan(5, True) + edges([(0, 210), (4, 170)]) + [1],
    "fan7_open": fan(7, False) + edges([(1, 230)]) + [1],
    "fan40_closed": fan(40, True) + edges([]) + [0],
    "fan3_huge_coord": fan(3, True, [13, 0] + [140] * 6) + edges([]) + [0],
    "fan6_nan_coord": fan(6, True, [4, 1] + [140] * 12) + edges([]) + [0],
    "raw_triangle": raw(3, [[0, 1, 2]], [24 + 16 * i for i in range(9)]) + edges([]) + [0],
    "raw_quad_repeat": raw(4, [[0, 1, 1, 2]], [150] * 12) + edges([]) + [0],
    "raw_twogon": raw(3, [[0, 1]], [150] * 9) + edges([]) + [0],
    "raw_two_tris": raw(4, [[0, 1, 2], [0, 2, 3]], [24, 24, 24, 40, 24, 24, 40, 40, 24, 24, 40, 24])
    + edges([(0, 160)]) + [1],
    "raw_evmatrix": [0x20 | 2, 1, 1] + [0] * 6 + [140] * 4 + [0, 0] + [8] + [200] * 70 + [0],
}
plan_seeds = {}
for name, b in mesh_seeds.items():
    if name in ("raw_evmatrix",):
        continue
    # scheme, cap, levels(+1), corners, threads, then perturbation bytes
    plan_seeds[name] = b[:-1] + [0, 0, 3, 0, 0] + [140] * 8
plan_seeds["fan5_refine_cap"] = fan(5, True) + edges([(0, 210)]) + [0, 1, 3, 1, 1]
plan_seeds["grid_cc_level0"] = grid(2, 2) + edges([]) + [2, 0, 1, 0, 0]
plan_seeds["grid_bad_opts"] = grid(2, 2) + edges([]) + [3, 2, 0, 2, 0]
plan_seeds["grid_levels_1000"] = grid(2, 2) + edges([]) + [0, 0, 255, 0, 0]
plan_seeds["tri_nurss_level4"] = raw(3, [[0, 1, 2]], [24 + 16 * i for i in range(9)]) + edges([]) + [1, 0, 4, 0, 0]

for d, seeds in (("corpus_mesh", mesh_seeds), ("corpus_plan", plan_seeds)):
    os.makedirs(os.path.join(HERE, d), exist_ok=True)
    for name, b in seeds.items():
        with open(os.path.join(HERE, d, name), "wb") as f:
            f.write(bytes(x & 0xff for x in b))
