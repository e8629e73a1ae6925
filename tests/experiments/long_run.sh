#!/bin/sh
# One-time long runs of `ccnurbs experiment` (NOT part of `make test`; see RESULTS.md).
# Runs an experiment in chunks of CHUNK cases (--offset i*CHUNK, so every case is the one the
# single big run would draw) until TOTAL cases are done or BUDGET seconds have passed, keeps
# each chunk's output in OUT/, and prints the summed figures.
#   usage: tests/experiments/long_run.sh OUT TOTAL CHUNK BUDGET maxima|charmap [experiment options]
#   e.g.   nohup tests/experiments/long_run.sh /tmp/max1m 1000000 50000 2400 maxima \
#              --seed 1 --persist 7 > /tmp/max1m.log 2>&1 &
# A chunk file already in OUT that ends with its `time:` line is kept, not re-run, so a stopped
# run resumes where it stopped (cases are drawn per index, so the figures do not change).
# Environment: CCNURBS (default build/ccnurbs).
cd "$(dirname "$0")/../.." || exit 2
[ $# -ge 5 ] || { sed -n '2,9p' "$0"; exit 2; }
out=$1; total=$2; chunk=$3; budget=$4; shift 4
ccn=${CCNURBS:-build/ccnurbs}
mkdir -p "$out" || exit 2
start=$(date +%s); done_cases=0; k=0
echo "command: $ccn experiment $* --cases $chunk --offset <k*$chunk>  (chunks until $total cases or ${budget}s)"
while [ "$done_cases" -lt "$total" ] && [ $(( $(date +%s) - start )) -lt "$budget" ]; do
  n=$chunk; [ $((done_cases + n)) -gt "$total" ] && n=$((total - done_cases))
  f=$(printf '%s/chunk%04d.txt' "$out" "$k")
  if grep -q '^time:' "$f" 2>/dev/null; then
    done_cases=$((done_cases + n)); k=$((k + 1)); echo "chunk $k: kept"; continue
  fi
  "$ccn" experiment "$@" --cases "$n" --offset "$done_cases" --list 1000000 > "$f" || { echo "chunk $k failed"; exit 1; }
  done_cases=$((done_cases + n)); k=$((k + 1))
  echo "chunk $k: $done_cases cases, $(( $(date +%s) - start )) s"
done
echo "cases: $done_cases in $k chunks, wall time $(( $(date +%s) - start )) s"
awk -F': ' '
  /^time:/ { t += $2 + 0 }
  /^(failures|single maximum|matrix ok|spectrum ok|regular|injective|all pass|errors|non-finite):/ { s[$1] += $2 + 0 }
  /^persistent/ { split($2, p, ";"); s["persistent"] += p[1] + 0 }
  /^fallbacks:/ { s["fallback cases"] += $2 + 0 }
  END { for (k in s) printf("%s: %d\n", k, s[k]); printf("sum of chunk times: %.1f s\n", t) }' "$out"/chunk*.txt | sort
echo "listed failures:"
grep -h '^fail case' "$out"/chunk*.txt
