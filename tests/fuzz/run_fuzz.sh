#!/bin/sh
# libFuzzer run: for each harness build/fuzz/fuzz_NAME (NAME = obj, mesh, plan; built by
# tests/fuzz/fuzz.mk) first replays every saved input in tests/fuzz/regressions/NAME/ and
# tests/fuzz/regressions/NAME-*, then fuzzes FUZZ_SECONDS seconds (default 60) from the seeds
# in tests/fuzz/corpus_NAME/ (new inputs go to build/fuzz/corpus_NAME/, kept between runs).
# Harnesses run in parallel (FUZZ_JOBS at a time, default 3: all at once, so `make test`
# spends FUZZ_SECONDS). A crash, sanitizer report, failed check, leak, timeout (> 30 s for
# one input: the sanitized build on two busy cores; the eigen polyhedron verification of
# extreme spoke ratios costs seconds there) or out-of-memory (> 2 GB) is a failure; the input is saved as
# build/fuzz/crash_NAME-* (copy it to tests/fuzz/regressions/NAME/ and make it a unit test).
# Earlier library bugs (tests/c/test_fixed_bugs.c) are fixed; the harnesses check strictly.
# (tests/fuzz/fuzz_common.h). fuzz_plan is skipped, not failed, while the library lacks
# ccn_plan_evaluate.
# One line per replay / run, then "N passed, N failed".
cd "$(dirname "$0")/../.." || exit 2
SECS=${FUZZ_SECONDS:-60}
JOBS=${FUZZ_JOBS:-3}
OUT=build/fuzz
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=0"
TO=
if command -v timeout >/dev/null 2>&1; then TO="timeout $((SECS + 300))"; fi
mkdir -p "$OUT" || exit 2
pass=0; fail=0

max_len() { case $1 in obj) echo 8192 ;; *) echo 1024 ;; esac; }

names=""
for n in obj mesh plan; do
  bin=$OUT/fuzz_$n
  if [ ! -x "$bin" ]; then
    if [ $n = plan ] &&
       ! nm "$OUT/libccnurbs_fuzz.a" 2>/dev/null | grep -q ' T ccn_plan_evaluate$'; then
      echo "skip fuzz_plan (ccn_plan_evaluate is not in the library yet)"
      continue
    fi
    fail=$((fail + 1)); echo "FAIL $bin is missing (make fuzz-build)"; continue
  fi
  names="$names $n"
  # regressions: every saved input must now run clean
  regs=$( (ls "tests/fuzz/regressions/$n/" 2>/dev/null | sed "s|^|tests/fuzz/regressions/$n/|"
          ls -d tests/fuzz/regressions/"$n"-* 2>/dev/null) | grep -v '^$')
  if [ -n "$regs" ]; then
    # shellcheck disable=SC2086
    if $TO "$bin" -timeout=30 -rss_limit_mb=2048 $regs >"$OUT/replay_$n.log" 2>&1; then
      pass=$((pass + 1)); echo "ok   fuzz_$n regressions ($(echo "$regs" | wc -l) inputs)"
    else
      fail=$((fail + 1)); echo "FAIL fuzz_$n regressions (log $OUT/replay_$n.log):"
      grep -E 'FUZZ CHECK|ERROR|runtime error|Running:' "$OUT/replay_$n.log" | tail -n 6 |
        sed 's/^/     /'
    fi
  fi
done

# fuzz_one NAME: runs in the background, writes $OUT/NAME.log and $OUT/NAME.rc
fuzz_one() {
  n=$1
  mkdir -p "$OUT/corpus_$n"
  rm -f "$OUT/$n.rc"
  # a fixed seed (FUZZ_SEED, default 1; 0 = random) keeps make test reproducible
  $TO "$OUT/fuzz_$n" -seed="${FUZZ_SEED:-1}" -max_total_time="$SECS" -timeout=30 -rss_limit_mb=2048 \
    -max_len="$(max_len "$n")" -print_final_stats=1 -artifact_prefix="$OUT/crash_$n-" \
    "$OUT/corpus_$n" "tests/fuzz/corpus_$n" >"$OUT/$n.log" 2>&1
  echo $? >"$OUT/$n.rc"
}

running=0
for n in $names; do
  fuzz_one "$n" &
  running=$((running + 1))
  if [ "$running" -ge "$JOBS" ]; then wait; running=0; fi
done
wait

for n in $names; do
  rc=$(cat "$OUT/$n.rc" 2>/dev/null || echo 99)
  runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$OUT/$n.log" | grep -o '[0-9]*$')
  cov=$(grep -o 'cov: [0-9]*' "$OUT/$n.log" | tail -n 1)
  if [ "$rc" = 0 ]; then
    pass=$((pass + 1)); echo "ok   fuzz_$n ${SECS}s: ${runs:-?} inputs, $cov"
  else
    fail=$((fail + 1))
    art=$(grep -o "Test unit written to [^ ]*" "$OUT/$n.log" | sed 's/Test unit written to //')
    echo "FAIL fuzz_$n (exit $rc) input saved as ${art:-?}; log $OUT/$n.log:"
    grep -E 'FUZZ CHECK|ERROR|runtime error|SUMMARY|#[0-9]+ 0x.* in (ccn|fz_|LLVMFuzzerTestOneInput)' \
      "$OUT/$n.log" | head -n 12 | cut -c1-200 | sed 's/^/     /'
  fi
done

echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
