#!/bin/sh
# Principal curvatures on caps and patches against OpenCASCADE: `ccnurbs limit --curvature`
# (level 6) vs OpenCASCADE's curvature of the faces `ccnurbs export` writes (build/occt_read
# --curvature, a 9 x 9 grid per face), at every sample inside a face that is a limit vertex
# (tests/oracle/curvature_check.py): within 1e-9 of the largest |k|. The cages have caps at
# valence 3 and 5 (uniform intervals), a boundary EV, a jittered sphere and a non-uniform
# valence-6 EV. Regular non-uniform regions are checked against a B-spline written in
# tests/c/test_curvature.c.
cd "$(dirname "$0")/../.." || exit 2
T=$(mktemp -d) || exit 2
trap 'rm -rf "$T"' EXIT
pass=0; fail=0
for c in cube fan5 pentaprism jitter_sphere fig16_v6; do
  f=tests/data/$c.obj
  if build/ccnurbs export --format step "$f" "$T/$c.step" > /dev/null 2> "$T/err" &&
     build/occt_read --grid 9 --points "$T/$c.pts" --curvature "$T/$c.step" > /dev/null 2>> "$T/err" &&
     build/ccnurbs limit --levels 6 --curvature "$f" "$T/$c.ply" 2>> "$T/err" &&
     python3 tests/oracle/curvature_check.py "$T/$c.ply" "$T/$c.pts" 1e-9 > "$T/out" 2>> "$T/err"; then
    pass=$((pass+1)); echo "ok   $c: $(cat "$T/out")"
  else
    fail=$((fail+1)); echo "FAIL $c: $(cat "$T/out" 2>/dev/null) $(tail -3 "$T/err")"
  fi
done
echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
