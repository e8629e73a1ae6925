#!/bin/sh
# Li, Finnigan, Sederberg 2016 section 7 experiments through `ccnurbs experiment`
# (DESIGN 4.3 acceptance; reference/eigen/SPEC.md section 3). Figures: tests/experiments/RESULTS.md. The library chooses the eigen polyhedron
# per vertex (rules/eigen_select.c); the experiment measures that choice with its own machinery
# (the engine's refinement, its own face-local maxima count, the 3-ring matrix from the engine,
# LAPACK's eigenvectors, the exact Bezier test of det J).
#
#  (a) maxima, the per-vertex choice, uniform [1e-6, 1], level 5: every case has one maximum at
#      level 5 and no errors (100 % of 10,000, which `make test` runs; EXP_MAXIMA_CASES
#      sets another count for a quick local run). The 10,000 take 70-190 s on 2 cores.
#  (a') the first 1,200 of those cases with the paper's polyhedron (--polyhedron 1): the known twin
#      peaks (cases 332, 644, 704, 1118) are found, so (a) can fail.
#  (b) SPEC 3.3's table: Fig. 16-18 intervals give 2 maxima at level 5 with NURSS rules and 1
#      with the eigen rules; the nurss count is confirmed on tests/data/fig1[678]_v*.obj through
#      `ccnurbs refine` and an awk counter (independent of the experiment's own cage and count);
#      the 3-ring cage is exact (a 6-ring / 4-ring cage gives identical level-5 figures).
#  (c) charmap, the per-vertex choice, 1,000 cases, uniform [1e-6, 1]: 3-ring matrix consistent
#      with ccn_ev_matrix, spectrum, regular and injective in every case (100 %).
#  (c') charmap with the paper's polyhedron, 1,000 cases, uniform [1e-3, 1]: the known
#      non-regular maps (cases 55, 840; det J provably changes sign) are found, and no others.
#  (d) maxima, NURSS rules, 2,000 cases: a higher failure rate than (a') (the contrast).
#  (e) maxima from the level-0 cage (the library pipeline), 2,000 cases: 100 %.
#  (f) the first failure of (a') and of (c') pass with the choice (--knots, `ccnurbs matrix`
#      names another polyhedron).
# One line per check, then "N passed, N failed"; exit 0 only if every check passed.
# Environment (optional): CCNURBS (CLI, default build/ccnurbs), EXP_THREADS (default 2),
# EXP_MAXIMA_CASES (cases of (a), default 10000).
cd "$(dirname "$0")/../.." || exit 2

CCN=${CCNURBS:-build/ccnurbs}
T=${EXP_THREADS:-2}
KNOWN_CHARMAP="55 840"
pass=0
fail=0

if [ ! -x "$CCN" ]; then
  echo "FAIL $CCN is missing (make build)"
  echo "0 passed, 1 failed"
  exit 1
fi
tmp=$(mktemp -d "${TMPDIR:-/tmp}/ccn_exp.XXXXXX") || exit 2
trap 'rm -rf "$tmp"' EXIT
trap 'exit 130' INT TERM

report() { # ok|FAIL label message
  if [ "$1" = ok ]; then pass=$((pass + 1)); else fail=$((fail + 1)); fi
  printf '%-4s %-34s %s\n' "$1" "$2" "$3"
}
check() { # label condition-as-shell-test message
  if eval "$2"; then report ok "$1" "$3"; else report FAIL "$1" "$3"; fi
}
val() { # file key: the first integer after "key: "
  sed -n "s/^$2: \([0-9][0-9]*\).*/\1/p" "$1" | head -n 1
}
run() { # output-file experiment args...
  out=$1; shift
  if ! "$CCN" experiment "$@" --threads "$T" > "$out" 2> "$out.err"; then
    cat "$out.err"
    return 1
  fi
}
# maxima at level 5 from a --knots run: the last number of "maxima per level 1..5: ..."
level5() {
  sed -n 's/^maxima per level 1\.\.5:\([0-9 ]*\).*/\1/p' "$1" | awk '{ print $NF }'
}
# face-local maxima of an OBJ (z > 1e-12, strictly above every vertex sharing a face)
count_obj_maxima() {
  awk '
    /^v / { nv++; z[nv] = $4 + 0 }
    /^f / {
      n = NF - 1
      for (a = 2; a <= NF; a++) { split($a, p, "/"); fv[a - 1] = p[1] + 0 }
      for (a = 1; a <= n; a++) for (b = 1; b <= n; b++)
        if (a != b && !(z[fv[a]] > z[fv[b]])) lower[fv[a]] = 1
    }
    END { c = 0; for (v = 1; v <= nv; v++) if (z[v] > 1e-12 && !(v in lower)) c++; print c }' "$1"
}

