#!/bin/sh
# Limit positions vs OpenSubdiv (uniform intervals): `ccnurbs limit --cap refine` at level L
# samples exactly the level-L refined vertices; OpenSubdiv's PrimvarRefiner::Limit gives
# their limit positions. Every vertex must agree <= 1e-9 of the bounding-box size.
cd "$(dirname "$0")/../.." || exit 2
CLI=${CCNURBS:-build/ccnurbs}
T=$(mktemp -d) || exit 2
trap 'rm -rf "$T"' EXIT
pass=0; fail=0
for cage in tests/data/*.obj; do
  grep -q "^# knot" "$cage" && continue # non-uniform knots: not comparable with OpenSubdiv
  name=$(basename "$cage")
  for L in 1 2 3; do
    for corners in smooth pinned; do
      build/osd_refine --limit --levels "$L" --corners "$corners" "$cage" "$T/ref.obj" 2>"$T/err" || { fail=$((fail+1)); echo "FAIL $name osd: $(cat "$T/err")"; continue; }
      for scheme in cc eigen nurss; do
        if "$CLI" limit --cap refine --scheme $scheme --levels "$L" --corners "$corners" "$cage" "$T/out.obj" 2>"$T/err" &&
           r=$(build/objdiff --tol-rel 1e-9 "$T/out.obj" "$T/ref.obj" 2>&1); then
          pass=$((pass+1)); echo "ok   $name L$L $corners $scheme $r"
        else
          fail=$((fail+1)); echo "FAIL $name L$L $corners $scheme ${r:-$(cat "$T/err")}"
        fi
      done
    done
  done
done
echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
