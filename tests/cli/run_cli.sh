#!/bin/sh
# CLI contract: errors print a message on stderr, exit 2 and write no output file;
# a successful refine writes v/f lines and "# knot" lines with the refined intervals; UV maps
# (vt, f v/vt) come back refined (refine) or as limit values per face corner (limit).
cd "$(dirname "$0")/../.." || exit 2
CLI=${CCNURBS:-build/ccnurbs}
T=$(mktemp -d) || exit 2
trap 'rm -rf "$T"' EXIT
pass=0; fail=0
ok()  { pass=$((pass+1)); echo "ok   $1"; }
bad() { fail=$((fail+1)); echo "FAIL $1"; }

# expect_error NAME EXPECTED-MESSAGE-FRAGMENT ARGS... : exit 2, message, no out file
expect_error() {
  name=$1; msg=$2; shift 2
  rm -f "$T/out.obj"
  "$CLI" "$@" > "$T/stdout" 2> "$T/stderr"; rc=$?
  if [ "$rc" -ne 2 ]; then bad "$name: exit $rc, expected 2"; return; fi
  if ! grep -q -- "$msg" "$T/stderr"; then bad "$name: stderr lacks '$msg': $(cat "$T/stderr")"; return; fi
  if [ -e "$T/out.obj" ] || ls "$T"/out.obj.tmp* >/dev/null 2>&1; then bad "$name: output file left behind"; return; fi
  ok "$name"
}

printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 1 1 1\nf 1 2 3\nf 2 1 4\nf 1 2 5\n' > "$T/nonmanifold.obj"
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 2 1 0\nf 1 2 3\nf 1 4 5\n' > "$T/bowtie.obj"
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 2\n' > "$T/repeat.obj"
printf 'v 0 0 0\nv 1 0 0\nf 1 2\n' > "$T/twogon.obj"
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n' > "$T/range.obj"
printf 'v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 2 1 0\nf 1 2 3 4\nf 1 2 6 5\n' > "$T/orient.obj"
printf 'v 0 0 0\nv 1 0 nan\nv 0 1 0\nf 1 2 3\n' > "$T/nan.obj"
printf 'v 0 0 0\nv 1 0\n' > "$T/truncated.obj"
printf '\001\002garbage\377\nf x y z\n' > "$T/garbage.obj"
: > "$T/empty.obj"

expect_error "repeated vertex"    "face 0 repeats vertex 1"       refine --levels 1 "$T/repeat.obj" "$T/out.obj"
expect_error "two-gon"            "face 0 has 2 vertices"         refine --levels 1 "$T/twogon.obj" "$T/out.obj"
expect_error "index out of range" "vertex index 8"                refine --levels 1 "$T/range.obj" "$T/out.obj"
expect_error "NaN coordinate"     "vertex 1 has a non-finite"     refine --levels 1 "$T/nan.obj" "$T/out.obj"
expect_error "truncated OBJ"      "line 2"                        refine --levels 1 "$T/truncated.obj" "$T/out.obj"
expect_error "garbage OBJ"        "line 2"                        refine --levels 1 "$T/garbage.obj" "$T/out.obj"
expect_error "empty OBJ"          "no faces"                      refine --levels 1 "$T/empty.obj" "$T/out.obj"
expect_error "missing file"       "cannot open"                   refine --levels 1 "$T/none.obj" "$T/out.obj"
expect_error "bad scheme"         "bad --scheme"                  refine --scheme foo tests/data/cube.obj "$T/out.obj"
expect_error "bad levels"         "levels"                        refine --levels -2 tests/data/cube.obj "$T/out.obj"
expect_error "bad polyhedron"     "--polyhedron must be"          limit --levels 1 --polyhedron 99 tests/data/cube.obj "$T/out.obj"
expect_error "bad exp polyhedron" "polyhedron"                    experiment maxima --cases 1 --polyhedron -1
expect_error "unknown command"    "unknown command"               frobnicate
expect_error "matrix valence"     "valence"                       matrix --valence 2

