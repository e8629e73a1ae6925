#!/usr/bin/env python3
"""Zebra / highlight-line rendering of a limit OBJ (v + vn + f) with numpy: orthographic view,
z-buffer, per-pixel interpolated normals, stripes of the reflected view vector (reflection
lines of a striped environment): stripe = floor(k * atan2(r_x, r_z)) mod 2. Writes a PNG."""
import sys, zlib, struct
import numpy as np

def read_obj(path):
    V, N, F = [], [], []
    for line in open(path):
        t = line.split()
        if not t: continue
        if t[0] == 'v': V.append([float(x) for x in t[1:4]])
        elif t[0] == 'vn': N.append([float(x) for x in t[1:4]])
        elif t[0] == 'f':
            idx = [int(x.split('/')[0]) - 1 for x in t[1:]]
            for k in range(1, len(idx) - 1): F.append([idx[0], idx[k], idx[k + 1]])
    return np.array(V), np.array(N), np.array(F)

def rot(yaw, pitch):
    cy, sy, cp, sp = np.cos(yaw), np.sin(yaw), np.cos(pitch), np.sin(pitch)
    Ry = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    Rx = np.array([[1, 0, 0], [0, cp, -sp], [0, sp, cp]])
    return Rx @ Ry

def render(V, N, F, W, yaw, pitch, stripes, centre=None, radius=None):
    R = rot(yaw, pitch)
    P = V @ R.T
    Nn = N @ R.T
    if centre is None:
        lo, hi = P.min(0), P.max(0); c = (lo + hi) / 2; r = (hi - lo)[:2].max() / 2 * 1.05
    else:
        c = np.array(centre) @ R.T; r = radius
    s = (W / 2) / r
    X = (P[:, 0] - c[0]) * s + W / 2; Y = (c[1] - P[:, 1]) * s + W / 2; Z = P[:, 2]
    zbuf = np.full((W, W), -np.inf); img = np.zeros((W, W, 3))
    for tri in F:
        x, y, z = X[tri], Y[tri], Z[tri]
        x0, x1 = max(int(np.floor(x.min())), 0), min(int(np.ceil(x.max())), W - 1)
        y0, y1 = max(int(np.floor(y.min())), 0), min(int(np.ceil(y.max())), W - 1)
        if x0 > x1 or y0 > y1: continue
        det = (y[1] - y[2]) * (x[0] - x[2]) + (x[2] - x[1]) * (y[0] - y[2])
        if abs(det) < 1e-12: continue
        gx, gy = np.meshgrid(np.arange(x0, x1 + 1) + 0.5, np.arange(y0, y1 + 1) + 0.5)
        l0 = ((y[1] - y[2]) * (gx - x[2]) + (x[2] - x[1]) * (gy - y[2])) / det
        l1 = ((y[2] - y[0]) * (gx - x[2]) + (x[0] - x[2]) * (gy - y[2])) / det
        l2 = 1 - l0 - l1
        inside = (l0 >= -1e-9) & (l1 >= -1e-9) & (l2 >= -1e-9)
        if not inside.any(): continue
        zz = l0 * z[0] + l1 * z[1] + l2 * z[2]
        sub = zbuf[y0:y1 + 1, x0:x1 + 1]
        m = inside & (zz > sub)
        if not m.any(): continue
        n = l0[..., None] * Nn[tri[0]] + l1[..., None] * Nn[tri[1]] + l2[..., None] * Nn[tri[2]]
        n /= np.linalg.norm(n, axis=-1, keepdims=True)
        v = np.array([0, 0, -1.0])                         # view direction (towards -z)
        rr = v - 2 * (n @ v)[..., None] * n                # reflected
        st = (np.floor(stripes * (0.6 * rr[..., 0] + 0.8 * rr[..., 1])) % 2)[..., None]
        shade = 0.35 + 0.65 * np.abs(n[..., 2:3])
        col = np.where(st > 0, np.array([1.0, 1.0, 1.0]), np.array([0.08, 0.08, 0.12])) * shade
        sub[m] = zz[m]
        img[y0:y1 + 1, x0:x1 + 1][m] = col[m]
    return img

def write_png(path, img):
    h, w, _ = img.shape
    data = (np.clip(img, 0, 1) * 255).astype(np.uint8)
    raw = b''.join(b'\x00' + data[i].tobytes() for i in range(h))
    def chunk(t, d): return struct.pack('>I', len(d)) + t + d + struct.pack('>I', zlib.crc32(t + d) & 0xffffffff)
    png = b'\x89PNG\r\n\x1a\n' + chunk(b'IHDR', struct.pack('>IIBBBBB', w, h, 8, 2, 0, 0, 0)) + chunk(b'IDAT', zlib.compress(raw, 6)) + chunk(b'IEND', b'')
    open(path, 'wb').write(png)

if __name__ == '__main__':
    # zebra.py out.png W yaw pitch stripes in1.obj [in2.obj ...]  (side by side)
    out, W, yaw, pitch, stripes = sys.argv[1], int(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4]), float(sys.argv[5])
    zoom = [float(x) for x in sys.argv[6].split(',')] if sys.argv[6].count(',') == 3 else None
    files = sys.argv[7:] if zoom else sys.argv[6:]
    imgs = []
    cen = rad = None
    for k, p in enumerate(files):
        V, N, F = read_obj(p)
        if k == 0 and zoom:
            cen, rad = np.array(zoom[:3]), zoom[3]
        elif k == 0:
            R = rot(yaw, pitch); P = V @ R.T; lo, hi = P.min(0), P.max(0)
            cen = ((lo + hi) / 2) @ R; rad = (hi - lo)[:2].max() / 2 * 1.05
        imgs.append(render(V, N, F, W, yaw, pitch, stripes, cen, rad))
    write_png(out, np.concatenate(imgs, axis=1))
