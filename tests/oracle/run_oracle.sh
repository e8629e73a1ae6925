#!/bin/sh
# OpenSubdiv oracle: `ccnurbs refine` must reproduce OpenSubdiv's Catmull-Clark refinement.
#
# For every cage tests/data/*.obj except those with "# knot" lines (non-uniform knots), levels
# 1..4 (level 4 only for cages of <= 100 faces), corners smooth and pinned:
#   build/ccnurbs refine --scheme S --levels K --corners C in.obj out.obj, S = cc eigen nurss
#   and, for S = eigen nurss, the same cage with every edge interval 2.5 (uniform knots)
# is compared with build/osd_refine --levels K --corners C by build/objdiff --tol-rel 1e-9.
# One line per comparison, then "N passed, N failed"; exit 0 only if everything passed.
# Environment (optional): CCNURBS (CLI to test, default build/ccnurbs), ORACLE_MAX_LEVEL
# (default 4), ORACLE_TIMEOUT (seconds per command, default 60).
cd "$(dirname "$0")/../.." || exit 2

CCN=${CCNURBS:-build/ccnurbs}
OSD=build/osd_refine
DIFF=build/objdiff
TOL=1e-9
MAXL=${ORACLE_MAX_LEVEL:-4}
TO=
if command -v timeout >/dev/null 2>&1; then TO="timeout ${ORACLE_TIMEOUT:-60}"; fi

pass=0
fail=0

for tool in "$OSD" "$DIFF"; do
  if [ ! -x "$tool" ]; then
    echo "FAIL oracle tool $tool is missing (make $tool)"
    echo "0 passed, 1 failed"
    exit 1
  fi
done

tmp=$(mktemp -d "${TMPDIR:-/tmp}/ccn_oracle.XXXXXX") || exit 2
trap 'rm -rf "$tmp"' EXIT
trap 'exit 130' INT TERM

report() { # status label message
  if [ "$1" = ok ]; then pass=$((pass + 1)); else fail=$((fail + 1)); fi
  printf '%-4s %-40s %s\n' "$1" "$2" "$3"
}

# Writes a copy of cage $1 to $2 with a "# knot i j 2.5" line for every (undirected) edge.
knots25() {
  awk '
    /^v[ \t]/ { nv++ }
    /^f[ \t]/ {
      n = 0
      for (i = 2; i <= NF; i++) {
        split($i, p, "/"); x = p[1] + 0
        if (x < 0) x = nv + x + 1
        idx[++n] = x
      }
      for (i = 1; i <= n; i++) {
        a = idx[i]; b = idx[i % n + 1]
        if (a > b) { t = a; a = b; b = t }
        k = a " " b
        if (!(k in seen)) { seen[k] = 1; order[++ne] = k }
      }
    }
    { print }
    END { for (i = 1; i <= ne; i++) print "# knot " order[i] " 2.5" }
  ' "$1" >"$2"
}

# compare LABEL INPUT SCHEME   (uses $level, $corners, $ref, $refok)
compare() {
  label="$1 $3"
  if [ "$refok" != 1 ]; then
    report FAIL "$label" "osd_refine failed: $refmsg"
    return
  fi
  out="$tmp/out.obj"
  rm -f "$out"
  if [ ! -x "$CCN" ]; then
    report FAIL "$label" "$CCN is missing"
    return
  fi
  $TO "$CCN" refine --scheme "$3" --levels "$level" --corners "$corners" "$2" "$out" \
    >"$tmp/ccn.log" 2>&1
  rc=$?
  if [ $rc -ne 0 ] || [ ! -s "$out" ]; then
    report FAIL "$label" "ccnurbs exit $rc: $(head -c 300 "$tmp/ccn.log" | tr '\n' ' ')"
    return
  fi
  "$DIFF" --tol-rel "$TOL" "$ref" "$out" >"$tmp/diff.log" 2>&1
  rc=$?
  msg=$(tr '\n' ' ' <"$tmp/diff.log")
  if [ $rc -eq 0 ]; then report ok "$label" "$msg"; else report FAIL "$label" "$msg"; fi
}

for cage in tests/data/*.obj; do
  [ -f "$cage" ] || continue
  name=$(basename "$cage")
  grep -q "^# knot" "$cage" && continue # non-uniform knots: not comparable with OpenSubdiv
  nf=$(grep -c '^f[[:space:]]' "$cage")
  top=$MAXL
  if [ "$nf" -gt 100 ] && [ "$top" -gt 3 ]; then top=3; fi
  k25="$tmp/k25_$name"
  knots25 "$cage" "$k25"
  for corners in smooth pinned; do
    level=1
    while [ "$level" -le "$top" ]; do
      ref="$tmp/ref.obj"
      rm -f "$ref"
      if $TO "$OSD" --levels "$level" --corners "$corners" "$cage" "$ref" >"$tmp/osd.log" 2>&1; then
        refok=1
      else
        refok=0
        refmsg=$(head -c 300 "$tmp/osd.log" | tr '\n' ' ')
      fi
      for s in cc eigen nurss; do
        compare "$name L$level $corners" "$cage" "$s"
      done
      for s in eigen nurss; do
        compare "$name L$level $corners knots2.5" "$k25" "$s"
      done
      level=$((level + 1))
    done
  done
done

echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ] && [ "$pass" -gt 0 ]
