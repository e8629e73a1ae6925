#!/bin/sh
# `make demo`: refine shipped cages with non-uniform knot intervals and write OBJ files to out/.
set -e
cd "$(dirname "$0")/.."
mkdir -p out
CLI=build/ccnurbs
# Li et al. 2016 Fig. 17: valence-7 extraordinary point, spoke intervals 1,8,8,1,1,1,8, the
# centre lifted (z = 1): its blending function. NURSS shows two peaks, eigen one. (Fig. 16's
# cage gives two peaks under both here: level 0 -> 1 always uses NURSS, DESIGN 4.3.)
for s in eigen nurss; do
  $CLI refine --scheme $s --levels 4 tests/data/fig17_v7.obj out/fig17_$s.obj
  $CLI limit --scheme $s --levels 4 tests/data/fig17_v7.obj out/fig17_${s}_limit.obj
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
sh tests/blender/demo.sh
