#!/bin/sh
# The CAD writers vs OpenCASCADE (build/occt_read): test_cad_writer writes a closed pillow
# cube (6 Bezier faces), an open 2x3 patch grid and a periodic non-uniform torus face as
# STEP and IGES (and a T-junction model: a packed B-spline face whose side is split into three
# edges next to three Bezier faces; the torus with split seams) plus reference grids from its own Cox-de Boor evaluator. For every file:
# the loops as written (OpenCASCADE's entity model, before translation): closed head to
# tail, every shared edge used once each way; read without failure, BRepCheck valid with
# and without the reader's shape healing, one shell, the expected faces/edges/vertices, no
# free edge when closed, positive volume (the faces point out; the cube's is exactly 1.225),
# every inner edge used by exactly two faces (or twice by one face:
# a seam), no load warning, no transfer warning except one "made periodic" note per
# periodic face; every face evaluated by OpenCASCADE equals the reference <= 1e-12 (same
# parameters); normals agree across shared edges <= 1e-8 rad where the surface is smooth
# (grid, torus). Torus: exactly one periodic B-spline face with the given intervals as knots
# and the surface equals the Geom_BSplineSurface OpenCASCADE builds from poles and knots
# (occt_read --build) <= 1e-12.
cd "$(dirname "$0")/../.." || exit 2
T=$(mktemp -d) || exit 2
trap 'rm -rf "$T"' EXIT
pass=0; fail=0
ok() { pass=$((pass+1)); echo "ok   $*"; }
bad() { fail=$((fail+1)); echo "FAIL $*"; }
val() { sed -n "s/^$1: //p" "$2" | head -n 1; }

if ! build/tests/test_cad_writer "$T" >"$T/writer.log" 2>&1; then
  cat "$T/writer.log"; echo "FAIL test_cad_writer"; exit 1
fi

# max |a - b| over x y z (columns 6-8) and |u - u'| + |v - v'|, rows matched by (face, i, j)
griddiff() {
  awk 'NR == FNR { k = $1 " " $2 " " $3; x[k] = $6; y[k] = $7; z[k] = $8; u[k] = $4; v[k] = $5; next }
       { k = $1 " " $2 " " $3; if (!(k in x)) { miss++; next }
         n++; d = $6 - x[k]; if (d < 0) d = -d; if (d > m) m = d
         d = $7 - y[k]; if (d < 0) d = -d; if (d > m) m = d
         d = $8 - z[k]; if (d < 0) d = -d; if (d > m) m = d
         d = $4 - u[k]; if (d < 0) d = -d; e = $5 - v[k]; if (e < 0) e = -e; if (d + e > pm) pm = d + e }
       END { printf "%d %.3e %.3e %d\n", n, m, pm, miss + 0 }' "$1" "$2"
}

