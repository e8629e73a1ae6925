#!/bin/sh
# The source tree's shape: tests/layout/check_layers.py on this checkout, after a
# self-test that shows each of its checks failing on a small tree built here that breaks it.
cd "$(dirname "$0")/../.." || exit 2
CHECK=tests/layout/check_layers.py
tmp=$(mktemp -d "${TMPDIR:-/tmp}/ccn_layout.XXXXXX") || exit 2
trap 'rm -rf "$tmp"' EXIT INT TERM
pass=0; fail=0
report() { # status label detail
  if [ "$1" = ok ]; then pass=$((pass + 1)); else fail=$((fail + 1)); fi
  printf '%-4s %-40s %s\n' "$1" "$2" "$3"
}

# A minimal valid tree: base <- topology, an add-on of two modules.
fixture() {
  d="$tmp/$1"; rm -rf "$d"; mkdir -p "$d/csrc/include" "$d/csrc/base" "$d/csrc/topology" "$d/addon"
  printf '#ifndef P_H\n#define P_H\nint ccn_pub(void);\n#endif\n' >"$d/csrc/include/ccnurbs.h"
  printf 'int ccn__b(void);\n' >"$d/csrc/base/b.h"
  printf '#include "base/b.h"\nint ccn__b(void) { return 1; }\n' >"$d/csrc/base/b.c"
  printf 'int ccn__t(void);\n' >"$d/csrc/topology/t.h"
  printf '#include "topology/t.h"\n#include "base/b.h"\nint ccn__t(void) { return ccn__b(); }\n' >"$d/csrc/topology/t.c"
  printf 'from . import a\n' >"$d/addon/__init__.py"
  printf 'X = 1\n' >"$d/addon/a.py"
  printf 'from . import a\n' >"$d/addon/b.py"
  echo "$d"
}
expect() { # label expected-failing-check tree
  out=$(python3 "$CHECK" --root "$3" 2>&1)
  if [ $? -ne 0 ] && echo "$out" | grep -q "^FAIL $2"; then report ok "self-test: $1" "detected"
  else report FAIL "self-test: $1" "not detected: $(echo "$out" | tr '\n' '|')"; fi
}

d=$(fixture valid)
if python3 "$CHECK" --root "$d" >/dev/null 2>&1; then report ok "self-test: valid tree passes"
else report FAIL "self-test: valid tree passes" "$(python3 "$CHECK" --root "$d" | tr '\n' '|')"; fi

d=$(fixture callcycle)   # base calls topology: a call circle and an upward call
printf 'int ccn__t(void);\nint ccn__b(void) { return ccn__t(); }\n' >"$d/csrc/base/b.c"
expect "call circle" "no C dependency circle" "$d"
expect "upward call" "C layers point downwards" "$d"

d=$(fixture inccycle)    # base includes topology's header, topology includes base's
printf '#include "topology/t.h"\nint ccn__b(void) { return 1; }\n' >"$d/csrc/base/b.c"
expect "include circle" "no C dependency circle" "$d"

d=$(fixture bigfile)
python3 -c "print('\n'.join('/* %d */' % i for i in range(801)))" >>"$d/csrc/base/b.c"
expect "file over 800 lines" "files <= 800 lines" "$d"

d=$(fixture pycycle)     # a imports b inside a function, b imports a
printf 'def f():\n    from . import b\n    return b\n' >"$d/addon/a.py"
expect "add-on import circle" "no add-on import circle" "$d"

d=$(fixture dupname)
mkdir -p "$d/csrc/rules"; printf 'int ccn__r(void) { return 2; }\n' >"$d/csrc/rules/b.c"
expect "duplicate object name" "library object names unique" "$d"

echo "-- this checkout:"
python3 "$CHECK" | grep -v ' passed, ' | sed 's/^/  /'
if python3 "$CHECK" >/dev/null 2>&1; then report ok "tree layout" "see lines above"
else report FAIL "tree layout" "see lines above"; fi
echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