# ---- (a) maxima, the per-vertex choice ---------------------------------------------------------
a=$tmp/a.txt
if run "$a" maxima --scheme eigen --cases "${EXP_MAXIMA_CASES:-10000}" --seed 1 --levels 5 --dist uniform --lo 1e-6; then
  grep '^fail case' "$a"
  cases=$(val "$a" cases); single=$(val "$a" "single maximum"); efail=$(val "$a" failures)
  cases=${cases:-1}; single=${single:-0}; efail=${efail:-999999}
  check "maxima eigen level 5" "[ '$single' = '$cases' ]" \
    "$single / $cases single maximum at level 5 ($efail failures, need 100 %); $(grep '^time' "$a")"
  check "maxima eigen no errors" "[ '$(val "$a" errors)' = 0 ] && [ '$(val "$a" non-finite)' = 0 ]" \
    "errors $(val "$a" errors), non-finite $(val "$a" non-finite), $(grep '^fallbacks' "$a")"
else
  report FAIL "maxima eigen" "experiment did not run"
fi
ap=$tmp/ap.txt
if run "$ap" maxima --scheme eigen --polyhedron 1 --cases 1200 --seed 1 --levels 5 --dist uniform --lo 1e-6; then
  got=$(sed -n 's/^fail case \([0-9]*\) .*/\1/p' "$ap" | tr '\n' ' ')
  pfail=$(val "$ap" failures); pfail=${pfail:-0}
  check "maxima paper's polyhedron (contrast)" "[ '$got' = '332 644 704 1118 ' ]" \
    "twin peaks with the paper's lengths in cases: $got(RESULTS.md: 332 644 704 1118)"
else
  report FAIL "maxima paper's polyhedron" "experiment did not run"; pfail=0
fi

