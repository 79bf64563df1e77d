W=/tmp/rthdist-surface-work
for round in 1 2 3; do
for row in "dragon-res4.ply dragon.ply" "bunny-res4.ply bunny.ply" "armadillo-dec.ply armadillo.ply"; do
 set -- $row
 for b in /tmp/sb-before /work/main/build/rthdist-surface-bench; do
  $b $W/$1 $W/$2 --backend cpu --runs 15 --warmup 2 --no-verify 2>/dev/null > /tmp/keptab.json
  python3 -c "
import json;d=json.load(open('/tmp/keptab.json'));k=d['kept_median_ms'];print('$1>$2', '$b'[-6:], round(k['total'],3), round(k.get('build',0),3), round(k.get('search',0),3), d['hausdorff'], d['query'], d['triangle'], d['counters']['tail_tree_reused'])"
 done
done
done
