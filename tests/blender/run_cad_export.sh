#!/bin/sh
# Headless Blender test of the CAD export operator (addon/cad_export.py, test_cad_export.py).
# Last line: "N passed, N failed".
cd "$(dirname "$0")/../.." || exit 2
for f in build/ccnurbs.zip build/ccnurbs build/occt_read; do
  [ -f "$f" ] || { echo "run_cad_export: $f missing"; echo "0 passed, 1 failed"; exit 1; }
done
command -v blender > /dev/null 2>&1 || { echo "run_cad_export: no blender"; echo "0 passed, 1 failed"; exit 1; }
tmp=$(mktemp -d "${TMPDIR:-/tmp}/ccnurbs_cad.XXXXXX") || exit 2
trap 'rm -rf "$tmp"' EXIT INT TERM
mkdir -p "$tmp/out"
BLENDER_USER_SCRIPTS="$tmp/scripts" BLENDER_USER_CONFIG="$tmp/config" \
  timeout 300 blender --background --factory-startup --python-exit-code 1 \
  --python tests/blender/test_cad_export.py -- build/ccnurbs.zip build/ccnurbs build/occt_read "$tmp/out" > "$tmp/log" 2>&1
rc=$?
sed -n '/^== CCNURBS cad export tests ==$/,$p' "$tmp/log" | sed '1d' | grep -E ' \.\.\. |^(FAIL|ERROR|Traceback|  File|    |[A-Za-z]+Error)' | sed 's/^/  /'
summary=$(grep -E '^[0-9]+ passed, [0-9]+ failed$' "$tmp/log" | tail -n 1)
if [ -z "$summary" ]; then tail -n 30 "$tmp/log" | sed 's/^/  /'; summary="0 passed, 1 failed"; rc=1; fi
echo "$summary"
[ $rc -eq 0 ]
