#!/bin/sh
# Byte-identity of the CLI's output against another build (for any change that must not change output). Not part of `make test`.
#
#   tests/layout/compare_outputs.sh REV            build REV (a git revision) in a temporary
#                                                  worktree and compare it with build/ccnurbs
#   tests/layout/compare_outputs.sh BEFORE AFTER   compare two existing ccnurbs binaries
#
# Runs both on every tests/data/*.obj: refine (eigen, nurss, cc; levels 1-2; corners smooth and
# pinned), limit (levels 1-2; cap bi5 and refine; three schemes), patches; matrix for valences
# 3, 5, 7, 12 with and without --knots; the experiments (maxima, charmap, with variants; their
# "time:" lines removed); bad inputs (stdout, stderr and exit code). Prints the differing cases
# and "N identical, N different"; exit 1 if any differ.
cd "$(dirname "$0")/../.." || exit 2
tmp=$(mktemp -d "${TMPDIR:-/tmp}/ccn_compare.XXXXXX") || exit 2
trap 'rm -rf "$tmp"; [ -n "$wt" ] && git worktree remove --force "$wt" >/dev/null 2>&1' EXIT INT TERM
wt=
if [ $# -eq 1 ]; then
  wt="$tmp/wt"
  git worktree add -q --detach "$wt" "$1" || exit 2
  make -C "$wt" --no-print-directory -s build/ccnurbs >"$tmp/build.log" 2>&1 ||
    { echo "compare_outputs: building $1 failed:"; tail -20 "$tmp/build.log"; exit 2; }
  A="$wt/build/ccnurbs"; B=build/ccnurbs
elif [ $# -eq 2 ]; then
  A=$1; B=$2
else
  echo "usage: $0 REV | BEFORE_BIN AFTER_BIN" >&2; exit 2
fi
[ -x "$A" ] && [ -x "$B" ] || { echo "compare_outputs: missing binary ($A, $B)" >&2; exit 2; }
same=0; diff=0

run() { # bin outdir args... : writes stdout, stderr, exit code and output files to outdir
  bin=$1; o=$2; shift 2
  mkdir -p "$o"
  (cd "$o" && "$bin" "$@" >stdout 2>stderr; echo $? >code)
  sed -i '/^time: /d' "$o/stdout"
}
case_() { # label args... (paths: @in = input, out.* = output files in the case dir)
  label=$1; shift
  n=$((same + diff))
  run "$(realpath "$A")" "$tmp/a/$n" "$@"
  run "$(realpath "$B")" "$tmp/b/$n" "$@"
  if diff -r "$tmp/a/$n" "$tmp/b/$n" >/dev/null; then same=$((same + 1))
  else diff=$((diff + 1)); echo "DIFF $label"; diff -r "$tmp/a/$n" "$tmp/b/$n" | head -5; fi
  rm -rf "$tmp/a/$n" "$tmp/b/$n"
}

for f in tests/data/*.obj; do
  in=$(realpath "$f"); b=$(basename "$f" .obj)
  for s in eigen nurss cc; do
    for k in 1 2; do
      for c in smooth pinned; do case_ "refine $b $s $k $c" refine --scheme $s --levels $k --corners $c "$in" out.obj; done
      for cap in bi5 refine; do case_ "limit $b $s $k $cap" limit --scheme $s --levels $k --cap $cap "$in" out.obj; done
    done
    case_ "patches $b $s" patches --scheme $s "$in" out.bv
  done
done
for n in 3 5 7 12; do
  case_ "matrix $n" matrix --valence $n
  k=$(python3 -c "print(','.join(str(0.3+0.17*i) for i in range($n)))")
  for s in eigen nurss cc; do case_ "matrix $n knots $s" matrix --valence $n --knots "$k" --scheme $s; done
done
case_ "maxima" experiment maxima --cases 300 --seed 3
case_ "maxima loguniform" experiment maxima --cases 200 --seed 5 --dist loguniform --list 3
case_ "maxima cage start" experiment maxima --cases 100 --seed 7 --start cage --persist 7
case_ "maxima knots" experiment maxima --knots 1,8,8,1,1,1,8 --levels 6
case_ "charmap" experiment charmap --cases 40 --seed 3
case_ "charmap knots" experiment charmap --knots 1,3,1,3,3
case_ "experiment help" experiment --help
case_ "help" --help
case_ "no args"
case_ "unknown command" frobnicate
case_ "missing file" refine --levels 1 /nonexistent.obj out.obj
case_ "bad levels" refine --levels 99 "$(realpath tests/data/cube.obj)" out.obj
case_ "bad scheme" limit --scheme nope "$(realpath tests/data/cube.obj)" out.obj
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n' >"$tmp/bad.obj"
case_ "two-gon" refine --levels 1 "$tmp/bad.obj" out.obj
echo "$same identical, $diff different"
[ "$diff" -eq 0 ]
