#!/bin/sh
# `make demo` (Blender part): builds the add-on package, installs it into a throw-away Blender
# user dir, and runs tests/blender/demo.py headless: out/demo.png (NURSS vs eigen, highlight
# lines) and out/demo.blend.
set -e
cd "$(dirname "$0")/../.."
if ! command -v blender >/dev/null 2>&1; then
  echo "run_demo: blender is not installed (make deps installs Debian's blender)" >&2
  exit 1
fi
${MAKE:-make} --no-print-directory package >/dev/null
mkdir -p out
tmp=$(mktemp -d "${TMPDIR:-/tmp}/ccnurbs_demo.XXXXXX")
trap 'rm -rf "$tmp"' EXIT INT TERM
if ! BLENDER_USER_SCRIPTS="$tmp/scripts" BLENDER_USER_CONFIG="$tmp/config" \
     blender --background --factory-startup --python-exit-code 1 \
     --python tests/blender/demo.py -- build/ccnurbs.zip out >"$tmp/log" 2>&1; then
  tail -n 40 "$tmp/log" >&2
  echo "run_demo: blender failed" >&2
  exit 1
fi
grep '^demo:' "$tmp/log" | grep -v '^demo: wrote'
rm -f out/stripe_matcap.png
echo "demo: Blender render  $(pwd)/out/demo.png"
echo "demo: Blender file    $(pwd)/out/demo.blend  (opens and renders without the add-on)"
