#!/bin/sh
# `make deps`, Blender part: one virtual environment per Blender release line with PyPI's official
# `bpy` wheel (Blender as a Python module, CPython 3.11), used by run_blender.sh beside Debian's
# `blender` (3.4). Idempotent and offline once done:
#   $CCN_CACHE (default ${XDG_CACHE_HOME:-~/.cache}/ccnurbs, outside build/ so `make clean` keeps it)
#     wheels/            every wheel downloaded once (`pip download`); installs use --no-index
#     venv-bpy-<line>/   the environment; `.ok` inside it = `import bpy` worked (then skipped)
#     venv-bpy-<line>.failed   why the last attempt failed (run_blender.sh reports it)
# Lines: 4.5 (LTS) and 5 (the newest 5.x whose wheel installs on CPython 3.11).
CACHE=${CCN_CACHE:-${XDG_CACHE_HOME:-$HOME/.cache}/ccnurbs}
LINES=${CCN_BPY_LINES:-"4.5 5"}
mkdir -p "$CACHE/wheels" || exit 1
py=""
for c in "${CCN_PYTHON311:-}" python3.11 /usr/bin/python3.11 python3; do
  [ -n "$c" ] || continue
  if command -v "$c" >/dev/null 2>&1 && \
     "$c" -c 'import sys, venv; sys.exit(sys.version_info[:2] != (3, 11))' 2>/dev/null; then
    py=$(command -v "$c"); break
  fi
done
status=0
for line in $LINES; do
  env="$CACHE/venv-bpy-$line"
  [ -f "$env/.ok" ] && [ -x "$env/bin/python" ] && continue
  rm -f "$env.failed"
  if [ -z "$py" ]; then
    echo "no CPython 3.11 with venv found (python3.11 / python3)" >"$env.failed"; status=1; continue
  fi
  spec="bpy==$line.*"
  echo "deps: bpy $line into $env"
  log="$CACHE/venv-bpy-$line.log"
  {
    rm -rf "$env" &&
    "$py" -m venv "$env" &&
    # The wheel (~375 MB) and its dependencies are fetched only if no cached wheel satisfies spec.
    { "$env/bin/pip" install -q --no-index --find-links "$CACHE/wheels" "$spec" ||
      { "$env/bin/pip" download -q --only-binary=:all: -d "$CACHE/wheels" "$spec" &&
        "$env/bin/pip" install -q --no-index --find-links "$CACHE/wheels" "$spec"; }; } &&
    "$env/bin/python" -c 'import bpy; print(bpy.app.version_string)'
  } >"$log" 2>&1
  if [ $? -eq 0 ]; then
    touch "$env/.ok"
    echo "deps: bpy $(tail -n 1 "$log") ready"
  else
    tail -n 5 "$log" >"$env.failed"
    echo "deps: bpy $line could not be installed (see $log)"
    status=1
  fi
done
# Not fatal for `make deps`: run_blender.sh reports a missing version as a failed suite line.
exit 0