# ---- (b) Fig. 16-18 ---------------------------------------------------------------------------
for cfg in 16:v6:1,10,10,1,1,10 17:v7:1,8,8,1,1,1,8 18:v8:1,5,5,1,1,1,5,1; do
  fig=${cfg%%:*}; rest=${cfg#*:}; v=${rest%%:*}; k=${rest#*:}
  for sch in nurss eigen; do
    f=$tmp/fig$fig$sch.txt
    want=1; [ $sch = nurss ] && want=2
    if run "$f" maxima --scheme $sch --knots "$k"; then
      got=$(level5 "$f")
      check "fig $fig ($k) $sch" "[ '$got' = $want ]" \
        "maxima per level: $(sed -n 's/^maxima per level 1\.\.5: //p' "$f") (want $want at level 5)"
    else
      report FAIL "fig $fig $sch" "experiment did not run"
    fi
  done
  obj=tests/data/fig${fig}_$v.obj
  for sch in nurss eigen; do
    want=1; [ $sch = nurss ] && want=2
    if "$CCN" refine --scheme $sch --levels 5 "$obj" "$tmp/r.obj" 2> "$tmp/r.err"; then
      got=$(count_obj_maxima "$tmp/r.obj")
      check "fig $fig cage file $sch" "[ '$got' = $want ]" \
        "$obj refined 5 levels from the cage: $got maxima (awk count, want $want)"
    else
      report FAIL "fig $fig cage file $sch" "$(cat "$tmp/r.err")"
    fi
  done
  # the library pipeline from the level-0 cage (M at level 0 for a ready EV, refine.c)
  if run "$tmp/c$fig.txt" maxima --scheme eigen --start cage --knots "$k"; then
    per=$(sed -n 's/^maxima per level 1\.\.5: //p' "$tmp/c$fig.txt")
    check "fig $fig eigen from the cage" "[ '$per' = '1 1 1 1 1' ]" "maxima per level: $per"
  else
    report FAIL "fig $fig eigen from the cage" "experiment did not run"
  fi
done
for st in level1:6 cage:4; do
  s=${st%%:*}; r=${st#*:}
  k=0.028842936727228593,0.50936109731746526,0.071455828525520224,0.55190057828025219,0.8918351929677919,0.24884715363825369,0.24847156436929735,0.039191396373613324
  run "$tmp/r3.txt" maxima --start "$s" --rings 3 --knots "$k" &&
    run "$tmp/rb.txt" maxima --start "$s" --rings "$r" --knots "$k"
  l3=$(grep '^level 5:' "$tmp/r3.txt"); lb=$(grep '^level 5:' "$tmp/rb.txt")
  # the same support and fallbacks; sum and maximum within rounding and their printed digits (12
  # and 15: the two cages' arithmetic differs in the last bits, 1-2 ulps measured, so equal
  # printed digits would be chance)
  same=$(printf '%s\n%s\n' "$l3" "$lb" | awk '{
      s = $0; sub(/^.*support /, "", s); sub(/ vertices.*/, "", s)
      f = $0; sub(/^.*fallbacks /, "", f)
      t = $0; sub(/^.*sum z /, "", t); sub(/,.*/, "", t)
      z = $0; sub(/^.*max z /, "", z); sub(/,.*/, "", z)
      S[NR] = s; F[NR] = f; T[NR] = t + 0; Z[NR] = z + 0 }
    function near(a, b, tol) { return (a - b <= tol * (a < 0 ? -a : a) && b - a <= tol * (a < 0 ? -a : a)) }
    END { print (NR == 2 && S[1] != "" && S[1] == S[2] && F[1] == F[2] && near(T[1], T[2], 1e-11) &&
                 near(Z[1], Z[2], 1e-13)) ? 1 : 0 }')
  check "3-ring cage exact (start $s)" "[ -n '$l3' ] && [ $same = 1 ]" "rings 3 vs $r: $l3; rings $r: ${lb#level 5: }"
done

# ---- (c) charmap, the per-vertex choice -----------------------------------------------------------
c=$tmp/c.txt
if run "$c" charmap --scheme eigen --cases 1000 --seed 1 --dist uniform --lo 1e-6; then
  grep '^fail case' "$c"
  cases=$(val "$c" cases); cases=${cases:-1}
  check "charmap matrix" "[ '$(val "$c" "matrix ok")' = $cases ]" "$(grep '^matrix ok' "$c")"
  check "charmap spectrum" "[ '$(val "$c" "spectrum ok")' = $cases ]" "$(grep '^spectrum ok' "$c")"
  check "charmap regular+injective" "[ '$(val "$c" "all pass")' = $cases ] && [ '$(val "$c" errors)' = 0 ]" \
    "regular $(val "$c" regular), injective $(val "$c" injective), all pass $(val "$c" "all pass") of $cases (limit surface; need 100 %); $(grep '^time' "$c")"
else
  report FAIL "charmap eigen" "experiment did not run"
fi
cp=$tmp/cp.txt
if run "$cp" charmap --scheme eigen --polyhedron 1 --cases 1000 --seed 1 --dist uniform --lo 1e-3; then
  got=$(sed -n 's/^fail case \([0-9]*\) .*/\1/p' "$cp" | tr '\n' ' ')
  check "charmap paper's polyhedron (contrast)" "[ '$got' = '$KNOWN_CHARMAP ' ]" \
    "non-regular with the paper's lengths in cases: $got(known: $KNOWN_CHARMAP)"
else
  report FAIL "charmap paper's polyhedron" "experiment did not run"
fi

# ---- (d) maxima, NURSS: the contrast -----------------------------------------------------------
d=$tmp/d.txt
if run "$d" maxima --scheme nurss --cases 2000 --seed 1 --levels 5 --list 0; then
  nfail=$(val "$d" failures); nfail=${nfail:-0}
  check "maxima nurss contrast" "[ $nfail -gt $((pfail * 10)) ]" \
    "nurss $nfail / 2000 failures vs the paper's eigen polyhedron $pfail / 1200; $(grep '^failures by valence' "$d")"
else
  report FAIL "maxima nurss" "experiment did not run"
fi

# ---- (e) maxima from the level-0 cage: the library pipeline ------------------------------------
i=$tmp/i.txt
if run "$i" maxima --scheme eigen --start cage --cases 2000 --seed 1 --levels 5 --list 0; then
  cases=$(val "$i" cases); single=$(val "$i" "single maximum"); cases=${cases:-1}; single=${single:-0}
  check "maxima eigen from the cage" "[ '$single' = '$cases' ]" \
    "$single / $cases single maximum at level 5 (need 100 %); $(grep '^failures by valence' "$i")"
else
  report FAIL "maxima eigen from the cage" "experiment did not run"
fi

# ---- (f) the first failures of the paper's polyhedron pass with the choice -----------------------
first_fail() { # experiment output -> "d0,d1,..." of its first failure
  sed -n 's/^fail case [0-9]* .* intervals \([0-9.e,+-]*\).*/\1/p' "$1" | head -n 1
}
for f in "$ap:maxima" "$cp:charmap"; do
  file=${f%%:*}; exp=${f#*:}; k=$(first_fail "$file")
  n=$(echo "$k" | tr ',' '\n' | grep -c .)
  if [ -n "$k" ] && run "$tmp/f.txt" "$exp" --knots "$k" &&
     "$CCN" matrix --valence "$n" --knots "$k" > "$tmp/fm.txt" 2>&1; then
    poly=$(sed -n 's/^# polyhedron //p' "$tmp/fm.txt")
    ok=$(val "$tmp/f.txt" "single maximum"); [ "$exp" = charmap ] && ok=$(val "$tmp/f.txt" "all pass")
    check "first $exp failure passes with the choice" "[ '$ok' = 1 ] && [ '$poly' != 1 ] && [ '$poly' != 0 ]" \
      "intervals $k: polyhedron $poly, $(grep -E '^(maxima per level|regular)' "$tmp/f.txt" | head -n 1)"
  else
    report FAIL "first $exp failure passes with the choice" "no failure to try or the run failed"
  fi
done

echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
