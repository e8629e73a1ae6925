#!/bin/sh
# Headless Blender tests of the add-on (picked up by tests/run_tests.sh).
# Installs build/ccnurbs.zip into a throw-away user scripts dir and runs test_addon.py with
# `blender --background --factory-startup --python-exit-code 1`. Last line: "N passed, N failed".
cd "$(dirname "$0")/../.." || exit 2
ZIP=${CCN_ZIP:-build/ccnurbs.zip}
CLI=${CCN_CLI:-build/ccnurbs}
if ! command -v blender >/dev/null 2>&1; then
  echo "run_blender: blender is not installed (make deps installs Debian's blender)"
  echo "0 passed, 1 failed"; exit 1
fi
for f in "$ZIP" "$CLI"; do
  [ -f "$f" ] || { echo "run_blender: $f missing (make package build)"; echo "0 passed, 1 failed"; exit 1; }
done
tmp=$(mktemp -d "${TMPDIR:-/tmp}/ccnurbs_blender.XXXXXX") || exit 2
trap 'rm -rf "$tmp"' EXIT INT TERM
# Keep the user's Blender configuration untouched: install into a temporary user dir.
BLENDER_USER_SCRIPTS="$tmp/scripts" BLENDER_USER_CONFIG="$tmp/config" \
  timeout 600 blender --background --factory-startup --python-exit-code 1 \
  --python tests/blender/test_addon.py -- "$ZIP" "$CLI" "$tmp" >"$tmp/log" 2>&1
rc=$?
# One line per test (failures with their traceback); Blender's own output left out.
sed -n '/^== CCNURBS blender tests ==$/,$p' "$tmp/log" | sed '1d' \
  | grep -Ev '^[0-9]+ passed, [0-9]+ failed$|^Blender quit$|^$' | sed 's/^/  /'
summary=$(grep -E '^[0-9]+ passed, [0-9]+ failed$' "$tmp/log" | tail -n 1)
# A Python traceback printed by Blender or by a handler (which must never raise) is a failure.
tb=$(sed '/^== CCNURBS blender tests ==$/,$d' "$tmp/log" | grep -c '^Traceback')
if [ "$tb" -ne 0 ]; then
  echo "run_blender: $tb Python traceback(s) in Blender's output:"
  sed '/^== CCNURBS blender tests ==$/,$d' "$tmp/log" | grep -A 12 '^Traceback' | sed 's/^/  /'
  rc=1
  summary="${summary:-0 passed, 1 failed}"
  case "$summary" in *" 0 failed") p=${summary%% *}; summary="$p passed, 1 failed" ;; esac
fi
if [ -z "$summary" ] || [ $rc -ne 0 ]; then
  if [ -z "$summary" ]; then
    echo "run_blender: blender exited with $rc before the tests finished; last output:"
    tail -n 40 "$tmp/log" | sed 's/^/  /'
    summary="0 passed, 1 failed"
  fi
  echo "$summary"
  exit 1
fi
echo "$summary"
case "$summary" in *" 0 failed") exit 0 ;; *) exit 1 ;; esac
