#!/usr/bin/env bash
# Session 23, call 5 (one H200, 16 cores): surface to surface on the CPU
# backend by thread count against CGAL's bounded-error Hausdorff (one
# thread, its only mode), the rows bunny-res3|res4 and bunny-res2|res3 at
# 1e-4 of the diagonal (the surface_peers.py tolerance): where the threads
# go on a row of a few thousand queries in ~20 rounds.
source tools/bench/device_prelude.sh
B=.devs
S=$B/s2s
nproc
for pair in "bunny-res3 bunny-res4 2.502460501821433e-05" "bunny-res2 bunny-res3 2.502460501821433e-05"; do
  set -- $pair
  for r in 1 2 3; do
    for t in 1 2 4 8 16; do
      $B/rthdist $S/$1.ply $S/$2.ply --surface both --tolerance $3 --backend cpu --threads $t --json --quiet > $RES/$1-$t-$r.json
      python3 -c "import json; d=json.load(open('$RES/$1-$t-$r.json')); t=d['timings_ms']; print('$1|$2 threads $t round $r', 'total %.1f build %.1f search %.1f' % (t['total'], t['build'], t['search']), d['bounds'])"
    done
    $B/surface-cgal surfaces $S/$1.ply $S/$2.ply --tolerance $3 > $RES/$1-cgal-$r.json 2>&1
    python3 -c "import json; d=json.load(open('$RES/$1-cgal-$r.json')); print('$1|$2 cgal round $r', d['median_ms'], d['lower'], d['upper'])" 2>/dev/null || tail -2 $RES/$1-cgal-$r.json
  done
done
