#!/bin/sh
# Fairness of a cap measured on the output meshes (tests/experiments/cap_mesh_table.c):
#   tests/experiments/cap_mesh_table.sh bi5|blend [cases] [level] [seed]
# bi5: the library as it ships (HEAD). blend: the research build with
# tests/experiments/cap_blend.patch applied to HEAD's sources (the blended cap, RESULTS.md).
# Measure at level 7 too: coarser levels under-sample a narrow blend band.
cd "$(dirname "$0")/../.." || exit 2
B=${B:-build}
case $B in /*) out=$B/cap_mesh ;; *) out=$PWD/$B/cap_mesh ;; esac
cap=${1:-bi5}
src=$out/src_$cap
rm -rf "$src" && mkdir -p "$src" || exit 2
git archive HEAD | tar -x -C "$src" || exit 1
if [ "$cap" = blend ]; then
  (cd "$src" && patch -p1 -s < tests/experiments/cap_blend.patch) || exit 1
fi
make --no-print-directory -C "$src" B="$out/lib_$cap" "$out/lib_$cap/libccnurbs.a" >/dev/null || exit 1
cc -O2 -I"$src/csrc/include" -I"$src/csrc" -I"$src/tests/c" tests/experiments/cap_mesh_table.c \
  -o "$out/cap_mesh_table_$cap" "$out/lib_$cap/libccnurbs.a" -llapacke -llapack -lm -lpthread || exit 1
"$out/cap_mesh_table_$cap" "$@"
