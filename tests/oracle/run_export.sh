#!/bin/sh
# `ccnurbs export` (ccn_plan_export) vs OpenCASCADE (build/occt_read), the acceptance:
# cages: cube, torus, the Fig. 16-18 star cages (non-uniform intervals), the tear box
# (make_tearbox.py), n-gons (ngon_prism), boundaries (lshape, mixed_boundary),
# the 2.5k-face production-like cage (tests/bench/make_bench_cages.py), the cube with
# --cap refine (every EV a fill); creased cages: the cube with all edges infinitely sharp (6
# flat faces meeting C0), sharpness 1.5, a box with darts, a corner and a cone point
# (make_creased.py), eight of OpenSubdiv's creased regression shapes (inf_crease1: corners of
# three creases) and three of its cages of several parts (cubes_semisharp: four closed parts;
# xord_interior, quadstrips: open ones; from the cache `make deps` fills,
# tests/oracle/osd_shapes_deps.sh). For each, STEP and IGES:
#   - read with no load or transfer failure, the loops as written closed and every edge used at
#     most once each way, BRepCheck valid, one shell per part (as many as the export reports,
#     with no transfer warning that a shell was split), no edge with more than two face uses,
#     as many free edges as the export reports boundary edges (closed cages: closed shells
#     with positive volume), no sewing;
#   - normals across every shared edge <= 1e-8 rad except edges of fill faces (the counted
#     fallbacks, listed to occt_read --fallback), whose largest angle is printed (and held to
#     1e-8 too where the cage's fills are all G1, fill_g1 below), and crease
#     edges: OpenCASCADE's edges located on the cage through the face map (export_check.py)
#     that lie on an infinitely sharp cage edge of the file; as many as the export reports,
#     their angles printed;
#   - every sample of `ccnurbs limit` (same options) lies in a face (by the face map) and
#     OpenCASCADE's evaluation of that face there equals it <= 1e-9 x size (fills apart:
#     printed); every face that is one of the plan's patches equals `ccnurbs patches` on a 4x4
#     grid <= 1e-9 x size (tests/oracle/export_check.py);
#   - the IGES file gives the same figures as the STEP file.
# Then the packed export of regular tori with random ring intervals (nu_torus.py): exactly one
# periodic B-spline face whose knots are the ring intervals, equal to the B-spline OpenCASCADE
# builds from the cage's vertices and intervals (occt_read --build) <= 1e-12.
cd "$(dirname "$0")/../.." || exit 2
T=$(mktemp -d) || exit 2
trap 'rm -rf "$T"' EXIT
pass=0; fail=0; expect=""; fill_g1=""; smooth_g1=1e-8; closed_parts=0
val() { sed -n "s/^$1: //p" "$2" | head -n 1; }
le() { awk -v a="$1" -v b="$2" 'BEGIN { exit !(a != "" && a + 0 <= b + 0) }'; }
alike() { [ "$1" = "$2" ] || awk -v a="$1" -v b="$2" 'BEGIN { m = a > b ? a : b; d = a > b ? a - b : b - a
  exit !(a != "" && b != "" && a ~ /[.eE]/ && b ~ /[.eE]/ && (m <= 1e-11 || d <= 0.05 * m)) }'; }
python3 tests/oracle/make_tearbox.py "$T/tearbox.obj" || exit 2
python3 tests/oracle/make_creased.py "$T" || exit 2
OSD_DIR=$(sh tests/oracle/osd_shapes_deps.sh 2>/dev/null) && python3 tests/data/osd/extract_shapes.py "$OSD_DIR" "$T/osd" > /dev/null ||
  OSD_DIR="" 
python3 tests/bench/make_bench_cages.py "$T" > /dev/null || exit 2

