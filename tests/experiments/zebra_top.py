#!/usr/bin/env python3
"""Reflection stripes of limit OBJs (v + vn + f) seen from +z, side by side (matplotlib): the
view vector reflected on the exact normals, stripes of its angle in the xz plane, so that a
curvature jump shows as a kink and a curvature spike as converging stripes.

    zebra_top.py out.png cx,cy,r stripes cols title=file ...   (the square [cx +- r] x [cy +- r])"""
import sys
import numpy as np
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
from matplotlib.tri import Triangulation


def read_obj(path):
    V, N, F = [], [], []
    for line in open(path):
        t = line.split()
        if not t:
            continue
        if t[0] == "v":
            V.append([float(x) for x in t[1:4]])
        elif t[0] == "vn":
            N.append([float(x) for x in t[1:4]])
        elif t[0] == "f":
            i = [int(x.split("/")[0]) - 1 for x in t[1:]]
            F += [[i[0], i[k], i[k + 1]] for k in range(1, len(i) - 1)]
    return np.array(V), np.array(N), np.array(F)


def main():
    out, box, k, cols = sys.argv[1], sys.argv[2], float(sys.argv[3]), int(sys.argv[4])
    cx, cy, r = map(float, box.split(","))
    panels = [a.split("=", 1) for a in sys.argv[5:]]
    rows = (len(panels) + cols - 1) // cols
    fig, axs = plt.subplots(rows, cols, figsize=(4 * cols, 4 * rows), squeeze=False)
    for ax in axs.flat:
        ax.axis("off")
    for ax, (title, path) in zip(axs.flat, panels):
        V, N, F = read_obj(path)
        N = N / np.linalg.norm(N, axis=1)[:, None]
        R = 2 * N[:, 2:3] * N - np.array([0, 0, 1.0])
        s = np.sin(k * np.arctan2(R[:, 0], R[:, 2]))
        P = V[F]
        keep = np.all((np.abs(P[:, :, 0] - cx) < r) & (np.abs(P[:, :, 1] - cy) < r), axis=1)
        ax.tricontourf(Triangulation(V[:, 0], V[:, 1], F[keep]), s, levels=[-2, 0, 2], colors=["k", "w"])
        ax.set_xlim(cx - r, cx + r)
        ax.set_ylim(cy - r, cy + r)
        ax.set_aspect("equal")
        ax.set_title(title, fontsize=10)
    plt.tight_layout()
    plt.savefig(out, dpi=72)


if __name__ == "__main__":
    main()
