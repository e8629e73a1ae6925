#!/bin/sh
# Face-varying channels (UV maps) of OpenSubdiv's regression shapes vs OpenSubdiv.
#
# Every in-scope catmark_* shape (tests/data/osd/extract_shapes.py --scope: no degenerate face)
# that has a UV map (`vt` lines, `f v/vt` corners): the catmark_fvar_* shapes, cube, car, bishop,
# pawn, rook, helmet, the gregory tests and the rest. build/fvar_oracle checks, per shape, level
# 1..3, scheme cc and eigen (the shapes' equal intervals) and each of OpenSubdiv's six
# FVarLinearInterpolation modes, the refined values (ccn_fvar_refine vs InterpolateFaceVarying)
# and the limit values (ccn_plan_evaluate_fvar vs OpenSubdiv's exact limits) per face corner,
# <= 1e-9 of the UV bounding box (and the corner positions, so the corners are the same).
# Then the CLI's UV path (OBJ vt in and out) on three shapes against osd_refine's vt output,
# per face corner (objdiff --uv). One line per shape, level and scheme (and CLI comparison),
# then "N passed, N failed". Shapes come as for
# tests/oracle/run_osd_shapes.sh (OSD_SHAPES, or the cache tests/oracle/osd_shapes_deps.sh fills).
# Environment (optional): OSD_SHAPES, OSD_SHAPES_ONLY (names), FVAR_LEVELS (default "1 2 3"),
# FVAR_SCHEMES (default cc,eigen), ORACLE_TIMEOUT (seconds per shape, default 120).
# Two non-manifold shapes are left out: catmark_nonman_edge100, whose limit OpenSubdiv 3.5
# cannot compute (PrimvarRefiner::Limit writes past its weight buffer at an edge of 100 faces;
# run_osd_shapes.sh compares its refinement), and catmark_fan, whose UVs differ across its
# non-manifold edges: OpenSubdiv makes every value at a non-manifold vertex a corner once the
# values differ across any of its edges (Vtr::FVarLevel, gatherValueSpans), also at the
# vertices inside a non-manifold crease and at the points refinement puts on such edges, where
# ccnurbs applies the crease rule of each fan (docs/creases.md, "Non-manifold cages").
cd "$(dirname "$0")/../.." || exit 2

TOOL=build/fvar_oracle
SRC=${OSD_SHAPES:-}
if [ -z "$SRC" ]; then
  SRC=$(sh tests/oracle/osd_shapes_deps.sh 2>/dev/null) || {
    echo "FAIL OpenSubdiv's shapes are not available (tests/oracle/osd_shapes_deps.sh failed)"
    echo "0 passed, 1 failed"; exit 1; }
fi
if [ ! -x "$TOOL" ]; then
  echo "FAIL tool $TOOL is missing (make $TOOL)"; echo "0 passed, 1 failed"; exit 1
fi
TO=
if command -v timeout >/dev/null 2>&1; then TO="timeout ${ORACLE_TIMEOUT:-120}"; fi

tmp=$(mktemp -d "${TMPDIR:-/tmp}/ccn_fvar_shapes.XXXXXX") || exit 2
trap 'rm -rf "$tmp"' EXIT
trap 'exit 130' INT TERM

dir=$SRC
if ! ls "$SRC"/catmark_*.obj >/dev/null 2>&1; then
  if ls "$SRC"/catmark_*.h >/dev/null 2>&1 &&
     python3 tests/data/osd/extract_shapes.py "$SRC" "$tmp/shapes" >/dev/null; then
    dir=$tmp/shapes
  else
    echo "FAIL no OpenSubdiv shapes in $SRC"; echo "0 passed, 1 failed"; exit 1
  fi
fi
scope=$(python3 tests/data/osd/extract_shapes.py --scope "$dir") || {
  echo "FAIL extract_shapes.py --scope $dir failed"; echo "0 passed, 1 failed"; exit 1; }
[ -n "${OSD_SHAPES_ONLY:-}" ] && scope=$OSD_SHAPES_ONLY