check() { # name obj limit-level [options]
  name=$1 obj=$2 L=$3; shift 3
  e=""
  if ! build/ccnurbs export "$@" --face-map "$T/$name.map" "$obj" "$T/$name.step" > "$T/$name.info.step" 2> "$T/err" ||
     ! build/ccnurbs export "$@" --format iges "$obj" "$T/$name.igs" > "$T/$name.info.iges" 2>> "$T/err"; then
    fail=$((fail+1)); echo "FAIL $name: export: $(cat "$T/err")"; return
  fi
  awk '$1 == "F" && $3 == 4 { print $2 }' "$T/$name.map" > "$T/$name.fb"
  closed=$(val closed "$T/$name.info.step") bnd=$(val boundary_edges "$T/$name.info.step")
  shells=$(val shells "$T/$name.info.step") cshells=$closed_parts # closed parts of open cages
  [ "$closed" = 1 ] && cshells=$shells
  cap="" pat="--patches $T/$name.bv"
  case " $* " in
    *" --cap refine "*) cap="--cap refine" pat="" ;; # no patches at the EVs
    *" --cap fill "*) cap="--cap fill" ;;
  esac
  build/ccnurbs limit --levels "$L" $cap "$obj" "$T/$name.lim.obj" 2> /dev/null &&
    { [ -z "$pat" ] || build/ccnurbs patches $cap "$obj" "$T/$name.bv" 2> /dev/null; } &&
    python3 tests/oracle/export_check.py --cage "$obj" --limit "$T/$name.lim.obj" --map "$T/$name.map" \
      $pat --fallback "$T/$name.fb" --occt build/occt_read "$T/$name.step" "$T/$name.igs" > "$T/$name.chk" 2>&1 ||
    { fail=$((fail+1)); echo "FAIL $name: limit check: $(tail -n 3 "$T/$name.chk" 2> /dev/null)"; return; }
  for ext in step igs; do
    r="$T/$name.$ext.rep"
    grep -q "shell split\|split into" "$r.warn" && e="$e $ext:a shell was split"
    for kv in reader_status=done valid=1 shells=$shells edges_other=0 \
              file_loops_broken=0 file_edges_misused=0 \
              load_fails=0 transfer_fails=0 load_warnings=0 normal_undefined=0 closed_shells=$cshells \
              free_edges=$bnd faces=$(val faces "$T/$name.info.step"); do
      k=${kv%%=*} want=${kv#*=}
      [ "$(val "$k" "$r")" = "$want" ] || e="$e $ext:$k=$(val "$k" "$r")(want $want)"
    done
    if [ "$closed" = 1 ] && ! awk -v v="$(val volume "$r")" 'BEGIN { exit !(v > 0) }'; then e="$e $ext:volume"; fi
  done
  # counts equal; angles as the readers' own evaluation leaves them: equal to 5 %, or both
  # <= 1e-11 rad (each reader turns the same periodic faces periodic its own way)
  for k in faces edges vertices closed_shells free_edges normal_angle_max normal_angle_fallback_max; do
    alike "$(val $k "$T/$name.step.rep")" "$(val $k "$T/$name.igs.rep")" ||
      e="$e iges-differs:$k=$(val $k "$T/$name.step.rep")/$(val $k "$T/$name.igs.rep")"
  done
  for k in crease_edges crease_angle_min crease_angle_max smooth_angle_max fill_angle_max; do
    alike "$(val step_$k "$T/$name.chk")" "$(val iges_$k "$T/$name.chk")" ||
      e="$e iges-differs:$k=$(val step_$k "$T/$name.chk")/$(val iges_$k "$T/$name.chk")"
  done
  for k in faces packs bicubic bi5 refined fill_faces fills edges vertices closed max_g1_deviation max_fill_g1_deviation \
           crease_edges min_crease_angle max_crease_angle; do
    [ "$(val $k "$T/$name.info.step")" = "$(val $k "$T/$name.info.iges")" ] || e="$e iges-info-differs:$k"
  done
  c="$T/$name.chk"
  [ "$(val unmatched_vertices "$c")" = 0 ] || e="$e unmatched_limit_samples=$(val unmatched_vertices "$c")"
  for ext in step iges; do
    le "$(val ${ext}_smooth_angle_max "$c")" "$smooth_g1" || e="$e $ext:normal_angle_max=$(val ${ext}_smooth_angle_max "$c")"
    [ -z "$fill_g1" ] || le "$(val ${ext}_fill_angle_max "$c")" "$fill_g1" ||
      e="$e $ext:fill_angle_max=$(val ${ext}_fill_angle_max "$c")(want <= $fill_g1)"
    [ "$(val ${ext}_crease_edges "$c")" = "$(val crease_edges "$T/$name.info.step")" ] ||
      e="$e $ext:crease_edges=$(val ${ext}_crease_edges "$c")(export $(val crease_edges "$T/$name.info.step"))"
    [ "$(val ${ext}_edges_located_apart "$c")" = 0 ] || e="$e $ext:edges_located_apart=$(val ${ext}_edges_located_apart "$c")"
    le "$(val ${ext}_max_rel_dist "$c")" 1e-9 || e="$e $ext:limit_dist=$(val ${ext}_max_rel_dist "$c")"
    if [ -n "$(val faces_patch_checked "$c")" ] && [ "$(val faces_patch_checked "$c")" != 0 ]; then
      le "$(val ${ext}_patch_max_rel_dist "$c")" 1e-9 || e="$e $ext:patch_dist=$(val ${ext}_patch_max_rel_dist "$c")"
    fi
  done
  i="$T/$name.info.step"
  for kv in $expect; do # expectations of this cage
    k=${kv%%=*} w=${kv#*=}
    [ "$(val "$k" "$i")" = "$w" ] || e="$e $k=$(val "$k" "$i")(want $w)"
  done
  crease=""
  [ "$(val crease_edges "$i")" = 0 ] ||
    crease=" creases: $(val crease_edges "$i") C0 edges, angles $(val step_crease_angle_min "$c")..$(val step_crease_angle_max "$c") rad;"
  if [ -z "$e" ]; then
    pass=$((pass+1))
    echo "ok   $name: $(val faces "$i") faces ($(val packs "$i") packs, $(val bicubic "$i") bicubic, $(val bi5 "$i") bi-5, $(val refined "$i") refined, $(val fill_faces "$i") fill), closed=$closed, $(val bytes "$i") B; vs limit L$L: $(val step_samples "$c") samples $(val step_max_rel_dist "$c") x size, patches $(val step_patch_max_rel_dist "$c"); normals $(val step_smooth_angle_max "$c") rad;$crease fills: $(val fills "$i") (level $(val fill_level "$i")) G1 $(val step_fill_angle_max "$c") rad, dist $(val step_fill_max_rel_dist "$c") x size; STEP = IGES"
  else
    fail=$((fail+1)); echo "FAIL $name:$e"
  fi
}

# fill_g1: the largest normal angle OpenCASCADE may find across fill faces' edges (the fills are
# G1 across their spokes, io/fill_g1.c, and every edge carries its exact pcurves, so the reader
# places it on both faces without projecting; cone points close with degenerate corners)
fill_g1=1e-8
check cube tests/data/cube.obj 3
check cube_refine tests/data/cube.obj 3 --cap refine
check torus tests/data/torus.obj 3
check fig16_v6 tests/data/fig16_v6.obj 3
check fig17_v7 tests/data/fig17_v7.obj 3
check fig18_v8 tests/data/fig18_v8.obj 3
check star7_nu tests/data/star7_nu.obj 3
check star5_nu tests/data/star5_nu.obj 3
check tearbox "$T/tearbox.obj" 3
check ngon_prism tests/data/ngon_prism.obj 3
check lshape tests/data/lshape.obj 3
check fan64 tests/data/fan64.obj 3
# the G1 fill caps (--cap fill): the holes of the non-uniform EVs are the plan's own fill patches
# (one merged face per sector, counted as bi-5), no hole left there
expect="bi5=8 fill_faces=8"
check fig18_fill tests/data/fig18_v8.obj 3 --cap fill
expect="bi5=5 fill_faces=5"
check star5_fill tests/data/star5_nu.obj 3 --cap fill
expect=""
check tearbox_fill "$T/tearbox.obj" 3 --cap fill
check mixed_boundary tests/data/mixed_boundary.obj 3
check carlike_2.5k "$T/carlike.obj" 1
expect="faces=6 packs=6 edges=12 vertices=8 closed=1 crease_edges=12 min_crease_angle=1.571e+00 max_crease_angle=1.571e+00"
check cube_sharp "$T/cube_sharp.obj" 3
expect=""
for ext in step igs; do # the unit cube's six flat faces bound volume 1
  v=$(val volume "$T/cube_sharp.$ext.rep")
  if awk -v v="$v" 'BEGIN { d = v - 1; exit !(v != "" && d < 1e-9 && d > -1e-9) }'; then
    pass=$((pass+1)); echo "ok   cube_sharp .$ext: OpenCASCADE's volume $v"
  else fail=$((fail+1)); echo "FAIL cube_sharp .$ext: volume $v, expected 1"; fi
done
check cube_semi "$T/cube_semi.obj" 3
check crease_band tests/data/crease_band.obj 3 # bands of every level and packs merged into one face
check crease_tube tests/data/crease_tube.obj 3 # closed bands of every level merged around the tube
check dart_corner "$T/dart_corner.obj" 3
if [ -n "$OSD_DIR" ]; then
  for s in inf_crease0 inf_crease1 cube_creases2 single_crease torus_creases1 dart_edgecorner fvar_project0 cube_corner4; do
    check "osd_$s" "$T/osd/catmark_$s.obj" 3
  done
  for s in cubes_semisharp xord_interior quadstrips; do
    check "osd_$s" "$T/osd/catmark_$s.obj" 3
  done
  # interior valence-2 vertices (fills three levels earlier than elsewhere: fill.h), at the
  # origin and 100 times its size away (computed relative to the model; what is left there is
  # the rounding of the file's absolute coordinates next to the fills' degenerate corners)
  closed_parts=1 # nine parts, one closed
  check osd_val2_interior "$T/osd/catmark_val2_interior.obj" 3
  check osd_gregory_test8 "$T/osd/catmark_gregory_test8.obj" 3
  awk '$1 == "v" { printf "v %.17g %.17g %.17g\n", $2 + 500, $3 + 500, $4 + 500; next } { print }' \
    "$T/osd/catmark_val2_interior.obj" > "$T/val2_far.obj"
  fill_g1=5e-7 smooth_g1=5e-8
  check osd_val2_interior_far "$T/val2_far.obj" 3
  fill_g1=1e-8 smooth_g1=1e-8 closed_parts=0
else
  fail=$((fail+1)); echo "FAIL OpenSubdiv's creased shapes: not available (tests/oracle/osd_shapes_deps.sh)"
fi

# OpenSubdiv's car (1,575 cage faces, 314 semi-sharp edges, 31 parts, 100 seams of periodic
# faces), read back only (its limit samples would take a minute): both files valid, one shell
# per part and no reader repair (an IGES pcurve run against its use turned faces over), every
# shared edge G1 <= 1e-8 rad as OpenCASCADE reads it (fills included), the STEP file <= 30 MB.
if [ -n "$OSD_DIR" ]; then
  for ext in step igs; do
    r="$T/car.$ext.rep"
    if build/ccnurbs export "$T/osd/catmark_car.obj" "$T/car.$ext" > "$T/car.$ext.info" 2>&1 &&
       build/occt_read "$T/car.$ext" > "$r" 2> "$r.warn"; then
      e=""
      for kv in valid=1 shells=31 load_fails=0 transfer_fails=0 normal_undefined=0 edges_other=0; do
        [ "$(val "${kv%%=*}" "$r")" = "${kv#*=}" ] || e="$e ${kv%%=*}=$(val "${kv%%=*}" "$r")"
      done
      ! grep -q "incorrectly oriented\|split into" "$r.warn" || e="$e reader-repaired"
      le "$(val normal_angle_max "$r")" 1e-8 || e="$e normal_angle_max=$(val normal_angle_max "$r")"
      [ "$ext" != step ] || le "$(val bytes "$T/car.$ext.info")" 30000000 || e="$e bytes=$(val bytes "$T/car.$ext.info")"
      if [ -z "$e" ]; then
        pass=$((pass+1)); echo "ok   osd_car .$ext: $(val faces "$r") faces, $(val shells "$r") shells, $(val bytes "$T/car.$ext.info") B, normals across edges <= $(val normal_angle_max "$r") rad"
      else fail=$((fail+1)); echo "FAIL osd_car .$ext:$e"; fi
    else fail=$((fail+1)); echo "FAIL osd_car .$ext: export or read failed"; fi
  done
fi

# The CLI contract: errors print a message, exit 2 and leave no output file (nor a temporary).
printf 'v 0 0 0\nv 1 0 nan\nv 0 1 0\nf 1 2 3\n' > "$T/nan.obj"
cli_error() { # name message args...
  n=$1 msg=$2; shift 2
  rm -f "$T/out.step" "$T/out.map"
  build/ccnurbs export "$@" > /dev/null 2> "$T/stderr"; rc=$?
  if [ "$rc" -ne 2 ] || ! grep -q -- "$msg" "$T/stderr" || [ -e "$T/out.step" ] || [ -e "$T/out.map" ] ||
     ls "$T"/out.step.tmp* "$T"/out.map.tmp* > /dev/null 2>&1; then
    fail=$((fail+1)); echo "FAIL cli $n: exit $rc, $(cat "$T/stderr")"
  else pass=$((pass+1)); echo "ok   cli $n: exit 2, '$msg', no output"; fi
}
cli_error "bad format" "bad --format" --format dxf tests/data/cube.obj "$T/out.step"
cli_error "NaN vertex" "vertex 1 has a non-finite" --face-map "$T/out.map" "$T/nan.obj" "$T/out.step"
cli_error "missing input" "cannot open" "$T/none.obj" "$T/out.step"
cli_error "bad fill levels" "fill-levels" --fill-levels 0 tests/data/cube.obj "$T/out.step"
cli_error "quote in name" "printable ASCII" --name "a'b" tests/data/cube.obj "$T/out.step"
cli_error "bad cap" "bad --cap" --cap foo tests/data/cube.obj "$T/out.step"
cli_error "no output path" "need an input and an output" tests/data/cube.obj
cli_error "unwritable output" "cannot write" tests/data/cube.obj "$T/no/such/dir/out.step"

# Packed export of regular tori with random ring intervals.
griddiff() { # max |xyz| difference and max parameter difference, rows matched by (face, i, j)
  awk 'NR == FNR { k = $1 " " $2 " " $3; x[k] = $6; y[k] = $7; z[k] = $8; u[k] = $4; v[k] = $5; next }
       { k = $1 " " $2 " " $3; if (!(k in x)) { miss++; next }
         n++; for (c = 6; c <= 8; c++) { d = $c - (c == 6 ? x[k] : c == 7 ? y[k] : z[k]); if (d < 0) d = -d; if (d > m) m = d }
         d = $4 - u[k]; if (d < 0) d = -d; e = $5 - v[k]; if (e < 0) e = -e; if (d > pm) pm = d; if (e > pm) pm = e }
       END { printf "%d %.3e %.3e %d\n", n, m, pm, miss + 0 }' "$1" "$2"
}
for seed in 1 2 3; do
  python3 tests/oracle/nu_torus.py $seed "$T/nut.obj" "$T/nut_build.txt" &&
    build/ccnurbs export "$T/nut.obj" "$T/nut.step" > "$T/p" 2>&1 &&
    build/ccnurbs export "$T/nut.obj" "$T/nut.igs" >> "$T/p" 2>&1 &&
    build/occt_read --build "$T/nut_build.txt" --grid 9 --points "$T/built.pts" > /dev/null 2>&1 ||
    { fail=$((fail+1)); echo "FAIL torus seed $seed: $(cat "$T/p")"; continue; }
  for ext in step igs; do
    r="$T/nut.$ext.rep"
    build/occt_read --grid 9 --points "$T/nut.$ext.pts" "$T/nut.$ext" > "$r" 2> /dev/null
    e=""
    for kv in valid=1 faces=1 edges=2 vertices=1 closed_shells=1 edges_seam=2 file_loops_broken=0; do
      k=${kv%%=*} want=${kv#*=}
      [ "$(val "$k" "$r")" = "$want" ] || e="$e $k=$(val "$k" "$r")"
    done
    line=$(grep '^face 0:' "$r")
    case "$line" in *"upoles 8 vpoles 6 uperiodic 1 vperiodic 1"*) ;; *) e="$e not-one-periodic-8x6-face" ;; esac
    got=$(echo "$line" | sed 's/.* uknots [0-9]* \([^a-z]*\) umults.* vknots [0-9]* \([^a-z]*\) vmults.*/\1 \2/')
    want=$(sed -n 's/^[uv]knots [0-9]* //p' "$T/nut_build.txt" | tr '\n' ' ')
    awk -v a="$got" -v b="$want" 'BEGIN { n = split(a, x, " "); m = split(b, y, " "); if (n != m) exit 1
      for (i = 1; i <= n; i++) { d = x[i] - y[i]; if (d < 0) d = -d; if (d > 1e-12) exit 1 } }' || e="$e knots($got)!=($want)"
    set -- $(griddiff "$T/built.pts" "$T/nut.$ext.pts")
    awk -v n="$1" -v d="$2" -v p="$3" 'BEGIN { exit !(n == 81 && d <= 1e-12 && p <= 1e-12) }' || e="$e surface-diff=$2 param-diff=$3 points=$1"
    if [ -z "$e" ]; then
      pass=$((pass+1)); echo "ok   packed NU torus seed $seed .$ext: one periodic face, knots = ring intervals, = OCCT's B-spline of the cage (diff $2)"
    else
      fail=$((fail+1)); echo "FAIL packed NU torus seed $seed .$ext:$e"
    fi
  done
done
echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
