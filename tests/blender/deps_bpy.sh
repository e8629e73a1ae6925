#!/bin/sh
# `make deps`, Blender part: one virtual environment per Blender release line with PyPI's official
# `bpy` wheel (Blender as a Python module), used by run_blender.sh beside Debian's `blender` (3.4).
# Idempotent and offline once done:
#   $CCN_CACHE (default ${XDG_CACHE_HOME:-~/.cache}/ccnurbs, outside build/ so `make clean` keeps it)
#     wheels/            every wheel downloaded once (`pip download`); installs use --no-index
#     venv-bpy-<line>/   the environment; `.ok` inside it = `import bpy` worked (then skipped)
#     venv-bpy-<line>.failed   why the last attempt failed (run_blender.sh reports it)
# Lines: 4.2 and 4.5 (LTS; wheels for CPython 3.11), 5.2 (LTS) and 5.3 (wheels for CPython 3.13,
# found as python3.13 or in pyenv; CCN_PYTHON313 names one). A line whose Python is missing is
# recorded as failed (run_blender.sh then reports that version as a failure).
CACHE=${CCN_CACHE:-${XDG_CACHE_HOME:-$HOME/.cache}/ccnurbs}
LINES=${CCN_BPY_LINES:-"4.2 4.5 5.2 5.3"}
mkdir -p "$CACHE/wheels" || exit 1
# find_python X.Y CANDIDATE...: the first candidate that is CPython X.Y with venv, or nothing
find_python() {
  want=$1; shift
  for c in "$@"; do
    [ -n "$c" ] || continue
    if command -v "$c" >/dev/null 2>&1 && "$c" -c \
       "import sys, venv; sys.exit(sys.version_info[:2] != tuple(map(int, '$want'.split('.'))))" \
       2>/dev/null; then
      command -v "$c"; return
    fi
  done
}
PYENV=${PYENV_ROOT:-$HOME/.pyenv}
py311=$(find_python 3.11 "${CCN_PYTHON311:-}" python3.11 /usr/bin/python3.11 python3)
# shellcheck disable=SC2046
py313=$(find_python 3.13 "${CCN_PYTHON313:-}" python3.13 /usr/bin/python3.13 \
        /usr/local/bin/python3.13 $(ls -d "$PYENV"/versions/3.13*/bin/python3.13 2>/dev/null))
status=0
for line in $LINES; do
  env="$CACHE/venv-bpy-$line"
  [ -f "$env/.ok" ] && [ -x "$env/bin/python" ] && continue
  rm -f "$env.failed"
  # bpy 4.x-5.1: cp311 wheels; 5.2 and later: cp313
  case $line in 4.*|5|5.0|5.1) want=3.11; py=$py311 ;; *) want=3.13; py=$py313 ;; esac
  if [ -z "$py" ]; then
    echo "no CPython $want with venv found (python$want, pyenv $PYENV/versions/$want*)" \
      >"$env.failed"; status=1; continue
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
