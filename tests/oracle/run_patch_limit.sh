#!/bin/sh
# build/osd_refine --patch-limit (OpenSubdiv's adaptive patch table evaluated as Blender's
# Subdivision Surface does; tests/oracle/osd_patch.cpp) against the exact limit (--limit),
# relative to the bounding box, vertices matched by build/objdiff:
#   tests/data cages without knots, levels 1-3: pinned corners equal <= 1e-12 (regular
#     patches are exact and an end cap's corner is its vertex's limit mask, so this checks
#     the ptex placement, n-gons included); smooth corners <= 1e-7 (OpenSubdiv's legacy
#     sharp-corner patches, a default Blender keeps, stand in for them at the isolation level).
#   case_creases' cubes (Blender's default cube, sharpness 10 c^2), level 2: semi-sharp
#     creases only: equal <= 1e-12; edge creases 0.5, 1, 1 and vertex crease 0.7 (the two
#     infinitely sharp edges end at four darts): off by 1e-5..5e-5 at isolation 10 (Blender's
#     2.3e-5), closer with every isolation level 5..10, farther without inf-sharp patches.
cd "$(dirname "$0")/../.." || exit 2
OSD=build/osd_refine
T=$(mktemp -d) || exit 2
trap 'rm -rf "$T"' EXIT
pass=0; fail=0
ok() { pass=$((pass+1)); echo "ok   $*"; }
bad() { fail=$((fail+1)); echo "FAIL $*"; }
# rel A B: max relative distance of A's vertices to B's (objdiff with no tolerance to speak of)
rel() { build/objdiff --tol-rel 1 "$1" "$2" | sed -n 's/^ok: .*max_rel //p'; }
# le X Y: X <= Y (floating point)
le() { awk -v x="$1" -v y="$2" 'BEGIN { exit !(x != "" && x + 0 <= y + 0) }'; }

for cage in tests/data/*.obj; do
  grep -q "^# knot" "$cage" && continue
  name=$(basename "$cage")
  for L in 1 2 3; do
    for corners in pinned smooth; do
      tol=1e-12; [ "$corners" = smooth ] && tol=1e-7
      if $OSD --levels "$L" --corners "$corners" --limit "$cage" "$T/ex.obj" 2>"$T/err" &&
         $OSD --levels "$L" --corners "$corners" --patch-limit "$cage" "$T/pt.obj" 2>"$T/err"; then
        r=$(rel "$T/pt.obj" "$T/ex.obj")
        if le "$r" "$tol"; then ok "$name L$L $corners patch-limit vs limit $r <= $tol"
        else bad "$name L$L $corners patch-limit vs limit ${r:-no match} > $tol"; fi
      else
        bad "$name L$L $corners: $(cat "$T/err")"
      fi
    done
  done
done

# Blender's default cube (primitive_cube_add size=2): vertices, faces and the edges case_creases
# creases (edge 0: 3-1, edge 1: 1-2, edge 5: 4-8; vertex 3 is vertex 4 here).
cube() {
  printf 'v -1 -1 -1\nv -1 -1 1\nv -1 1 -1\nv -1 1 1\nv 1 -1 -1\nv 1 -1 1\nv 1 1 -1\nv 1 1 1\n'
  printf 'f 1 2 4 3\nf 3 4 8 7\nf 7 8 6 5\nf 5 6 2 1\nf 3 7 5 1\nf 8 4 2 6\n'
}
{ cube; printf '# crease 3 1 2.5\n# crease 1 2 10\n# crease 4 8 10\n# corner 4 4.9\n'; } >"$T/crease.obj"
{ cube; printf '# crease 3 1 2.5\n# crease 2 4 6.4\n# corner 4 4.9\n'; } >"$T/semi.obj"

$OSD --levels 2 --limit "$T/semi.obj" "$T/ex.obj" && $OSD --levels 2 --patch-limit "$T/semi.obj" "$T/pt.obj" &&
  r=$(rel "$T/pt.obj" "$T/ex.obj") && le "$r" 1e-12 &&
  ok "semi-sharp cube L2 patch-limit vs limit $r <= 1e-12" ||
  bad "semi-sharp cube L2 patch-limit vs limit ${r:-failed} > 1e-12"

$OSD --levels 2 --limit "$T/crease.obj" "$T/ex.obj" || bad "creased cube: --limit failed"
prev=1; row=""
for N in 5 6 7 8 9 10; do
  $OSD --levels 2 --patch-limit --isolation "$N" "$T/crease.obj" "$T/pt.obj" && r=$(rel "$T/pt.obj" "$T/ex.obj")
  row="$row N=$N:$r"
  if le "$r" "$prev" && ! le "$r" 1e-12; then :; else bad "creased cube isolation $N: ${r:-failed} not in (0, $prev)"; fi
  prev=$r
done
if le 1e-5 "$prev" && le "$prev" 5e-5; then ok "creased cube L2 patch-limit vs limit, closer with isolation:$row"
else bad "creased cube L2 isolation 10: $prev not in 1e-5..5e-5:$row"; fi
$OSD --levels 2 --patch-limit --inf-sharp-patch 0 "$T/crease.obj" "$T/pt.obj" && r=$(rel "$T/pt.obj" "$T/ex.obj")
if ! le "$r" "$prev"; then ok "creased cube L2 without inf-sharp patches: $r (> $prev)"
else bad "creased cube L2 without inf-sharp patches: ${r:-failed} not > $prev"; fi
$OSD --levels 2 --patch-limit --endcap bspline "$T/crease.obj" "$T/pt.obj" && r=$(rel "$T/pt.obj" "$T/ex.obj")
if [ "$r" = "$prev" ]; then ok "creased cube L2 with B-spline end caps: $r (the same at the vertices)"
else bad "creased cube L2 with B-spline end caps: ${r:-failed}, Gregory $prev"; fi

echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
