#!/bin/sh
# Runs every test suite: C test binaries (build/tests/test_*) and tests/*/run_*.sh scripts.
# Each suite prints its own lines; the last line here is the total "N passed, N failed".
cd "$(dirname "$0")/.." || exit 2
pass=0; fail=0; failed=""
run() {
  name=$1; shift
  start=$(date +%s)
  if "$@"; then pass=$((pass+1)); s=ok; else fail=$((fail+1)); failed="$failed $name"; s=FAILED; fi
  echo "== $name: $s ($(( $(date +%s) - start ))s)"
}
for t in build/tests/test_*; do
  [ -x "$t" ] || continue
  run "$(basename "$t")" "$t"
done
for s in tests/*/run_*.sh; do
  [ -f "$s" ] || continue
  run "$s" sh "$s"
done
[ -n "$failed" ] && echo "failed suites:$failed"
echo "suites: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
