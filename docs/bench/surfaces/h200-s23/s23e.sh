#!/usr/bin/env bash
# Session 23, call 6 (one H200, 16 cores): surface to surface on the CPU
# backend, the batches' chunks fixed at 256 items (03c13cb, "fixed") against
# 16 to 256 items, about four a thread ("spread"), alternated, 5 rounds, 16
# threads (and 8), with CGAL's bounded-error Hausdorff beside.
source tools/bench/device_prelude.sh
B=.devs
S=$B/s2s
for pair in "bunny-res3 bunny-res4 2.502460501821433e-05" "bunny-res2 bunny-res3 2.502460501821433e-05"; do
  set -- $pair
  for r in 1 2 3 4 5; do
    for v in fixed spread; do
      bin=$B/rthdist; [ $v = spread ] && bin=$B/rthdist-s2s
      for t in 16 8; do
        $bin $S/$1.ply $S/$2.ply --surface both --tolerance $3 --backend cpu --threads $t --json --quiet > $RES/$1-$v-$t-$r.json
        python3 -c "import json; d=json.load(open('$RES/$1-$v-$t-$r.json')); t=d['timings_ms']; print('$1|$2 $v threads $t round $r', 'total %.2f build %.2f search %.2f' % (t['total'], t['build'], t['search']), d['bounds'])"
      done
    done
    $B/surface-cgal surfaces $S/$1.ply $S/$2.ply --tolerance $3 > $RES/$1-cgal-$r.json 2>&1
    python3 -c "import json; d=json.load(open('$RES/$1-cgal-$r.json')); print('$1|$2 cgal round $r', d['median_ms'])"
  done
done
