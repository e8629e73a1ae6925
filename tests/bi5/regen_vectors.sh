#!/bin/sh
# Regenerates tests/bi5/test_vectors.txt from the numpy reference prototype
# (reference/bi5/dump_vectors.py; needs /usr/bin/python3 with python3-numpy, `make deps`).
# The C tests read the committed file; they never run Python.
set -e
REF=${BI5_REFERENCE:-/work/shared/reference/bi5}
OUT=$(cd "$(dirname "$0")" && pwd)/test_vectors.txt
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
cp "$REF"/*.py "$TMP"/
(cd "$TMP" && /usr/bin/python3 dump_vectors.py)
cp "$TMP"/test_vectors.txt "$OUT"
echo "wrote $OUT"
