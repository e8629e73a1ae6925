#!/bin/sh
# Sanitized suite: every build/asan/tests/test_* (clang-14, -fsanitize=address,undefined,
# -fno-sanitize-recover=all, built by tests/asan/asan.mk), then the CLI contract script and
# the OpenSubdiv oracle (levels 1-3) with CCNURBS=build/asan/ccnurbs. A suite fails on a
# non-zero exit or on any sanitizer report (kept in build/asan/logs/reports/, printed here).
# One line per suite, then "N passed, N failed".
# Environment (optional): ASAN_ORACLE=0 skips the oracle, ASAN_ORACLE_MAX_LEVEL (default 3;
# 4 = the full oracle, about 3x longer), ASAN_TIMEOUT (seconds per suite, default 900: 3x the
# slowest suite measured under load -- test_cap once took 462 s -- since `make test`
# runs two suites at a time).
cd "$(dirname "$0")/../.." || exit 2
LOGS=build/asan/logs
rm -rf "$LOGS"
mkdir -p "$LOGS/reports" || exit 2
ASAN_OPTIONS="detect_leaks=1:abort_on_error=0:log_path=$PWD/$LOGS/asan"
UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1:log_path=$PWD/$LOGS/ubsan"
export ASAN_OPTIONS UBSAN_OPTIONS
# the heavy measurement tests (test_cap_fair, test_normals_fd, test_suzanne) run a small sample
# under the sanitizers: the paths matter here, the figures are checked by the plain build
CCN_TEST_SMALL=1
export CCN_TEST_SMALL
TO=
if command -v timeout >/dev/null 2>&1; then TO="timeout ${ASAN_TIMEOUT:-900}"; fi
pass=0; fail=0

# suite NAME CMD... : runs CMD with output to a log; prints the log tail on failure.
suite() {
  name=$1; shift
  out="$LOGS/$(echo "$name" | tr '/ ' '__').out"
  start=$(date +%s)
  $TO "$@" >"$out" 2>&1
  rc=$?
  reports=$(ls "$LOGS"/asan.* "$LOGS"/ubsan.* 2>/dev/null)
  if [ $rc -eq 0 ] && [ -z "$reports" ]; then
    pass=$((pass + 1))
    echo "ok   $name ($(( $(date +%s) - start ))s): $(tail -n 1 "$out")"
  else
    fail=$((fail + 1))
    echo "FAIL $name (exit $rc, $(( $(date +%s) - start ))s)"
    grep -E 'FAIL|not ok|ERROR|runtime error' "$out" | head -n 20 | sed 's/^/     /'
    for r in $reports; do
      echo "     sanitizer report (kept in $LOGS/reports/):"
      head -n 24 "$r" | sed 's/^/     /'
      mv "$r" "$LOGS/reports/$(echo "$name" | tr '/ ' '__').$(basename "$r")"
    done
  fi
}

found=0
for t in build/asan/tests/test_*; do
  [ -x "$t" ] || continue
  found=1
  suite "$(basename "$t")" "$t"
done
if [ $found = 0 ]; then
  fail=$((fail + 1)); echo "FAIL no sanitized test binaries in build/asan/tests (make asan)"
fi
if [ -x build/asan/ccnurbs ]; then
  suite "cli/run_cli.sh" env CCNURBS=build/asan/ccnurbs sh tests/cli/run_cli.sh
  if [ "${ASAN_ORACLE:-1}" != 0 ]; then
    suite "oracle/run_oracle.sh" env CCNURBS=build/asan/ccnurbs \
      ORACLE_MAX_LEVEL="${ASAN_ORACLE_MAX_LEVEL:-3}" sh tests/oracle/run_oracle.sh
  fi
else
  fail=$((fail + 1)); echo "FAIL build/asan/ccnurbs is missing (make asan)"
fi

echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
