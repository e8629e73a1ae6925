#!/bin/sh
# Runs every test suite: C test binaries (build/tests/test_*) and tests/*/run_*.sh scripts,
# CCN_TEST_JOBS suites at a time (default 2: the 2-core reference machine; 1 = one after the
# other). Each suite writes build/test-logs/NAME.log, printed when the suite ends, followed by
# "== NAME: ok|FAILED (Ns)"; the last line is the total "suites: N passed, N failed".
# The longest suites start first (HEAVY, measured), so the lanes finish together; every suite keeps its own timeouts.
cd "$(dirname "$0")/.." || exit 2
JOBS=${CCN_TEST_JOBS:-2}
LOG=build/test-logs
HEAVY="tests/asan/run_asan.sh tests/experiments/run_experiments.sh tests/oracle/run_export.sh
       tests/blender/run_blender.sh tests/fuzz/run_fuzz.sh build/tests/test_cap build/tests/test_cap_fair
       build/tests/test_creases build/tests/test_normals_fd build/tests/test_continuity
       tests/oracle/run_osd_shapes.sh tests/package/run_wine.sh"
rm -rf "$LOG" && mkdir -p "$LOG" || exit 2
pass=0; fail=0; failed=""; running=""; pids=""
trap 'for p in $pids; do kill "$p" 2>/dev/null; done; exit 130' INT TERM

# the suites in start order: HEAVY first, then the others in name order
all=""
for t in build/tests/test_*; do [ -x "$t" ] && all="$all $t"; done
for s in tests/*/run_*.sh; do [ -f "$s" ] && all="$all $s"; done
order=""
for h in $HEAVY; do case " $all " in *" $h "*) order="$order $h" ;; esac; done
for x in $all; do case " $order " in *" $x "*) ;; *) order="$order $x" ;; esac; done

name_of() { case $1 in build/tests/*) basename "$1" ;; *) echo "$1" ;; esac; }
id_of() { echo "$1" | tr '/.' '__'; }

start() {
  id=$(id_of "$1")  # (the subshell below runs on its own copy)
  (
    t0=$(date +%s)
    case $1 in *.sh) sh "$1" ;; *) "$1" ;; esac >"$LOG/$id.log" 2>&1
    rc=$?
    echo "$rc $(( $(date +%s) - t0 ))" >"$LOG/$id.rc.tmp" && mv "$LOG/$id.rc.tmp" "$LOG/$id.rc"
  ) &
  pids="$pids $!"
  running="$running $1"
}

# prints and counts every finished suite; returns the number still running in $left
reap() { # (no locals in sh: its variables are r_*)
  r_still=""; left=0
  for r_x in $running; do
    r_id=$(id_of "$r_x")
    if [ -f "$LOG/$r_id.rc" ]; then
      read -r r_rc r_secs <"$LOG/$r_id.rc"
      cat "$LOG/$r_id.log"
      if [ "$r_rc" = 0 ]; then pass=$((pass + 1)); r_s=ok
      else fail=$((fail + 1)); failed="$failed $(name_of "$r_x")"; r_s=FAILED; fi
      echo "== $(name_of "$r_x"): $r_s (${r_secs}s)"
    else
      r_still="$r_still $r_x"; left=$((left + 1))
    fi
  done
  running=$r_still
}

wall0=$(date +%s)
for x in $order; do
  reap
  while [ "$left" -ge "$JOBS" ]; do sleep 0.5; reap; done
  start "$x"
done
reap
while [ "$left" -gt 0 ]; do sleep 0.5; reap; done
wait
# what failed, again at the end (a CI that keeps only the tail of the output shows it): each
# failed suite's failure lines, at most 8 (its full log: build/test-logs)
for x in $failed; do
  case $x in test_*) x=build/tests/$x ;; esac
  echo "-- $(name_of "$x"), what failed:"
  grep -E -i '(^|[^a-z_])([a-z]*error|fail(ed)?|not ok|traceback|exited with|timed? ?out)([^a-z_]|$)' \
      "$LOG/$(id_of "$x").log" | grep -Ev '(^|[^0-9])0 failed|^ok ' | tail -n 8 | cut -c1-300
done
[ -n "$failed" ] && echo "failed suites:$failed"
echo "wall time: $(( $(date +%s) - wall0 ))s with $JOBS suites at a time"
echo "suites: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