# Non-manifold cages are read as OpenSubdiv reads them: one level gives V + E + F vertices
# (the split fans welded back) and a quad per face corner, for refine and limit alike.
expect_counts() {
  name=$1; nv_want=$2; nf_want=$3; shift 3
  for cmd in refine limit; do
    if "$CLI" $cmd --levels 1 "$@" "$T/out.obj" 2> "$T/stderr"; then
      nv=$(grep -c '^v ' "$T/out.obj"); nf=$(grep -c '^f ' "$T/out.obj")
      if [ "$nv" = "$nv_want" ] && [ "$nf" = "$nf_want" ]; then ok "$name $cmd"
      else bad "$name $cmd: $nv verts, $nf faces, expected $nv_want, $nf_want"; fi
    else bad "$name $cmd failed: $(cat "$T/stderr")"; fi
  done
}
expect_counts "non-manifold edge" 15 9 "$T/nonmanifold.obj"
expect_counts "bowtie vertex" 13 6 "$T/bowtie.obj"
expect_counts "flipped face" 15 8 "$T/orient.obj"

# A successful refine: intervals come back halved, as "# knot" lines.
printf 'v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n# knot 1 2 3.0\n' > "$T/quad.obj"
if "$CLI" refine --scheme eigen --levels 2 "$T/quad.obj" "$T/out.obj" 2> "$T/stderr"; then
  nv=$(grep -c '^v ' "$T/out.obj"); nf=$(grep -c '^f ' "$T/out.obj")
  k=$(awk '/^# knot/ {print $5}' "$T/out.obj" | sort -u | tr '\n' ' ')
  if [ "$nv" = 25 ] && [ "$nf" = 16 ] && [ "$k" = "0.25 0.75 " ]; then ok "refine writes halved intervals"
  else bad "refine output: $nv verts, $nf faces, knots '$k'"; fi
else bad "refine of a quad failed: $(cat "$T/stderr")"; fi

# Creases in and out: '# crease i j s' / '# corner i s' read, refined sharpness written back
# (uniform: minus 1 per level), OpenSubdiv's 't' tags read (0-based), unknown tags warned.
printf 'v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nv 1 1 0\nv 2 1 0\nf 1 2 5 4\nf 2 3 6 5\n# crease 2 5 2.5\n# corner 1 3\n' > "$T/crease.obj"
if "$CLI" refine --levels 1 "$T/crease.obj" "$T/out.obj" 2> "$T/stderr"; then
  c=$(awk '/^# crease/ {print $5}' "$T/out.obj" | sort -u | tr '\n' ' '); n=$(grep -c '^# crease' "$T/out.obj")
  k=$(awk '/^# corner/ {print $4}' "$T/out.obj" | tr '\n' ' ')
  if [ "$c" = "1.5 " ] && [ "$n" = 2 ] && [ "$k" = "2 " ]; then ok "refine writes decayed creases and corners"
  else bad "refine creases: '$c' ($n lines), corners '$k'"; fi
else bad "refine of a creased cage failed: $(cat "$T/stderr")"; fi
printf 'v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nv 1 1 0\nv 2 1 0\nf 1 2 5 4\nf 2 3 6 5\nt crease 2/1/0 1 4 2.5\nt corner 1/1/0 0 3\nt hole 1/0/0 0\n' > "$T/tags.obj"
if "$CLI" refine --levels 1 "$T/tags.obj" "$T/out2.obj" 2> "$T/stderr" && grep -q "unsupported tag 'hole' ignored" "$T/stderr" &&
   [ "$(grep -v '^# ccnurbs' "$T/out.obj" | md5sum)" = "$(grep -v '^# ccnurbs' "$T/out2.obj" | md5sum)" ]; then
  ok "t crease / t corner tags = # crease / # corner; unknown tag warned"
else bad "t tags: $(cat "$T/stderr")"; fi
printf 'v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n# crease 1 2 nan\n' > "$T/nancrease.obj"
expect_error "NaN crease"         "NaN crease sharpness"          refine --levels 1 "$T/nancrease.obj" "$T/out.obj"
printf 'v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n# corner 9 2\n' > "$T/farcorner.obj"
expect_error "corner beyond vertices" "corner names vertex 9"   refine --levels 1 "$T/farcorner.obj" "$T/out.obj"
expect_error "bad crease method"  "bad --crease-method"           refine --crease-method foo tests/data/cube.obj "$T/out.obj"

