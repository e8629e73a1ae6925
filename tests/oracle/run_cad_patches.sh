#!/bin/sh
# Unpacked export prototype vs OpenCASCADE on every cage of tests/data: cad_from_patches turns
# the plan's finite patch set (ccn_plan_patches: bicubic patches, bi-5 rings and caps) into
# one Bezier face per patch, finds T-junctions and shared edges from the geometry, and writes
# STEP and IGES. For each file: read without fails, BRepCheck valid, one shell per connected
# component of the patch set (one shell once the holes are filled), the loops as
# written closed head to tail with every edge used at most once each way, no edge with more
# than two face uses, as many two-face edges as shared segment pairs and free edges as
# boundary segments (skipped faces leave holes until the library export fills them), closed
# with positive volume when nothing is open, normals across every shared edge <= 1e-8 rad.
cd "$(dirname "$0")/../.." || exit 2
T=$(mktemp -d) || exit 2
trap 'rm -rf "$T"' EXIT
pass=0; fail=0
val() { sed -n "s/^$1: //p" "$2" | head -n 1; }
for cage in tests/data/*.obj; do
  name=$(basename "$cage" .obj)
  if ! build/cad_from_patches "$cage" "$T/$name.step" "$T/$name.igs" >"$T/p" 2>"$T/err"; then
    fail=$((fail+1)); echo "FAIL $name: cad_from_patches: $(cat "$T/p" "$T/err" | tr '\n' ' ')"; continue
  fi
  shared=$(val shared_segments "$T/p") open=$(val boundary_segments "$T/p") comps=$(val components "$T/p")
  closed=0; [ "$open" = 0 ] && closed=1
  for ext in step igs; do
    r="$T/$name.$ext.rep"
    build/occt_read "$T/$name.$ext" >"$r" 2>/dev/null
    e=""
    for kv in reader_status=done valid=1 shells=$comps edges_other=0 file_loops_broken=0 \
              file_edges_misused=0 load_fails=0 transfer_fails=0 normal_undefined=0 \
              closed_shells=$closed edges_two_faces=$((shared / 2)) free_edges=$open; do
      k=${kv%%=*} want=${kv#*=}
      [ "$(val "$k" "$r")" = "$want" ] || e="$e $k=$(val "$k" "$r")(want $want)"
    done
    ang=$(val normal_angle_max "$r")
    awk -v a="$ang" 'BEGIN { exit !(a != "" && a <= 1e-8) }' || e="$e normal_angle_max=$ang"
    vol=$(val volume "$r")
    if [ "$closed" = 1 ] && ! awk -v v="$vol" 'BEGIN { exit !(v > 0) }'; then e="$e volume=$vol"; fi
    if [ -z "$e" ]; then
      pass=$((pass+1))
      echo "ok   $name.$ext: $(val patches "$T/p") faces ($(val bi5 "$T/p") bi-5), $(val side_breaks "$T/p") T-breaks, closed=$closed, max normal angle $ang"
    else
      fail=$((fail+1)); echo "FAIL $name.$ext:$e"
    fi
  done
done
echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
