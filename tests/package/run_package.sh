#!/bin/sh
# The per-platform packages of tests/package/package.mk, checked without running them where they
# cannot run here (picked up by tests/run_tests.sh). In $B (CCN_BUILD, default build):
#  1. each zip ccnurbs-<version>-<platform>.zip: one top folder `ccnurbs/`, its manifest declaring
#     exactly its platform, the add-on's sources, its own library and OpenBLAS, nothing else
#     native (no other platform's library, nothing from Debian); $B/ccnurbs.zip = the linux-x64 one;
#  2. each zip validated by Blender's own validator (`blender --command extension validate`'s
#     code, bl_pkg/cli/blender_ext.py) of every bpy line installed by tests/blender/deps_bpy.sh
#     (a missing line is a failure);
#  3. the native files (tests/package/bincheck.py): linux-x64 glibc symbol versions <= 2.28 and
#     nothing from Debian; windows-x64 imports; macos-* the Mach-O link check against the SDK's
#     libSystem and the bundled OpenBLAS;
#  4. addon/native.py on a package of another platform (unpacked here, on Linux): the add-on says
#     which platform the package is for and which to install (native.load_error()).
# Last: what is tested where, and "N passed, N failed"; exit 1 on any failure.
cd "$(dirname "$0")/../.." || exit 2
B=${CCN_BUILD:-build}
CACHE=${CCN_CACHE:-${XDG_CACHE_HOME:-$HOME/.cache}/ccnurbs}
LINES=${CCN_BPY_LINES:-"4.2 4.5 5.2 5.3"}
PLATFORMS="linux-x64 windows-x64 macos-arm64 macos-x64"
version=$(sed -n 's/^version *= *"\(.*\)"/\1/p' blender_manifest.toml)
pass=0; fail=0
ok() { pass=$((pass + 1)); echo "ok    $*"; }
bad() { fail=$((fail + 1)); echo "FAIL  $*"; }
tmp=$(mktemp -d "${TMPDIR:-/tmp}/ccnurbs_package.XXXXXX") || exit 2
trap 'rm -rf "$tmp"' EXIT INT TERM
py=python3
python3 -c 'import numpy' 2>/dev/null || py=/usr/bin/python3

lib_of() { case $1 in linux-*) echo libccnurbs.so ;; windows-*) echo ccnurbs.dll ;;
           macos-*) echo libccnurbs.dylib ;; esac; }
ob_of() { case $1 in linux-*) echo libscipy_openblas.so ;; windows-*) echo libscipy_openblas.dll ;;
          macos-*) echo libscipy_openblas.dylib ;; esac; }