pass=0; fail=0; shapes=0
# fvar_oracle on one OBJ ($1; $2 names it in a failure): its lines, and its counts added up
oracle_run() {
  in=$1
  $TO "$TOOL" --levels "${FVAR_LEVELS:-1 2 3}" --schemes "${FVAR_SCHEMES:-cc,eigen}" "$in" >"$tmp/out" 2>&1
  rc=$?
  grep -v 'passed, .* failed$' "$tmp/out"
  p=$(sed -n 's/^\([0-9]*\) passed, \([0-9]*\) failed$/\1/p' "$tmp/out")
  f=$(sed -n 's/^\([0-9]*\) passed, \([0-9]*\) failed$/\2/p' "$tmp/out")
  if [ -z "$p" ] || { [ "$rc" -ne 0 ] && [ "${f:-0}" -eq 0 ]; }; then
    echo "FAIL $2 fvar_oracle exited $rc"; fail=$((fail + 1)); p=${p:-0}; f=0
  fi
  pass=$((pass + p)); fail=$((fail + f))
}

for name in $scope; do
  case $name in catmark_nonman_edge100|catmark_fan) continue ;; esac
  in="$dir/$name.obj"
  grep -q '^vt' "$in" 2>/dev/null || continue
  shapes=$((shapes + 1))
  oracle_run "$in" "$name"
done
[ "$shapes" -gt 0 ] || { echo "FAIL no shape with a UV map"; fail=$((fail + 1)); }

# Cages of our own for what the shapes lack: OpenSubdiv's dependent sharpness (a semi-sharp
# crease ending at a seam, CORNERS_PLUS1/2), its A, B, A, B sibling count (NONE), and a
# 64-sided cylinder with Blender's UVs, whose cap disks are evaluated through the channel's
# levels rather than composed (surface/fvar_compose.c: too many probe colours).
for in in tests/data/fvar_dependent.obj tests/data/fvar_abab.obj tests/data/fvar_cylinder64.obj; do
  oracle_run "$in" "$in"
done

# The CLI's UV path (OBJ vt in, refined / limit vt out) on a few shapes, against osd_refine's
# vt output, compared per face corner by build/objdiff --uv (vertex and face order free).
CCN=${CCNURBS:-build/ccnurbs}
for name in ${FVAR_CLI_SHAPES:-catmark_fvar_bound1 catmark_fvar_bound3 catmark_cube}; do
  in="$dir/$name.obj"
  [ -f "$in" ] || { echo "FAIL $name: no $in"; fail=$((fail + 1)); continue; }
  for mode in corners-plus1 boundaries none; do
    for kind in refine limit; do
      if [ $kind = refine ]; then
        $TO "$CCN" refine --scheme eigen --levels 2 --fvar-linear $mode "$in" "$tmp/c.obj" >"$tmp/log" 2>&1 &&
          $TO build/osd_refine --levels 2 --fvar-linear $mode "$in" "$tmp/o.obj" >>"$tmp/log" 2>&1
      else
        $TO "$CCN" limit --cap refine --scheme eigen --levels 2 --fvar-linear $mode "$in" "$tmp/c.obj" >"$tmp/log" 2>&1 &&
          $TO build/osd_refine --limit --levels 2 --fvar-linear $mode "$in" "$tmp/o.obj" >>"$tmp/log" 2>&1
      fi
      if [ $? -ne 0 ]; then echo "FAIL $name CLI $kind $mode: $(head -c 300 "$tmp/log")"; fail=$((fail + 1)); continue; fi
      if msg=$(build/objdiff --uv 1e-9 "$tmp/o.obj" "$tmp/c.obj" 2>&1); then
        echo "ok   $name CLI L2 eigen $kind --fvar-linear $mode: $msg"; pass=$((pass + 1))
      else
        echo "FAIL $name CLI L2 eigen $kind --fvar-linear $mode: $msg"; fail=$((fail + 1))
      fi
    done
  done
done
echo "$shapes shapes with UV maps"
echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ] && [ "$pass" -gt 0 ]
