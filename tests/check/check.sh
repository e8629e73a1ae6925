#!/bin/sh
# `make check` (tests/check/check.mk): the everyday tier. Runs the C tests named as arguments
# (build/tests/NAME), two at a time, then the CLI contract (tests/cli/run_cli.sh), the limit
# against OpenSubdiv (tests/oracle/run_limit.sh) and the add-on's modifier cases
# (CCN_CASES=case_modifier) on the newest Blender line that `make deps` installed. One line per
# suite, then "check: N passed, N failed (S s)". `make test` is the full suite.
cd "$(dirname "$0")/../.." || exit 2
CACHE=${CCN_CACHE:-${XDG_CACHE_HOME:-$HOME/.cache}/ccnurbs}
LOG=build/check-logs
rm -rf "$LOG" && mkdir -p "$LOG" || exit 2
t0=$(date +%s)
pass=0; fail=0
result() { # name rc secs
  if [ "$2" = 0 ]; then pass=$((pass + 1)); s=ok; else fail=$((fail + 1)); s=FAILED; fi
  echo "== $1: $s ($3 s)$( [ "$2" = 0 ] || echo "; log $LOG/$1.log")"
  [ "$2" = 0 ] || tail -n 15 "$LOG/$1.log" | sed 's/^/   /'
}
run() { # name cmd...
  name=$1; shift
  s0=$(date +%s)
  "$@" >"$LOG/$name.log" 2>&1
  echo "$? $(( $(date +%s) - s0 ))" >"$LOG/$name.rc"
}
set -- "$@"
while [ $# -gt 0 ]; do # two C tests at a time
  a=$1; shift
  run "$a" "build/tests/$a" &
  if [ $# -gt 0 ]; then b=$1; shift; run "$b" "build/tests/$b"; else b=""; fi
  wait
  for n in $a $b; do read -r rc secs <"$LOG/$n.rc"; result "$n" "$rc" "$secs"; done
done
run run_cli sh tests/cli/run_cli.sh & run run_limit sh tests/oracle/run_limit.sh; wait
for n in run_cli run_limit; do read -r rc secs <"$LOG/$n.rc"; result "$n" "$rc" "$secs"; done
py=""
for line in 5.3 5.2 4.5; do
  if [ -f "$CACHE/venv-bpy-$line/.ok" ]; then py="$CACHE/venv-bpy-$line/bin/python"; break; fi
done
if [ -n "$py" ]; then
  mkdir -p "$LOG/blender/work"
  BLENDER_USER_SCRIPTS="$LOG/blender/scripts" BLENDER_USER_CONFIG="$LOG/blender/config" \
  BLENDER_USER_EXTENSIONS="$LOG/blender/extensions" BLENDER_USER_DATAFILES="$LOG/blender/datafiles" \
  CCN_CASES=case_modifier run blender "$py" tests/blender/test_addon.py build/ccnurbs.zip build/ccnurbs \
    "$LOG/blender/work"
  read -r rc secs <"$LOG/blender.rc"
  grep -q "^[0-9]* passed, 0 failed" "$LOG/blender.log" || rc=1
  result "blender ($(grep -o 'Blender [0-9.]*' "$LOG/blender.log" | head -n 1)) case_modifier" "$rc" "$secs"
else
  echo "== blender: no bpy environment (make deps makes one)"; fail=$((fail + 1))
fi
echo "check: $pass passed, $fail failed ($(( $(date +%s) - t0 )) s)"
[ "$fail" -eq 0 ]
