#!/bin/sh
# OpenSubdiv's regression shapes (catmark_*.h) for tests/oracle/run_osd_shapes.sh, run by
# `make deps`. They are OpenSubdiv's data (Modified Apache 2.0 License) and are not in this
# repository: they come from Debian's source package of the OpenSubdiv the oracle links
# (opensubdiv 3.5.0, the orig tarball in Debian's archive, checked against the SHA-256 of its
# .dsc) and are kept in a cache outside the checkout, so a second run downloads nothing:
#   ${CCN_CACHE:-$HOME/.cache/ccnurbs}/opensubdiv-3.5.0/regression/shapes/*.h, LICENSE.txt
# Prints the shapes directory. Idempotent; exits 1 (with the reason) if they cannot be had.
set -e
CACHE=${CCN_CACHE:-${XDG_CACHE_HOME:-$HOME/.cache}/ccnurbs}
DIR=$CACHE/opensubdiv-3.5.0
URL=${OSD_ORIG_URL:-http://deb.debian.org/debian/pool/main/o/opensubdiv/opensubdiv_3.5.0.orig.tar.xz}
SHA=8bc452ad9934d69bd2b03662e9d86a3d014d95445dc599013e523e577ae90693
if [ -f "$DIR/.complete" ]; then echo "$DIR/regression/shapes"; exit 0; fi
mkdir -p "$CACHE"
tmp=$(mktemp -d "$CACHE/.osd.XXXXXX")
trap 'rm -rf "$tmp"' EXIT INT TERM
echo "osd_shapes_deps: downloading $URL" >&2
if ! curl -fsSL --retry 3 -o "$tmp/orig.tar.xz" "$URL"; then
  echo "osd_shapes_deps: cannot download $URL" >&2; exit 1
fi
got=$(sha256sum "$tmp/orig.tar.xz" | cut -d' ' -f1)
if [ "$got" != "$SHA" ]; then
  echo "osd_shapes_deps: $URL has SHA-256 $got, expected $SHA" >&2; exit 1
fi
top=$(tar -tJf "$tmp/orig.tar.xz" | head -1 | cut -d/ -f1)
tar -xJf "$tmp/orig.tar.xz" -C "$tmp" "$top/regression/shapes" "$top/LICENSE.txt" "$top/NOTICE.txt"
rm -rf "$DIR"
mkdir -p "$DIR/regression"
mv "$tmp/$top/regression/shapes" "$DIR/regression/shapes"
mv "$tmp/$top/LICENSE.txt" "$tmp/$top/NOTICE.txt" "$DIR/"
touch "$DIR/.complete"
echo "$DIR/regression/shapes"