# 1. contents
sources=$(cd addon && ls ./*.py | sed 's|^\./||' | sort | tr '\n' ' ')
for p in $PLATFORMS; do
  zip="$B/ccnurbs-$version-$(echo "$p" | tr - _).zip"
  if [ ! -f "$zip" ]; then bad "$zip missing (make package)"; continue; fi
  mkdir -p "$tmp/$p" && "$py" -m zipfile -e "$zip" "$tmp/$p" || {
    bad "$zip does not unpack"; continue; }
  problems=""
  [ "$(ls -A "$tmp/$p")" = "ccnurbs" ] || problems="$problems top level: $(ls -A "$tmp/$p");"
  d="$tmp/$p/ccnurbs"
  grep -qx "platforms = \[\"$p\"\]" "$d/blender_manifest.toml" 2>/dev/null ||
    problems="$problems manifest platforms: $(grep '^platforms' "$d/blender_manifest.toml");"
  got=$(cd "$d" && ls ./*.py | sed 's|^\./||' | sort | tr '\n' ' ')
  [ "$got" = "$sources" ] || problems="$problems sources differ from addon/;"
  native=$(cd "$d" && ls | grep -vE '\.(py|toml)$' | sort | tr '\n' ' ')
  want=$(printf '%s\n%s\n' "$(lib_of "$p")" "$(ob_of "$p")" | sort | tr '\n' ' ')
  [ "$native" = "$want" ] || problems="$problems native files: $native(want $want);"
  if [ -z "$problems" ]; then
    ok "$(basename "$zip"): ccnurbs/ with platforms = [\"$p\"], ${native% }, the add-on's sources"
  else
    bad "$(basename "$zip"):$problems"
  fi
done
if cmp -s "$B/ccnurbs.zip" "$B/ccnurbs-$version-linux_x64.zip"; then
  ok "ccnurbs.zip is the linux-x64 package"
else
  bad "$B/ccnurbs.zip is not ccnurbs-$version-linux_x64.zip"
fi

# 2. Blender's validator, per bpy line
validated=""
for line in $LINES; do
  env="$CACHE/venv-bpy-$line"
  val=$(find "$env" -path '*/addons_core/bl_pkg/cli/blender_ext.py' 2>/dev/null | head -n 1)
  if [ ! -f "$env/.ok" ] || [ -z "$val" ]; then
    bad "Blender $line (bpy): not installed (make deps), its validator cannot run"; continue
  fi
  ver=$("$env/bin/python" -c 'import bpy; print(bpy.app.version_string.split()[0])' 2>/dev/null)
  for p in $PLATFORMS; do
    zip="$B/ccnurbs-$version-$(echo "$p" | tr - _).zip"
    [ -f "$zip" ] || continue
    if out=$("$env/bin/python" "$val" validate "$zip" 2>&1); then
      ok "Blender ${ver:-$line} validates $(basename "$zip")"
    else
      bad "Blender ${ver:-$line} validate $(basename "$zip"): $(echo "$out" | tail -n 3 | tr '\n' ' ')"
    fi
  done
  validated="$validated ${ver:-$line}"
done

# 3. native files
tbd=$(find "$CACHE"/xbuild/venv-zig-*/ -path '*/libc/darwin/libSystem.tbd' 2>/dev/null | head -n 1)
for p in $PLATFORMS; do
  case $p in linux-*) kind=elf ;; windows-*) kind=pe ;; macos-*) kind=macho ;; esac
  if [ "$kind" = macho ] && [ -z "$tbd" ]; then bad "$p: no libSystem.tbd (make deps)"; continue; fi
  "$py" tests/package/bincheck.py "$kind" "$B/$p" $tbd >"$tmp/bincheck.log" 2>&1
  rc=$?
  grep -E '^(ok|FAIL) ' "$tmp/bincheck.log" >"$tmp/lines"
  while IFS= read -r l; do
    case $l in ok*) ok "${l#ok    }" ;; *) bad "${l#FAIL  }" ;; esac
  done <"$tmp/lines"
  if [ $rc -ne 0 ] && ! grep -q '^FAIL' "$tmp/lines"; then
    bad "$p: bincheck failed: $(tail -n 3 "$tmp/bincheck.log")"
  fi
done

# 4. the add-on's message on a package of another platform
for p in linux-x64 windows-x64 macos-arm64; do
  d="$tmp/$p/ccnurbs"
  [ -d "$d" ] || continue
  msg=$("$py" -c "
import importlib.util, sys
spec = importlib.util.spec_from_file_location('native', sys.argv[1] + '/native.py')
n = importlib.util.module_from_spec(spec); spec.loader.exec_module(n)
print(n.available(), n.platform_name(), n.load_error())" "$d" 2>&1)
  case $p in
    linux-x64) [ "$msg" = "True linux-x64 None" ] && ok "add-on loads the linux-x64 package here" ||
                 bad "add-on on the linux-x64 package: $msg" ;;
    *) case $msg in
         "False linux-x64 cannot load the CCNURBS library: this CCNURBS package is for $p, this"\
" Blender runs on linux-x64: install the package made for linux-x64; "*)
           ok "add-on on the $p package here says: ${msg#False linux-x64 }" ;;
         *) bad "add-on on the $p package: $msg" ;;
       esac ;;
  esac
done

echo "run_package: tested where: linux-x64 here (glibc <= 2.28 checked; the add-on suite on every" \
     "Blender by run_blender.sh); windows-x64 under Wine (run_wine.sh: C suite, the DLL as the" \
     "add-on loads it, CLI); macos-arm64, macos-x64 built and link-checked only, not run: untested" \
     "on Apple hardware; validated by Blender$validated"
echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
