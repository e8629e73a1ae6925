#!/usr/bin/env python3
# usage: make_star.py N d0,d1,... out.obj  -- an open valence-N star cage (3 x 3 quads per sector,
# every edge parallel to spoke s carrying d_s, a wavy dome), as test_cap_fair builds it
import sys, math
n = int(sys.argv[1]); m = 3; d = [float(x) for x in sys.argv[2].split(',')]; out = sys.argv[3]
def sv(s, i, j):
    if i == 0: return 0 if j == 0 else 1 + ((s + 1) % n) * m * (m + 1) + (j - 1) * (m + 1)
    return 1 + (s % n) * m * (m + 1) + (i - 1) * (m + 1) + j
pos = [None] * (1 + n * m * (m + 1)); pos[0] = (0, 0, 0.5)
for s in range(n):
    for i in range(1, m + 1):
        for j in range(m + 1):
            x = i * math.cos(2 * math.pi * s / n) + j * math.cos(2 * math.pi * (s + 1) / n)
            y = i * math.sin(2 * math.pi * s / n) + j * math.sin(2 * math.pi * (s + 1) / n)
            pos[sv(s, i, j)] = (x, y, 0.5 * (1 - (x * x + y * y) / (2.0 * m * m)) + 0.15 * math.sin(1.3 * x) * math.cos(0.9 * y))
with open(out, 'w') as f:
    for p in pos: f.write('v %.17g %.17g %.17g\n' % p)
    for s in range(n):
        for i in range(m):
            for j in range(m):
                f.write('f %d %d %d %d\n' % (sv(s, i, j) + 1, sv(s, i + 1, j) + 1, sv(s, i + 1, j + 1) + 1, sv(s, i, j + 1) + 1))
    for s in range(n):
        for j in range(m + 1):
            for i in range(m): f.write('# knot %d %d %.17g\n' % (sv(s, i, j) + 1, sv(s, i + 1, j) + 1, d[s]))
        for i in range(1, m + 1):
            for j in range(m): f.write('# knot %d %d %.17g\n' % (sv(s, i, j) + 1, sv(s, i, j + 1) + 1, d[(s + 1) % n]))
