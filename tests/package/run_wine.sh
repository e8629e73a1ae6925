#!/bin/sh
# The Windows package under Wine (Debian's wine64; picked up by tests/run_tests.sh). What
# tests/package/package.mk built for windows-x64 in $B (CCN_BUILD, default build):
#  1. the C test suite: every tests/c/test_*.c cross-compiled ($B/windows-x64/tests/*.exe), run
#     with CCN_TEST_SMALL=1 (the heavy tests' small sizes) from the repository root;
#  2. the packaged ccnurbs.dll loaded from its package folder as the add-on loads it
#     (loadcheck.exe: AddDllDirectory + LoadLibraryExW, every function addon/native.py binds),
#     its limit surfaces of every tests/data/*.obj equal to the linux-x64 package's <= 1e-12;
#  3. the CLI: `limit --levels 2` and `refine --scheme eigen --levels 2` on every tests/data/*.obj,
#     equal to the linux-x64 package's CLI <= 1e-12 (same compiler and OpenBLAS: the platforms
#     compared; in practice bit-identical), and close to the Debian build's $B/ccnurbs (reference
#     LAPACK instead of OpenBLAS): positions <= 1e-10, normals (`vn`) <= 1e-8 (mixed_boundary's
#     normal at a degenerate boundary vertex differs by ~5e-9 between the two LAPACKs, with any
#     compiler); the largest differences are printed.
# One line per check, "N passed, N failed" last; exit 1 on any failure. Wine or a build missing
# is a failure. The Wine prefix: tests/package/deps_wine.sh (made here if missing).
cd "$(dirname "$0")/../.." || exit 2
B=${CCN_BUILD:-build}
CACHE=${CCN_CACHE:-${XDG_CACHE_HOME:-$HOME/.cache}/ccnurbs}
WINEPREFIX=${CCN_WINEPREFIX:-$CACHE/wine-prefix}
WINEDEBUG=-all
WINEDLLOVERRIDES="mscoree,mshtml="
export WINEPREFIX WINEDEBUG WINEDLLOVERRIDES
TIMEOUT=${CCN_WINE_TIMEOUT:-300}
W=$B/windows-x64
L=$B/linux-x64
pass=0; fail=0
ok() { pass=$((pass + 1)); echo "ok    $*"; }
bad() { fail=$((fail + 1)); echo "FAIL  $*"; }
finish() {
  echo "run_wine: Windows x64 (windows-x64 package) tested under $(wine --version 2>/dev/null)"
  echo "$pass passed, $fail failed"
  [ "$fail" -eq 0 ]; exit
}

if ! command -v wine >/dev/null 2>&1; then
  bad "wine is not installed (make deps installs Debian's wine64)"; finish
fi
CCN_WINEPREFIX=$WINEPREFIX sh tests/package/deps_wine.sh >/dev/null || { bad "no Wine prefix"; finish; }
for f in "$W/ccnurbs.exe" "$W/ccnurbs.dll" "$W/loadcheck/loadcheck.exe" "$L/ccnurbs" \
         "$L/loadcheck/loadcheck" "$B/ccnurbs" "$B/xpkg/windows-x64/ccnurbs/ccnurbs.dll" \
         "$B/xpkg/linux-x64/ccnurbs/libccnurbs.so"; do
  [ -f "$f" ] || { bad "$f missing (make package: tests/package/package.mk)"; finish; }
done
tmp=$(mktemp -d "${TMPDIR:-/tmp}/ccnurbs_wine.XXXXXX") || exit 2
trap 'rm -rf "$tmp"' EXIT INT TERM
# wine_run LOG ARGS...: the program under Wine, output to LOG; a failed run is run once more (under
# load Wine itself has failed a start now and then: exit 1, no output, the same program passing
# when run again), and the first failure is reported in $retried so that the check says so.
retried=""
wine_run() {
  log=$1; shift
  timeout "$TIMEOUT" wine "$@" >"$log" 2>&1
  rc=$?
  if [ $rc -ne 0 ]; then
    first=$(tr -d '\r' <"$log" | grep -v '^ok' | tail -n 1)
    timeout "$TIMEOUT" wine "$@" >"$log" 2>&1
    rc2=$?
    [ $rc2 -eq 0 ] && retried=" (passed when run again; the first run: exit $rc${first:+, $first})"
    rc=$rc2
  fi
  return $rc
}
# one server for all the runs below (a wine start is then ~0.1 s); it ends 10 s after the last
wineserver -p10 2>/dev/null

