#!/usr/bin/env python3
"""The random general stars of RESULTS.md's closure tables: two per valence 3, 5-8, 10, 12 and
spoke ratio R = 2, 4, 10; spoke intervals log-uniform in [1, R] with one spoke at 1 and another
at R; cages by make_star.py (3 x 3 quads per sector, a wavy dome).
usage: star_set.py OUTDIR [SEED]  -- writes OUTDIR/s_R_n_k.obj"""
import math, os, random, subprocess, sys

out, seed = sys.argv[1], int(sys.argv[2]) if len(sys.argv) > 2 else 1
random.seed(seed)
here = os.path.dirname(os.path.abspath(__file__))
os.makedirs(out, exist_ok=True)
for R in (2, 4, 10):
    for n in (3, 5, 6, 7, 8, 10, 12):
        for rep in range(2):
            d = [math.exp(random.uniform(0, math.log(R))) for _ in range(n)]
            i1 = random.randrange(n)
            i2 = (i1 + 1 + random.randrange(n - 1)) % n
            d[i1], d[i2] = 1.0, float(R)
            subprocess.run([sys.executable, os.path.join(here, "make_star.py"), str(n),
                            ",".join("%.6g" % x for x in d), os.path.join(out, "s_%d_%d_%d.obj" % (R, n, rep))],
                           check=True)