# name faces edges vertices closed boundary_edges shared_edges seams smooth periodic_faces
for spec in "cube 6 12 8 1 0 12 0 0 0" "grid 6 17 12 0 10 7 0 1 0" "tee 4 13 10 0 8 5 0 1 0" \
            "torus 1 2 1 1 0 0 2 1 1" "torus_split 1 5 4 1 0 0 5 1 1"; do
  set -- $spec
  name=$1 nf=$2 ne=$3 nv=$4 closed=$5 nb=$6 n2=$7 nseam=$8 smooth=$9 nper=${10}
  for ext in step igs; do
    vol=""
    f="$T/$name.$ext" r="$T/$name.$ext.rep"
    what="$name.$ext"
    if ! build/occt_read --grid 7 --points "$f.pts" "$f" >"$r" 2>"$T/err"; then
      bad "$what: occt_read failed: $(head -c 300 "$T/err")"; continue
    fi
    e=""
    if ! build/occt_read --no-heal "$f" >"$r.raw" 2>/dev/null || [ "$(val valid "$r.raw")" != 1 ]; then
      e="$e not-valid-without-healing"
    fi
    [ "$(val file_loops "$r")" = "$nf" ] || e="$e file_loops=$(val file_loops "$r")"
    [ "$(val file_loops_broken "$r")" = 0 ] || e="$e file_loops_broken=$(val file_loops_broken "$r")"
    [ "$(val file_edges_used_both_ways "$r")" = $((n2 + nseam)) ] || e="$e file_edges_used_both_ways=$(val file_edges_used_both_ways "$r")"
    [ "$(val file_edges_used_once "$r")" = "$nb" ] || e="$e file_edges_used_once=$(val file_edges_used_once "$r")"
    [ "$(val file_edges_misused "$r")" = 0 ] || e="$e file_edges_misused=$(val file_edges_misused "$r")"
    if [ "$closed" = 1 ]; then
      vol=$(val volume "$r")
      awk -v v="$vol" -v c="$name" 'BEGIN { exit !(v > 0 && (c != "cube" || (v - 1.225 < 1e-12 && 1.225 - v < 1e-12))) }' || e="$e volume=$vol"
    fi
    [ "$(val reader_status "$r")" = done ] || e="$e reader_status=$(val reader_status "$r")"
    [ "$(val valid "$r")" = 1 ] || e="$e not-valid"
    [ "$(val shells "$r")" = 1 ] || e="$e shells=$(val shells "$r")"
    [ "$(val faces "$r")" = "$nf" ] || e="$e faces=$(val faces "$r")"
    [ "$(val edges "$r")" = "$ne" ] || e="$e edges=$(val edges "$r")"
    [ "$(val vertices "$r")" = "$nv" ] || e="$e vertices=$(val vertices "$r")"
    [ "$(val closed_shells "$r")" = "$closed" ] || e="$e closed_shells=$(val closed_shells "$r")"
    [ "$(val free_edges "$r")" = "$nb" ] || e="$e free_edges=$(val free_edges "$r")"
    [ "$(val edges_one_face "$r")" = "$nb" ] || e="$e edges_one_face=$(val edges_one_face "$r")"
    [ "$(val edges_two_faces "$r")" = "$n2" ] || e="$e edges_two_faces=$(val edges_two_faces "$r")"
    [ "$(val edges_seam "$r")" = "$nseam" ] || e="$e edges_seam=$(val edges_seam "$r")"
    [ "$(val edges_other "$r")" = 0 ] || e="$e edges_other=$(val edges_other "$r")"
    [ "$(val load_warnings "$r")" = 0 ] && [ "$(val load_fails "$r")" = 0 ] || e="$e load-checks"
    [ "$(val transfer_fails "$r")" = 0 ] || e="$e transfer_fails=$(val transfer_fails "$r")"
    [ "$(val transfer_warnings "$r")" = "$nper" ] || e="$e transfer_warnings=$(val transfer_warnings "$r")"
    if [ "$nper" -gt 0 ] && [ "$(grep -c -i periodic "$T/err")" != "$nper" ]; then e="$e unexpected-warning"; fi
    [ "$(val edge_pairs "$r")" = $((n2 + nseam)) ] || e="$e edge_pairs=$(val edge_pairs "$r")"
    [ "$(val normal_undefined "$r")" = 0 ] || e="$e normal_undefined=$(val normal_undefined "$r")"
    ang=$(val normal_angle_max "$r")
    if [ "$smooth" = 1 ] && ! awk -v a="$ang" 'BEGIN { exit !(a <= 1e-8) }'; then e="$e normal_angle_max=$ang"; fi
    set -- $(griddiff "$T/$name.ref" "$f.pts")
    npts=$1 dmax=$2 pmax=$3 miss=$4
    [ "$npts" = $((nf * 49)) ] && [ "$miss" = 0 ] || e="$e grid-points=$npts/missing=$miss"
    awk -v d="$dmax" -v p="$pmax" 'BEGIN { exit !(d <= 1e-12 && p == 0) }' || e="$e surface-diff=$dmax param-diff=$pmax"
    if [ -z "$e" ]; then
      ok "$what: valid, $nf faces, $ne edges, $nv vertices, closed=$closed${vol:+ volume $vol}, surface diff $dmax, max normal angle $ang, edge tol $(val max_edge_tolerance "$r")"
    else
      bad "$what:$e"
    fi
    if [ "$name" = torus ]; then # one periodic face, knots = the intervals, = OpenCASCADE's own surface
      line=$(grep '^face 0:' "$r")
      uk=$(echo "$line" | sed 's/.* uknots [0-9]* \([^a-z]*\) umults.*/\1/')
      vk=$(echo "$line" | sed 's/.* vknots [0-9]* \([^a-z]*\) vmults.*/\1/')
      want_u=$(sed -n 's/^uknots [0-9]* //p' "$T/torus_build.txt")
      want_v=$(sed -n 's/^vknots [0-9]* //p' "$T/torus_build.txt")
      knots_ok=$(awk -v a="$uk $vk" -v b="$want_u $want_v" 'BEGIN { n = split(a, x, " "); m = split(b, y, " ")
        if (n != m) { print 0; exit } for (i = 1; i <= n; i++) { d = x[i] - y[i]; if (d < 0) d = -d; if (d > 1e-15 * 10) { print 0; exit } } print 1 }')
      case "$line" in
        *"type Geom_BSplineSurface"*"upoles 8 vpoles 6 uperiodic 1 vperiodic 1"*) per=1 ;;
        *) per=0 ;;
      esac
      build/occt_read --build "$T/torus_build.txt" --grid 7 --points "$T/built.pts" >/dev/null 2>"$T/err" || per=0
      set -- $(griddiff "$T/built.pts" "$f.pts")
      if [ "$per" = 1 ] && [ "$knots_ok" = 1 ] && awk -v d="$2" -v p="$3" 'BEGIN { exit !(d <= 1e-12 && p == 0) }'; then
        ok "$what: one periodic face, knots = intervals, = OpenCASCADE's surface from poles+knots (diff $2)"
      else
        bad "$what: periodic=$per knots_ok=$knots_ok diff=$2 ($line)"
      fi
    fi
  done
done
echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
