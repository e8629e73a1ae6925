#!/bin/sh
# `make demo`: refine shipped cages with non-uniform knot intervals and write OBJ files to out/.
set -e
cd "$(dirname "$0")/.."
mkdir -p out
CLI=build/ccnurbs
# Li et al. 2016 Fig. 16: valence-6 extraordinary point, spoke intervals 1,10,10,1,1,10,
# the centre lifted (z = 1): the blending function. NURSS shows two peaks, eigen one.
for s in eigen nurss; do
  $CLI refine --scheme $s --levels 4 tests/data/fig16_v6.obj out/fig16_$s.obj
done
# A torus with one knot ring stretched (interval 6): the surface stays C2 NURBS.
awk 'BEGIN{done=0} {print} /^f / && !done {split($2,a,"/"); split($3,b,"/"); printf("# knot %s %s 6\n", a[1], b[1]); done=1}' \
  tests/data/torus.obj > out/torus_knots.obj
$CLI refine --scheme eigen --levels 3 out/torus_knots.obj out/torus_eigen.obj
$CLI refine --scheme cc --levels 3 tests/data/icosa_quad.obj out/icosa_quad_cc.obj
$CLI refine --scheme eigen --levels 3 --corners pinned tests/data/lshape.obj out/lshape_pinned.obj
echo "demo: refined meshes written to $(pwd)/out/:"
ls -1 out/*.obj | sed 's/^/  /'
echo "(open them in Blender: File > Import > Wavefront OBJ; '# knot i j d' lines carry the intervals)"
