#!/bin/sh
# Builds tests/experiments/cap_table.c twice -- against the library as it ships, and against a
# research build with the non-uniform cap's kappa range opened (-DCCN_CAP_KAPPA_RANGE=1e9) --
# and prints both tables (README "The guided bi-5 cap"). Arguments go to cap_table: cases per
# (valence, ratio), output level, seed.
cd "$(dirname "$0")/../.." || exit 2
B=${B:-build}
out=$B/cap_table
mkdir -p "$out" || exit 2
make --no-print-directory B="$out/ship" "$out/ship/libccnurbs.a" >/dev/null || exit 1
make --no-print-directory B="$out/open" CFLAGS="-O2 -g -DCCN_CAP_KAPPA_RANGE=1e9" "$out/open/libccnurbs.a" >/dev/null || exit 1
for v in ship open; do
  cc -O2 -Icsrc/include -Icsrc -Itests/c tests/experiments/cap_table.c -o "$out/cap_table_$v" \
    "$out/$v/libccnurbs.a" -llapacke -llapack -lm -lpthread || exit 1
done
echo "== as shipped"
"$out/cap_table_ship" "$@"
echo "== the non-uniform construction wherever it builds (kappa range opened)"
"$out/cap_table_open" "$@"
