#!/bin/sh
# `make deps`, Wine part (after the Debian packages, wine64 among them): the Wine prefix that
# tests/package/run_wine.sh runs the Windows build in, made once (wineboot, ~10 s, no download)
# in $CCN_CACHE/wine-prefix (CCN_CACHE default ${XDG_CACHE_HOME:-~/.cache}/ccnurbs); its `.ok`
# marks it done. CCN_WINEPREFIX names another prefix.
CACHE=${CCN_CACHE:-${XDG_CACHE_HOME:-$HOME/.cache}/ccnurbs}
prefix=${CCN_WINEPREFIX:-$CACHE/wine-prefix}
[ -f "$prefix/.ok" ] && [ -f "$prefix/system.reg" ] && exit 0
command -v wine >/dev/null 2>&1 || { echo "deps_wine: wine is not installed" >&2; exit 1; }
rm -rf "$prefix" && mkdir -p "$(dirname "$prefix")" || exit 1
echo "deps: Wine prefix $prefix"
# no Mono/Gecko (their installers would ask to download), no console output
WINEPREFIX="$prefix" WINEDEBUG=-all WINEDLLOVERRIDES="mscoree,mshtml=" wine wineboot -i \
  >"$prefix.log" 2>&1
WINEPREFIX="$prefix" wineserver -w 2>/dev/null
[ -f "$prefix/system.reg" ] || { echo "deps_wine: wineboot failed (see $prefix.log)" >&2; exit 1; }
touch "$prefix/.ok"
