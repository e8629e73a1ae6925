#!/bin/sh
# `make bench`: CCNURBS vs OpenSubdiv 3.5 and Blender's Subdivision Surface modifier (Debian's 3.4
# and the bpy 4.5 / 5.x venvs of tests/blender/deps_bpy.sh, where present) on the same meshes, in
# one run on this machine. The library runs with the DEFAULT options (scheme eigen, cap guided
# bi-5, per-vertex eigen polyhedron) unless a row says otherwise. Every time is the minimum over
# BENCH_REPS runs (default 3); the machine is shared, so ratios are the figures to read.
# Prints the targets table: one "target |" line per measured row, ratio = ours / theirs.
# Environment: BENCH_REPS, BENCH_BLENDER=0 (skip Blender), CCN_CACHE (the bpy venvs),
# CCN_BENCH_BLENDER_CASES (tests/blender/bench_blender.py).
cd "$(dirname "$0")/../.." || exit 2
D=build/bench
R=${BENCH_REPS:-3}
CACHE=${CCN_CACHE:-${XDG_CACHE_HOME:-$HOME/.cache}/ccnurbs}
mkdir -p "$D"
python3 tests/bench/make_bench_cages.py "$D" > /dev/null || exit 2
ratio() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.2f", (b > 0 ? a / b : 0) }'; }
field() { grep -v '^ccn uv' | sed -n "s/.*[;,] $1 \([0-9.]*\) s.*/\1/p"; } # the plan's line, not the UV one; ', plan' not 'first plan'
kb() { sed -n "s/.*peak RSS \([0-9]*\) kB.*/\1/p"; }
num() { sed -n "s/.*$1 \([0-9]*\).*/\1/p"; }
verdict() { awk -v r="$1" -v t="$2" 'BEGIN { if (r <= t) print "met"; else printf "missed (%.2fx the target)\n", r / t }'; }
row() { echo "target | $1 | $2 | $3 | $4 | $5 | $(verdict "$4" "$5")"; }

