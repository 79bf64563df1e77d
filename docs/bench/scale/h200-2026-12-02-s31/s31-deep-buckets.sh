#!/usr/bin/env bash
# Session 31 (one H200 machine, 16 cores): the CPU order's deep buckets (a
# second most-significant-digit pass for buckets of 2^20 entries and more,
# cpu/key_sort.cpp) against the build before it: cpu-index-bench --runs 3 on
# crowded-20M and the torus 300M x 400M (the scale suite's seeds), before
# and after alternated in 2 rounds; the hashes of everything the builds
# produce must match.
BUNDLE=.dev31
source tools/bench/device_prelude.sh
B=/tmp/b; mkdir -p $B; for f in gen cib-before cib-after; do xz -dc .dev31/$f.xz > $B/$f; chmod +x $B/$f; done
mv $B/gen $B/rthdist-scale-gen
source tools/bench/scale_cases.sh
S=/tmp/scale; mkdir -p $S
for c in crowded-20M torus-300x400; do
  scale_specs $c; scale_files $B $S; cat "${files[@]}" > /dev/null
  for r in 1 2; do
    for v in cib-before cib-after; do
      $B/$v "${files[@]}" --runs 3 > $RES/$c.$v.$r.json 2> /dev/null
      python3 -c "import json,sys; j=json.load(open(sys.argv[1])); a=j['set_a']; b=j['set_b']; print(sys.argv[2], sys.argv[3], 'order A', a['order_all'], 'B', b['order_all'], 'index A', a['index_all'], 'B', b['index_all'], 'hash', a['hash'], b['hash'])" $RES/$c.$v.$r.json $c $v
    done
  done
  rm -f "${files[@]}"
done
