#!/bin/sh
# The long runs of `ccnurbs experiment` with the library's per-vertex eigen polyhedron
# choice, one after the other, in the background-friendly form they were run (figures: README
# "Experiments", tests/experiments/RESULTS.md). Chunked and resumable (long_run.sh): rerunning
# the script skips finished chunks. Run it as
#   nohup nice -n 19 tests/experiments/long_runs.sh OUTDIR > OUTDIR.log 2>&1 &
# with CCNURBS pointing at a copy of the binary that is not rebuilt meanwhile.
cd "$(dirname "$0")/../.." || exit 2
L=${1:?usage: long_runs.sh OUTDIR}
mkdir -p "$L" || exit 2
R=tests/experiments/long_run.sh
sh $R "$L/cm_u6" 100000 10000 200000 charmap --seed 1 --lo 1e-6 --threads 2 > "$L/cm_u6.log" 2>&1
sh $R "$L/mx_l3" 20000 10000 200000 maxima --seed 1 --dist loguniform --lo 1e-3 --threads 2 > "$L/mx_l3.log" 2>&1
sh $R "$L/cm_l3" 10000 5000 200000 charmap --seed 1 --dist loguniform --lo 1e-3 --threads 2 > "$L/cm_l3.log" 2>&1
sh $R "$L/mx_l6" 20000 10000 200000 maxima --seed 1 --dist loguniform --lo 1e-6 --threads 2 > "$L/mx_l6.log" 2>&1
sh $R "$L/cm_l6" 10000 5000 200000 charmap --seed 1 --dist loguniform --lo 1e-6 --threads 2 > "$L/cm_l6.log" 2>&1
sh $R "$L/mx_u6" 1000000 20000 200000 maxima --seed 1 --lo 1e-6 --persist 7 --threads 2 > "$L/mx_u6.log" 2>&1
echo "all done"