echo "target | what | ours | theirs | ratio | target ratio | verdict"
# ---- library: plan creation and evaluation vs OpenSubdiv's limit-stencil pipeline ----------------
for cl in sphere8k:2 sphere8k:3 sphere50k:2 carlike:2 carlike:3 carlike_knots:2 carlike_knots:3; do
  cage=${cl%%:*}; L=${cl#*:}
  o=$(build/bench/osd_bench "$D/$cage.obj" "$L" "$R" stencil) || exit 2
  c1=$(build/bench/ccn_bench "$D/$cage.obj" "$L" bi5 "$R" 0 1) || exit 2
  c2=$(build/bench/ccn_bench "$D/$cage.obj" "$L" bi5 "$R" 0 2) || exit 2
  oc=$(echo "$o" | field create); ou=$(echo "$o" | field update); ost=$(echo "$o" | sed -n "s/.*: \([0-9]*\) stencils.*/\1/p")
  cp=$(echo "$c1" | field plan); ce1=$(echo "$c1" | field evaluate); ce2=$(echo "$c2" | field evaluate)
  nv=$(echo "$c1" | sed -n 's/.*-> \([0-9]*\) verts.*/\1/p')
  caps=$(echo "$c1" | num "caps"); fb=$(echo "$c1" | num "cap fallbacks")
  row "ccn_plan_create, default cap, $cage L$L ($caps caps, $fb fallbacks)" "$cp s" \
      "$oc s (refiner + LimitStencilTableFactory)" "$(ratio "$cp" "$oc")" 1.0
  row "ccn_plan_evaluate 1 thread, $cage L$L (2 threads: $ce2 s, $(ratio "$ce1" "$ce2")x faster)" \
      "$ce1 s" "$ou s (UpdateValues + UpdateDerivs)" "$(ratio "$ce1" "$ou")" 0.5
  en=$(echo "$c2" | sed -n 's/.*new plan \([0-9.]*\) s.*/\1/p'); er=$(echo "$c2" | sed -n 's/.*recreated \([0-9.]*\) s,.*/\1/p')
  ek=$(echo "$c2" | sed -n 's/.*changed values only \([0-9.]*\) s.*/\1/p')
  os=$(awk -v a="$oc" -v b="$ou" 'BEGIN{printf "%.4f", a + b}')
  row "interval edit, library, 2 threads: options.previous + evaluate_changed, $cage L$L (a new plan + evaluate: $en s; recreate + a full evaluate: $er s)" \
      "$ek s" "$os s (OSD refiner + stencils + update: its topology change)" "$(ratio "$ek" "$os")" 1.0
  mc=$(echo "$c1" | kb); mo=$(echo "$o" | kb); tb=$(echo "$o" | sed -n 's/.*table \([0-9]*\) bytes.*/\1/p')
  row "peak memory per output vertex, $cage L$L (OSD table alone $(awk -v b="$tb" -v n="$ost" 'BEGIN{printf "%.0f", b/n}') B)" \
      "$(awk -v k="$mc" -v n="$nv" 'BEGIN{printf "%.0f", 1024*k/n}') B" \
      "$(awk -v k="$mo" -v n="$ost" 'BEGIN{printf "%.0f", 1024*k/n}') B (peak RSS / stencils)" \
      "$(awk -v a="$mc" -v n="$nv" -v b="$mo" -v m="$ost" 'BEGIN{printf "%.2f", (a/n)/(b/m)}')" 1.0
done
# ---- the 32-gon cylinder with one ring = 3: a full rebuild (plan creation) -------------------------
for cyl in cyl32_side3 cyl32_rim3; do
  for L in 2 3 4; do
    c=$(build/bench/ccn_bench "$D/$cyl.obj" "$L" bi5 1) || exit 2
    k=$(build/bench/ccn_bench "$D/$cyl.obj" "$L" bi5 "$((R + 1))" 0 0 cached) || exit 2
    r=$(build/bench/ccn_bench "$D/$cyl.obj" "$L" refine "$R") || exit 2
    cp=$(echo "$c" | field plan); kp=$(echo "$k" | field plan); rp=$(echo "$r" | field plan)
    ms=$(awk -v a="$cp" 'BEGIN{printf "%.1f", 1000*a}'); mk=$(awk -v a="$kp" 'BEGIN{printf "%.1f", 1000*a}')
    what="32-gon cylinder ($cyl) L$L rebuild, default cap ($(echo "$c" | num "caps") caps, $(echo "$c" | num "cap fallbacks") fallbacks; cap = refine $rp s)"
    row "$what, new plan" "$ms ms" "30 ms (absolute target)" "$(ratio "$ms" 30)" 1.0
    row "$what, with a ccn_cache (operators kept)" "$mk ms" "30 ms (absolute target)" "$(ratio "$mk" 30)" 1.0
  done
done
# ---- the earlier table: uniform refinement vs OpenSubdiv's, and the cap's own cost --------------------
echo "mesh level | ccn plan (default) | ccn plan (cap refine) | ccn evaluate | ccn refine | osd topology+points | osd points+limit | refine ratio"
for cage in sphere8k carlike carlike_knots; do
  for L in 2 3; do
    o=$(build/bench/osd_bench "$D/$cage.obj" "$L" "$R") || exit 2
    c=$(build/bench/ccn_bench "$D/$cage.obj" "$L" bi5 "$R") || exit 2
    r=$(build/bench/ccn_bench "$D/$cage.obj" "$L" refine "$R") || exit 2
    ot=$(echo "$o" | field topology); op=$(echo "$o" | field points); ol=$(echo "$o" | field limit)
    otp=$(awk -v a="$ot" -v b="$op" 'BEGIN{print a+b}'); opl=$(awk -v a="$op" -v b="$ol" 'BEGIN{print a+b}')
    cr=$(echo "$c" | field refine)
    echo "$cage L$L | $(echo "$c" | field plan) | $(echo "$r" | field plan) | $(echo "$c" | field evaluate) | $cr | $otp | $opl | $(ratio "$cr" "$otp")"
  done
done
# the per-vertex eigen polyhedron choice (0 for spoke ratios <= 5)
for cage in $D/carlike_knots.obj tests/data/fig16_v6.obj tests/data/fig17_v7.obj tests/data/fig18_v8.obj; do
  s=$(build/bench/ccn_bench "$cage" 2 bi5 "$R" 0) || exit 2
  q=$(build/bench/ccn_bench "$cage" 2 bi5 "$R" 1) || exit 2
  ts=$(echo "$s" | field plan); tq=$(echo "$q" | field plan); nv=$(echo "$s" | num "EVs verified")
  per=$(awk -v a="$ts" -v b="$tq" -v n="$nv" 'BEGIN { printf "%.1f", (n > 0 ? 1000 * (a - b) / n : 0) }')
  echo "eigen polyhedron choice, $(basename "$cage" .obj) L2: plan $ts s (paper's polyhedron only: $tq s); $nv EVs verified (spoke ratio > 5), $per ms per verified EV, outside G1 $(echo "$s" | num "outside G1")"
done
echo "CAD export (ccn_plan_export) of the production-like cages, into memory:"
for cage in carlike carlike_knots; do build/bench/export_bench "$D/$cage.obj" 3 || exit 2; done
echo "CAD export of OpenSubdiv's catmark_car (semi-sharp creases; target: <= 3,000 faces, <= 30 MB):"
shapes=$(tests/oracle/osd_shapes_deps.sh) && python3 tests/data/osd/extract_shapes.py "$shapes" "$D/osd" > /dev/null &&
  build/bench/export_bench "$D/osd/catmark_car.obj" 1 || exit 2
echo "One UV channel (the cages' box unwrap, --cap refine; target: <= 1.5x the plan without):"
echo "mesh level | plan | plan + uv | ratio | evaluate | evaluate + uv | ratio | memory MB | memory + uv MB | ratio"
for cage in sphere8k carlike carlike_knots; do
  for L in 2 3; do
    u=$(build/bench/ccn_bench "$D/$cage.obj" "$L" refine "$R" | grep '^ccn uv') || exit 2
    unum() { echo "$u" | sed -n "s/.*$1 \([0-9.]*\) \(s\|MB\).*/\1/p"; }
    p0=$(unum "plan"); p1=$(unum "plan [0-9.]* s, with uv"); e0=$(unum "evaluate"); e1=$(unum "evaluate [0-9.]* s, with uv")
    m0=$(unum "memory"); m1=$(unum "memory [0-9.]* MB, with uv")
    echo "$cage L$L | $p0 | $p1 | $(ratio "$p1" "$p0") | $e0 | $e1 | $(ratio "$e1" "$e0") | $m0 | $m1 | $(ratio "$m1" "$m0")"
  done
done
# ---- Blender: the modifier vs Subdivision Surface ----------------------------------------------
[ "${BENCH_BLENDER:-1}" = 0 ] && exit 0
blender_rows() { # label target-for-position-updates log: the target rows from bench_blender.py
  pos_t=$2; grep '^bench' "$3" | sed 's/^/  /'
  grep '^bench .* exact normals' "$3" | while read -r line; do
    what=$(echo "$line" | sed 's/^bench \([^ ]* L[0-9]\).*/\1/')
    sub=$(grep "^bench $what (.*subsurf pos" "$3" | head -n 1)
    get() { echo "$1" | sed -n "s/.* $2 \([0-9.]*\) s.*/\1/p"; }
    gr() { echo "$line" | sed -n "s/.* $1 [0-9.]* s (\([0-9.]*\)x.*/\1/p"; }
    row "position update, Object Mode, $what, Blender $1" "$(get "$line" pos) s" "$(get "$sub" pos) s" "$(gr pos)" "$pos_t"
    row "position update, Edit Mode, $what, Blender $1" "$(get "$line" edit) s" "$(get "$sub" edit) s" "$(gr edit)" "$pos_t"
    row "interval edit, $what, Blender $1" "$(get "$line" interval) s" "$(get "$sub" topo) s (Subsurf topology change)" "$(gr interval)" 1.0
    [ "$pos_t" = 0.5 ] && row "topology edit, $what, Blender $1" "$(get "$line" topo) s" "$(get "$sub" topo) s" "$(gr topo)" 1.5
  done
  grep '^bench animation' "$3" | while read -r line; do  # the playback row (target on 4.5/5.x)
    fps=$(echo "$line" | sed -n 's/.*ccnurbs \([0-9.]*\) fps.*/\1/p'); sfps=$(echo "$line" | sed -n 's/.*subsurf \([0-9.]*\) fps.*/\1/p')
    echo "target | animation playback, carlike L2 armature, Blender $1 | $fps fps | Subsurf $sfps fps | $(ratio 24 "$fps") | 1.0 (>= 24 fps) | $(verdict "$(ratio 24 "$fps")" 1.0)"
  done
}
tmp=$(mktemp -d) || exit 2
trap 'rm -rf "$tmp"' EXIT
if command -v blender > /dev/null; then
  v=$(blender --version 2>/dev/null | head -n 1 | cut -d' ' -f2)
  BLENDER_USER_SCRIPTS="$tmp/s34" BLENDER_USER_CONFIG="$tmp/c34" \
    blender --background --factory-startup --python-exit-code 1 \
    --python tests/blender/bench_blender.py -- "$D" build/ccnurbs.zip > "$tmp/b34.log" 2>&1
  blender_rows "$v" 1.0 "$tmp/b34.log"
fi
for line in ${BENCH_BPY_LINES:-4.5 5.3}; do
  py=$CACHE/venv-bpy-$line/bin/python
  [ -x "$py" ] && [ -f "$CACHE/venv-bpy-$line/.ok" ] || { echo "Blender $line: no bpy venv at $CACHE (make deps)"; continue; }
  d="$tmp/b$line"; mkdir -p "$d"
  BLENDER_USER_SCRIPTS="$d/s" BLENDER_USER_CONFIG="$d/c" BLENDER_USER_EXTENSIONS="$d/e" \
    BLENDER_USER_DATAFILES="$d/d" "$py" tests/blender/bench_blender.py "$D" build/ccnurbs.zip > "$d/log" 2>&1
  blender_rows "bpy $line" 0.5 "$d/log"
done
