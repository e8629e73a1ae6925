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
    A = np.loadtxt(lines[start:start + nv], ndmin=2)  # "nan" reads as NaN
    return A, props


def main():
    ply, pts, tol = sys.argv[1], sys.argv[2], float(sys.argv[3])
    A, props = read_ply(ply)
    assert props == ["x", "y", "z", "nx", "ny", "nz", "k1", "k2"], props
    P = np.loadtxt(pts, ndmin=2)
    X = A[:, :3]
    size = float(np.max(X.max(0) - X.min(0)))
    grid = int(P[:, 1].max()) + 1
    inner = (P[:, 1] > 0) & (P[:, 1] < grid - 1) & (P[:, 2] > 0) & (P[:, 2] < grid - 1)
    Q = P[inner]
    # a sample on a limit vertex: the same point to rounding; matched through keys on a grid of
    # 1e-10 x size (a pair split by a cell border is missed, which only lowers the count)
    h = 1e-10 * size

    def keys(Y):
        k = np.ascontiguousarray(np.rint((Y - X.min(0)) / h).astype(np.int64))
        return k.view([("x", np.int64), ("y", np.int64), ("z", np.int64)]).ravel()
    kx, kq = keys(X), keys(Q[:, 5:8])
    order = np.argsort(kx, kind="stable")
    pos = np.clip(np.searchsorted(kx[order], kq), 0, len(kx) - 1)
    cand = order[pos]
    hit = kx[cand] == kq
    d = np.linalg.norm(X[cand] - Q[:, 5:8], axis=1)
    hit &= d <= 1e-9 * size
    matched = int(hit.sum())
    ko, ka = Q[hit][:, 11:13], A[cand[hit]][:, 6:8]
    both = np.isfinite(ko).all(1) & np.isfinite(ka).all(1)
    compared = int(both.sum())
    rows = list(np.abs(ko[both] - ka[both]).max(1)) if compared else []
    kmax = float(np.abs(ka[both]).max()) if compared else 0.0
    worst = max(rows) if rows else 0.0
    rel = worst / kmax if kmax > 0 else 0.0
    print("samples %d inside faces, %d on limit vertices, %d compared: largest difference %.3g of "
          "max |k| %.3g" % (int(inner.sum()), matched, compared, rel, kmax))
    sys.exit(0 if compared >= 50 and rel <= tol else 1)


if __name__ == "__main__":
    main()
