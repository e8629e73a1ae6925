"""Principal curvatures of `ccnurbs limit --curvature` against OpenCASCADE's evaluation of the
exported faces (occt_read --grid N --points F --curvature).

  python3 curvature_check.py limit.ply occt.pts TOL

Every sample inside a face (grid indices 1 .. N-2 both ways: a face's border is a join, where
the surface is G1 and each side has its own curvature) that coincides with a limit vertex
(<= 1e-9 x size) and has numbers on both sides is compared: |k_ccn - k_occt| <= TOL x the
largest |k| compared. Prints the counts and the largest difference; exit 1 on a failure or when
fewer than 50 samples could be compared.
"""
import sys

import numpy as np


def read_ply(path):
    with open(path) as f:
        lines = f.read().split("\n")
    nv = int(next(l for l in lines if l.startswith("element vertex")).split()[2])
    props = [l.split()[2] for l in lines if l.startswith("property double")]
    start = lines.index("end_header") + 1
    A = np.array([[float(x) for x in l.split()] for l in lines[start:start + nv]])
    return A, props


def main():
    ply, pts, tol = sys.argv[1], sys.argv[2], float(sys.argv[3])
    A, props = read_ply(ply)
    assert props == ["x", "y", "z", "nx", "ny", "nz", "k1", "k2"], props
    P = np.loadtxt(pts, ndmin=2)
    X = A[:, :3]
    size = float(np.max(X.max(0) - X.min(0)))
    h = 1e-7 * size
    cells = {}
    for i, key in enumerate(map(tuple, np.floor(X / h).astype(np.int64))):
        cells.setdefault(key, []).append(i)
    n = grid = int(P[:, 1].max()) + 1
    inner = (P[:, 1] > 0) & (P[:, 1] < grid - 1) & (P[:, 2] > 0) & (P[:, 2] < grid - 1)
    matched = compared = 0
    worst, kmax, rows = 0.0, 0.0, []
    for s in np.flatnonzero(inner):
        q = P[s, 5:8]
        c = np.floor(q / h).astype(np.int64)
        best, bd = -1, np.inf
        for dx in (-1, 0, 1):
            for dy in (-1, 0, 1):
                for dz in (-1, 0, 1):
                    for i in cells.get((c[0] + dx, c[1] + dy, c[2] + dz), ()):
                        d = float(np.linalg.norm(X[i] - q))
                        if d < bd:
                            best, bd = i, d
        if best < 0 or bd > 1e-9 * size:
            continue
        matched += 1
        ko, ka = P[s, 11:13], A[best, 6:8]
        if not (np.isfinite(ko).all() and np.isfinite(ka).all()):
            continue
        compared += 1
        rows.append(np.abs(ko - ka).max())
        kmax = max(kmax, float(np.abs(ka).max()))
    worst = max(rows) if rows else 0.0
    rel = worst / kmax if kmax > 0 else 0.0
    print("samples %d inside faces, %d on limit vertices, %d compared: largest difference %.3g of "
          "max |k| %.3g" % (int(inner.sum()), matched, compared, rel, kmax))
    sys.exit(0 if compared >= 50 and rel <= tol else 1)


if __name__ == "__main__":
    main()
