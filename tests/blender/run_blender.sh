#!/bin/sh
# Headless Blender tests of the add-on (picked up by tests/run_tests.sh), on every Blender:
#   3.4  Debian's `blender`:  blender --background --factory-startup --python-exit-code 1 --python
#   4.2, 4.5 (LTS), 5.2 (LTS), 5.3  PyPI's `bpy` module in the venvs of tests/blender/deps_bpy.sh:
#        python test_addon.py
# Each run installs build/ccnurbs.zip (the linux-x64 package of tests/package/package.mk; 3.x:
# legacy add-on; 4.2+: extension API) into throw-away user dirs. 3.4, 4.5 and 5.3 run every case;
# the lines in CCN_BPY_SUBSET_LINES (4.2, 5.2: `make test` stays short) run CCN_SUBSET_CASES, the
# add-on suite without its four slowest cases. One line per test, then
# "== Blender X.Y.Z (how): N passed, N failed" per version; a version that is not installed
# counts as a failure. Last lines: the versions tested, "N passed, N failed" in total.
cd "$(dirname "$0")/../.." || exit 2
ZIP=${CCN_ZIP:-build/ccnurbs.zip}
CLI=${CCN_CLI:-build/ccnurbs}
CACHE=${CCN_CACHE:-${XDG_CACHE_HOME:-$HOME/.cache}/ccnurbs}
LINES=${CCN_BPY_LINES:-"4.2 4.5 5.2 5.3"}
SUBSET_LINES=${CCN_BPY_SUBSET_LINES-"4.2 5.2"}
SUBSET_CASES=${CCN_SUBSET_CASES:-case_package,case_knots,case_modifier,case_creases,case_stack,\
case_animation,case_files,case_scenes,case_objio,case_values,case_zenable}
# a guard against a hang, not a budget: one Blender's suite takes 50-110 s on a quiet 2-core
# machine and has taken 250 s beside the other lane's suites and a second build
TIMEOUT=${CCN_BLENDER_TIMEOUT:-900}
for f in "$ZIP" "$CLI"; do
  [ -f "$f" ] || { echo "run_blender: $f missing (make package build)"; echo "0 passed, 1 failed"; exit 1; }
done
tmp=$(mktemp -d "${TMPDIR:-/tmp}/ccnurbs_blender.XXXXXX") || exit 2
trap 'rm -rf "$tmp"' EXIT INT TERM
total_p=0; total_f=0; versions=""

# run LABEL CMD...: runs test_addon.py with a fresh user dir, prints its lines, adds its counts.
run() {
  label=$1; shift
  d="$tmp/$label"; mkdir -p "$d/work"
  start=$(date +%s)
  BLENDER_USER_SCRIPTS="$d/scripts" BLENDER_USER_CONFIG="$d/config" \
  BLENDER_USER_EXTENSIONS="$d/extensions" BLENDER_USER_DATAFILES="$d/datafiles" \
    timeout "$TIMEOUT" "$@" "$ZIP" "$CLI" "$d/work" >"$d/log" 2>&1
  rc=$?
  sed -n '/^== CCNURBS blender tests ==$/,$p' "$d/log" | sed '1d' \
    | grep -Ev '^[0-9]+ passed, [0-9]+ failed$|^Blender quit$|^$|^Freeing memory after|^Error: Not freed memory|^(bench|measure) ' \
    | sed 's/^/  /'
  grep -E '^(bench|measure) ' "$d/log" | sed 's/^/  /'
  summary=$(grep -E '^[0-9]+ passed, [0-9]+ failed$' "$d/log" | tail -n 1)
  ver=$(grep -E '^== CCNURBS blender tests ==' -B1000 "$d/log" | grep -oE '^CCNURBS test Blender [0-9.]+' | tail -n 1 | awk '{print $4}')
  # A Python traceback printed by Blender or by a handler (which must never raise) is a failure.
  tb=$(sed '/^== CCNURBS blender tests ==$/,$d' "$d/log" | grep -c '^Traceback')
  if [ "$tb" -ne 0 ]; then
    echo "  run_blender: $tb Python traceback(s) in Blender's output:"
    sed '/^== CCNURBS blender tests ==$/,$d' "$d/log" | grep -A 16 "^Traceback" | sed 's/^/    /'
  fi
  # Blender's own leak report at exit (the program prints it; bpy modules end with os._exit, and
  # case_files checks a fresh module's exit instead)
  leak=$(sed -n '/^== CCNURBS blender tests ==$/,$p' "$d/log" | grep -c '^Error: Not freed memory')
  if [ "$leak" -ne 0 ]; then
    echo "  run_blender: Blender reports memory not freed at exit:"
    sed -n '/^== CCNURBS blender tests ==$/,$p' "$d/log" | grep -A 8 '^Error: Not freed memory' | sed 's/^/    /'
  fi
  if [ -z "$summary" ]; then
    echo "  run_blender: exited with $rc before the tests finished; last output:"
    tail -n 40 "$d/log" | sed 's/^/    /'
    summary="0 passed, 1 failed"
  fi
  p=${summary%% passed*}; f=${summary#*passed, }; f=${f%% failed*}
  if [ "$f" -eq 0 ] && { [ "$tb" -ne 0 ] || [ "$leak" -ne 0 ] || [ $rc -ne 0 ]; }; then f=1; fi
  total_p=$((total_p + p)); total_f=$((total_f + f))
  versions="$versions ${ver:-?}${subset:+(subset)}"
  echo "== Blender ${ver:-$label} ($label${subset:+, subset of $(echo "$CCN_CASES" | tr , '\n' |
       wc -l) cases}): $p passed, $f failed ($(( $(date +%s) - start ))s)"
}

missing() {
  echo "== Blender $1: not available: $2"
  total_f=$((total_f + 1)); versions="$versions $1(missing)"
}

subset=""
if [ "${CCN_DEBIAN:-1}" = 0 ]; then
  : # (long_storm.sh: the bpy lines only)
elif command -v blender >/dev/null 2>&1; then
  run "debian-blender" blender --background --factory-startup --python-exit-code 1 \
    --python tests/blender/test_addon.py --
else
  missing "3.4 (Debian blender)" "blender is not installed (make deps installs it)"
fi
for line in $LINES; do
  env="$CACHE/venv-bpy-$line"
  if [ -f "$env/.ok" ] && [ -x "$env/bin/python" ]; then
    subset=""
    case " $SUBSET_LINES " in *" $line "*) [ -z "${CCN_CASES:-}" ] && subset=1 ;; esac
    [ -n "$subset" ] && export CCN_CASES="$SUBSET_CASES"
    run "bpy-$line" "$env/bin/python" tests/blender/test_addon.py
    [ -n "$subset" ] && unset CCN_CASES
  else
    why=$(cat "$env.failed" 2>/dev/null | tr '\n' ' ')
    missing "$line (bpy wheel)" "${why:-no venv at $env (make deps creates it)}"
  fi
done
echo "run_blender: Blender versions tested:$versions"
echo "$total_p passed, $total_f failed"
[ "$total_f" -eq 0 ]