# UV maps: vt in and out, --fvar-linear, the file's facevaryinginterpolateboundary tag.
printf 'v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 2 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 0.2 0.1\nvt 0.7 0.4\nvt 0.6 0.9\nvt 0.1 0.8\nf 1/1 2/2 3/3 4/4\nf 2/5 5/6 6/7 3/8\nt facevaryinginterpolateboundary 1/0/0 5\n' > "$T/uv.obj"
if "$CLI" refine --levels 1 "$T/uv.obj" "$T/out.obj" 2> "$T/stderr" && grep -q '^vt 0.40000000000000002 0.55000000000000004$' "$T/out.obj" &&
   grep -q -- '--fvar-linear all' "$T/out.obj" && [ "$(grep -c '^vt ' "$T/out.obj")" = 18 ] && grep -q '^f [0-9]*/[0-9]* ' "$T/out.obj"; then
  ok "refine writes refined vt (the tag's mode: all, bilinear face point)"
else bad "refine with vt: $(cat "$T/stderr")"; fi
if grep -q '^vt 0.20000000000000001 0.10000000000000001$' "$T/out.obj" &&
   "$CLI" refine --levels 1 --fvar-linear none "$T/uv.obj" "$T/out.obj" 2> "$T/stderr" && grep -q -- '--fvar-linear none' "$T/out.obj" &&
   ! grep -q '^vt 0.20000000000000001 0.10000000000000001$' "$T/out.obj"; then
  ok "--fvar-linear wins over the tag (all keeps the corner values, none moves them)"
else bad "--fvar-linear none: $(cat "$T/stderr")"; fi
if "$CLI" limit --levels 2 "$T/uv.obj" "$T/out.obj" 2> "$T/stderr" && grep -q '^f [0-9]*/[0-9]*/[0-9]* ' "$T/out.obj" &&
   [ "$(grep -c '^vt ' "$T/out.obj")" -gt 25 ]; then
  ok "limit writes limit vt per face corner (f v/vt/vn)"
else bad "limit with vt: $(cat "$T/stderr")"; fi
expect_error "bad fvar mode"      "bad --fvar-linear"             refine --fvar-linear foo "$T/uv.obj" "$T/out.obj"
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1 3/4\n' > "$T/vtbeyond.obj"
expect_error "texture index beyond vt" "OBJ line 5: texture index 4" limit --levels 1 "$T/vtbeyond.obj" "$T/out.obj"
printf 'v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1 3 4\n' > "$T/vtpartial.obj"
if "$CLI" refine --levels 1 "$T/vtpartial.obj" "$T/out.obj" 2> "$T/stderr" && grep -q "UV map ignored" "$T/stderr" &&
   ! grep -q '^vt' "$T/out.obj"; then ok "a partial UV map is ignored with a warning"
else bad "partial UV map: $(cat "$T/stderr")"; fi

printf 'v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\nf 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n' > "$T/cube.obj"
# --curvature: PLY with k1 k2 per vertex; the limit of a cube is convex: k1 >= k2 >= 0 at every
# vertex with caps (the caps' own curvature), nan at exactly its 8 extraordinary corners without
# caps
ply_check() { # FILE NAN-COUNT: header, k1 >= k2 >= 0 where a number, that many nan rows
  awk -v want="$2" 'NR == 1 && $0 != "ply" { exit 1 }
        /^element vertex/ { nv = $3 } /^property double k[12]$/ { props++ }
        /^end_header/ { body = 1; next }
        body && n < nv { n++; if ($7 == "nan") nan++; else if ($8 + 0 < -1e-9 || $7 + 0 < $8 + 0) exit 1 }
        END { exit !(props == 2 && n == nv && nv == 386 && nan + 0 == want) }' "$1"
}
if "$CLI" limit --levels 3 --curvature "$T/cube.obj" "$T/out.ply" 2> "$T/stderr" && ply_check "$T/out.ply" 0 &&
   "$CLI" limit --levels 3 --cap refine --curvature "$T/cube.obj" "$T/out.ply" 2> "$T/stderr" && ply_check "$T/out.ply" 8; then
  ok "limit --curvature writes PLY: k1 >= k2 >= 0 on a cube's convex limit, nan only at its 8 corners without caps"
else bad "limit --curvature: $(cat "$T/stderr")"; fi
expect_error "curvature needs PLY" "name the output \*.ply" limit --curvature "$T/cube.obj" "$T/out.obj"

echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
