#!/bin/sh
# `make bench`: CCNURBS vs OpenSubdiv 3.5 (and Blender's Subdivision Surface modifier when
# tests/blender/bench_blender.py exists) on the same meshes, in one run on this machine.
# Ratios are ours / theirs (lower is better for times).
cd "$(dirname "$0")/../.." || exit 2
D=build/bench
mkdir -p "$D"
python3 tests/bench/make_bench_cages.py "$D" > /dev/null || exit 2
ratio() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.2f", (b > 0 ? a / b : 0) }'; }
field() { sed -n "s/.*$1 \([0-9.]*\) s.*/\1/p"; }
echo "mesh level | ccn plan | ccn evaluate | ccn refine | osd topology+points | osd points+limit | refine ratio | evaluate ratio | plan ratio"
for cage in sphere8k carlike carlike_knots; do
  for L in 2 3; do
    o=$(build/bench/osd_bench "$D/$cage.obj" "$L" 3) || exit 2
    c=$(build/bench/ccn_bench "$D/$cage.obj" "$L" refine 3) || exit 2
    ot=$(echo "$o" | field topology); op=$(echo "$o" | field points); ol=$(echo "$o" | field limit)
    cp=$(echo "$c" | field plan); ce=$(echo "$c" | field evaluate); cr=$(echo "$c" | field refine)
    otp=$(awk -v a="$ot" -v b="$op" 'BEGIN{print a+b}'); opl=$(awk -v a="$op" -v b="$ol" 'BEGIN{print a+b}')
    oall=$(awk -v a="$ot" -v b="$op" -v c="$ol" 'BEGIN{print a+b+c}')
    echo "$cage L$L | $cp | $ce | $cr | $otp | $opl | $(ratio "$cr" "$otp") | $(ratio "$ce" "$opl") | $(ratio "$cp" "$oall")"
  done
done
echo "refine ratio = ccn_refine (topology + points) / OSD uniform refinement (topology + points);"
# issue 14: the per-vertex eigen polyhedron choice (0 for spoke ratios <= 5) and the cap's cost
num() { sed -n "s/.*$1 \([0-9]*\).*/\1/p"; }
for cage in $D/carlike.obj $D/carlike_knots.obj tests/data/fig16_v6.obj tests/data/fig17_v7.obj tests/data/fig18_v8.obj; do
  s=$(build/bench/ccn_bench "$cage" 2 refine 5 0) || exit 2
  q=$(build/bench/ccn_bench "$cage" 2 refine 5 1) || exit 2
  ts=$(echo "$s" | field plan); tq=$(echo "$q" | field plan); nv=$(echo "$s" | num "EVs verified")
  per=$(awk -v a="$ts" -v b="$tq" -v n="$nv" 'BEGIN { printf "%.1f", n > 0 ? 1000 * (a - b) / n : 0 }')
  echo "eigen polyhedron choice, $(basename "$cage" .obj) L2: plan $ts s (paper's polyhedron only: $tq s); $nv EVs verified (spoke ratio > 5), $per ms per verified EV, outside G1 $(echo "$s" | num "outside G1")"
done
for L in 2 3; do
  b=$(build/bench/ccn_bench "$D/carlike.obj" "$L" bi5 3) || exit 2
  r=$(build/bench/ccn_bench "$D/carlike.obj" "$L" refine 3) || exit 2
  echo "cap carlike L$L: bi5 plan $(echo "$b" | field plan) s, evaluate $(echo "$b" | field evaluate) s ($(echo "$b" | num caps) caps); refine plan $(echo "$r" | field plan) s, evaluate $(echo "$r" | field evaluate) s"
done
echo "evaluate ratio = plan evaluate (positions + normals) / OSD re-interpolation + Limit with tangents;"
echo "plan ratio = plan creation / OSD topology + points + limit."
echo "One UV channel (the cages' box unwrap, --cap refine; target: <= 1.5x the plan without):"
echo "mesh level | plan | plan + uv | ratio | evaluate | evaluate + uv | ratio | memory MB | memory + uv MB | ratio"
for cage in sphere8k carlike carlike_knots; do
  for L in 2 3; do
    u=$(build/bench/ccn_bench "$D/$cage.obj" "$L" refine 3 | grep '^ccn uv') || exit 2
    num() { echo "$u" | sed -n "s/.*$1 \([0-9.]*\) \(s\|MB\).*/\1/p"; }
    p0=$(num "plan"); p1=$(num "plan [0-9.]* s, with uv"); e0=$(num "evaluate"); e1=$(num "evaluate [0-9.]* s, with uv")
    m0=$(num "memory"); m1=$(num "memory [0-9.]* MB, with uv")
    echo "$cage L$L | $p0 | $p1 | $(ratio "$p1" "$p0") | $e0 | $e1 | $(ratio "$e1" "$e0") | $m0 | $m1 | $(ratio "$m1" "$m0")"
  done
done
if command -v blender > /dev/null; then
  echo "Blender $(blender --version 2>/dev/null | head -n 1 | cut -d' ' -f2): CCNURBS modifier vs Subdivision Surface, same density (ratio = ours / Subsurf):"
  tmp=$(mktemp -d) || exit 2
  BLENDER_USER_SCRIPTS="$tmp/scripts" BLENDER_USER_CONFIG="$tmp/config" \
    blender --background --factory-startup --python-exit-code 1 \
    --python tests/blender/bench_blender.py -- "$D" build/ccnurbs.zip 2>&1 | grep '^bench'
  rm -rf "$tmp"
fi