# 1. the C suite
CCN_TEST_SMALL=1 # the heavy tests' small sizes (the CLI and loadcheck below do not read it)
export CCN_TEST_SMALL
for src in tests/c/test_*.c; do
  name=$(basename "$src" .c)
  exe=$W/tests/$name.exe
  if [ ! -f "$exe" ]; then bad "$name: $exe missing"; continue; fi
  t0=$(date +%s)
  retried=""
  wine_run "$tmp/$name.log" "$exe"
  rc=$?
  summary=$(tr -d '\r' <"$tmp/$name.log" | grep -E '^[0-9]+ passed, [0-9]+ failed$' | tail -n 1)
  secs=$(( $(date +%s) - t0 ))
  if [ $rc -eq 0 ] && [ -n "$summary" ] && [ "${summary#*passed, }" = "0 failed" ]; then
    ok "$name.exe: $summary (${secs}s)$retried"
  else
    bad "$name.exe: exit $rc, ${summary:-no summary} (${secs}s); last lines:"
    tr -d '\r' <"$tmp/$name.log" | grep -v '^ok' | tail -n 15 | sed 's/^/      /'
  fi
done

# 2. the packaged DLL as the add-on loads it, against the linux-x64 package's library
need=$(grep -oE 'lib\.ccn_[a-z0-9_]+' addon/native.py | sed 's/^lib\.//' | sort -u |
       sed 's/^/--need /' | tr '\n' ' ')
# shellcheck disable=SC2086
"$L/loadcheck/loadcheck" "$B/xpkg/linux-x64/ccnurbs/libccnurbs.so" $need --out "$tmp/lc_linux.txt" \
  tests/data/*.obj >"$tmp/lc_linux.log" 2>&1
rc_l=$?
# shellcheck disable=SC2086
timeout "$TIMEOUT" wine "$W/loadcheck/loadcheck.exe" "$B/xpkg/windows-x64/ccnurbs/ccnurbs.dll" \
  $need --out "$tmp/lc_win.txt" tests/data/*.obj >"$tmp/lc_win.log" 2>&1
rc_w=$?
if [ $rc_l -ne 0 ] || [ $rc_w -ne 0 ]; then
  bad "packaged ccnurbs.dll / libccnurbs.so loaded by loadcheck: exit $rc_w / $rc_l"
  tr -d '\r' <"$tmp/lc_win.log" | tail -n 5 | sed 's/^/      /'
  tail -n 5 "$tmp/lc_linux.log" | sed 's/^/      /'
elif cmp=$(python3 tests/package/objcmp.py "$tmp/lc_linux.txt" "$tmp/lc_win.txt"); then
  ok "packaged ccnurbs.dll loaded from its folder (OpenBLAS beside it), $(echo "$need" |
     wc -w | awk '{print $1 / 2}') add-on functions exported, limit surfaces of" \
     "$(ls tests/data/*.obj | wc -l) cages vs linux-x64: $cmp"
else
  bad "packaged ccnurbs.dll vs linux-x64 limit surfaces: $cmp"
fi

# 3. the CLI
for obj in tests/data/*.obj; do
  n=$(basename "$obj" .obj)
  line=""; status=ok
  for cmd in limit refine; do
    case $cmd in limit) args="limit --levels 2" ;; refine) args="refine --scheme eigen --levels 2" ;; esac
    retried=""
    # shellcheck disable=SC2086
    wine_run "$tmp/cli.log" "$W/ccnurbs.exe" $args "$obj" "$tmp/$n.$cmd.win.obj"
    rw=$?
    # shellcheck disable=SC2086
    "$L/ccnurbs" $args "$obj" "$tmp/$n.$cmd.lin.obj" >/dev/null 2>&1; rl=$?
    # shellcheck disable=SC2086
    "$B/ccnurbs" $args "$obj" "$tmp/$n.$cmd.deb.obj" >/dev/null 2>&1; rd=$?
    if [ $rw -ne $rl ] || [ $rw -ne $rd ]; then
      status=FAIL; line="$line $cmd: exit $rw (linux-x64 $rl, Debian build $rd; Windows said:" \
        "$(tr -d '\r' <"$tmp/cli.log" | tail -n 2 | tr '\n' ' '));"
    elif [ $rw -ne 0 ]; then
      line="$line $cmd: fails on all three (exit $rw);"
    else
      c1=$(python3 tests/package/objcmp.py "$tmp/$n.$cmd.lin.obj" "$tmp/$n.$cmd.win.obj") || status=FAIL
      c2=$(python3 tests/package/objcmp.py --tol 1e-10 --tol-vn 1e-8 "$tmp/$n.$cmd.deb.obj" \
           "$tmp/$n.$cmd.win.obj") ||
        status=FAIL
      line="$line $cmd: linux-x64 ${c1#same }, Debian build ${c2#same }$retried;"
    fi
  done
  if [ $status = ok ]; then ok "ccnurbs.exe $n.obj:${line%;}"; else bad "ccnurbs.exe $n.obj:${line%;}"; fi
done
finish
