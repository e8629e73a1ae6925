#!/bin/sh
# Unpacked export prototype vs OpenCASCADE on every cage of tests/data: cad_from_patches turns
# the plan's finite patch set (ccn_plan_patches: bicubic patches, bi-5 rings and caps) into
# one Bezier face per patch, finds T-junctions and shared edges from the geometry, and writes
# STEP and IGES. For each file: read without fails, BRepCheck valid, one shell per connected
# component of the patch set (one shell once the holes are filled), the loops as
# written closed head to tail with every edge used at most once each way, no edge with more
# than two face uses, as many two-face and seam edges as shared segment pairs and free edges as
# boundary segments (skipped faces leave holes until the library export fills them), closed
# with positive volume when nothing is open, normals across every shared edge <= 1e-8 rad;
# then the same with --packed (packs of strict-regular cage quads), and the packed NU tori.
cd "$(dirname "$0")/../.." || exit 2
T=$(mktemp -d) || exit 2
trap 'rm -rf "$T"' EXIT
pass=0; fail=0
val() { sed -n "s/^$1: //p" "$2" | head -n 1; }
for mode in unpacked packed; do
for cage in tests/data/*.obj; do
  name=$(basename "$cage" .obj)
  flag=""; [ "$mode" = packed ] && flag=--packed
  if ! build/cad_from_patches $flag "$cage" "$T/$name.step" "$T/$name.igs" >"$T/p" 2>"$T/err"; then
    fail=$((fail+1)); echo "FAIL $name: cad_from_patches: $(cat "$T/p" "$T/err" | tr '\n' ' ')"; continue
  fi
  [ "$mode" = packed ] && [ "$(val packs "$T/p")" = 0 ] && continue # same as unpacked
  shared=$(val shared_segments "$T/p") open=$(val boundary_segments "$T/p") comps=$(val components "$T/p")
  closed=0; [ "$open" = 0 ] && closed=1
  for ext in step igs; do
    r="$T/$name.$ext.rep"
    build/occt_read "$T/$name.$ext" >"$r" 2>/dev/null
    e=""
    for kv in reader_status=done valid=1 shells=$comps edges_other=0 file_loops_broken=0 \
              file_edges_misused=0 load_fails=0 transfer_fails=0 normal_undefined=0 \
              closed_shells=$closed free_edges=$open; do
      k=${kv%%=*} want=${kv#*=}
      [ "$(val "$k" "$r")" = "$want" ] || e="$e $k=$(val "$k" "$r")(want $want)"
    done
    [ $(( $(val edges_two_faces "$r") + $(val edges_seam "$r") )) = $((shared / 2)) ] ||
      e="$e edges_two_faces+seams=$(val edges_two_faces "$r")+$(val edges_seam "$r")(want $((shared / 2)))"
    ang=$(val normal_angle_max "$r")
    awk -v a="$ang" 'BEGIN { exit !(a != "" && a <= 1e-8) }' || e="$e normal_angle_max=$ang"
    vol=$(val volume "$r")
    if [ "$closed" = 1 ] && ! awk -v v="$vol" 'BEGIN { exit !(v > 0) }'; then e="$e volume=$vol"; fi
    if [ -z "$e" ]; then
      pass=$((pass+1))
      echo "ok   $mode $name.$ext: $(val faces "$T/p") faces ($(val packs "$T/p") packs, $(val bi5 "$T/p") bi-5), $(val side_breaks "$T/p") T-breaks, closed=$closed, max normal angle $ang"
    else
      fail=$((fail+1)); echo "FAIL $mode $name.$ext:$e"
    fi
  done
done
done
# Packed export of regular tori with random ring intervals (tests/oracle/nu_torus.py): exactly
# one periodic B-spline face whose knots are the ring intervals, equal to the B-spline that
# OpenCASCADE builds from the cage's vertices and intervals (occt_read --build) <= 1e-12.
griddiff() { # max |xyz| difference and max parameter difference, rows matched by (face, i, j)
  awk 'NR == FNR { k = $1 " " $2 " " $3; x[k] = $6; y[k] = $7; z[k] = $8; u[k] = $4; v[k] = $5; next }
       { k = $1 " " $2 " " $3; if (!(k in x)) { miss++; next }
         n++; for (c = 6; c <= 8; c++) { d = $c - (c == 6 ? x[k] : c == 7 ? y[k] : z[k]); if (d < 0) d = -d; if (d > m) m = d }
         d = $4 - u[k]; if (d < 0) d = -d; e = $5 - v[k]; if (e < 0) e = -e; if (d > pm) pm = d; if (e > pm) pm = e }
       END { printf "%d %.3e %.3e %d\n", n, m, pm, miss + 0 }' "$1" "$2"
}
for seed in 1 2 3; do
  python3 tests/oracle/nu_torus.py $seed "$T/nut.obj" "$T/nut_build.txt" &&
    build/cad_from_patches --packed "$T/nut.obj" "$T/nut.step" "$T/nut.igs" >"$T/p" 2>&1 &&
    build/occt_read --build "$T/nut_build.txt" --grid 9 --points "$T/built.pts" >/dev/null 2>&1 ||
    { fail=$((fail+1)); echo "FAIL torus seed $seed: $(cat "$T/p")"; continue; }
  for ext in step igs; do
    r="$T/nut.$ext.rep"
    build/occt_read --grid 9 --points "$T/nut.$ext.pts" "$T/nut.$ext" >"$r" 2>/dev/null
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
