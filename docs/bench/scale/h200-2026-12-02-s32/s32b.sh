#!/usr/bin/env bash
# Session 32, call 2 (kind nvidia-h200: one H200, 16 cores): the CPU
# backend's order and index at the suite's sizes, the session's start
# (36a2629: cli-before, cib-before) against 2c2cce9 (the sort moving only
# the keyed values, the empty boxes written on every thread: cli-after2,
# cib-after). crowded-20M through the CLI, 3 rounds alternated; the torus
# 300M x 400M through cpu-index-bench (--runs 2) and the CLI, one process
# each, alternated.
BUNDLE=.dev32
source tools/bench/device_prelude.sh
B=/tmp/b; mkdir -p $B
for f in cli-before cli-after2 cib-before cib-after rthdist-scale-gen; do xz -dc .dev32/$f.xz > $B/$f; chmod +x $B/$f; done
source tools/bench/scale_cases.sh
S=/tmp/scale; mkdir -p $S
cli() {  # label binary case
  $B/$2 --json --quiet --backend cpu "${files[@]}" > $RES/$1.json 2> $RES/$1.err
  echo "$1 rc=$? $(python3 -c "
import json,sys; d=json.load(open(sys.argv[1])); t=d['timings_ms']
print('H', d['hausdorff'], {k: round(v) for k, v in t.items() if v})" $RES/$1.json 2>&1 | head -c 400)"
}
date +%T; scale_specs crowded-20M; scale_files $B $S; cat "${files[@]}" > /dev/null; date +%T
for r in 1 2 3; do cli crowded_before_$r cli-before; cli crowded_after_$r cli-after2; done
rm -f "${files[@]}"
scale_specs torus-300x400; scale_files $B $S; cat "${files[@]}" > /dev/null; date +%T
for v in before after; do
  timeout 150 $B/cib-$v "${files[@]}" --runs 2 > $RES/torus_cib_$v.json 2> $RES/torus_cib_$v.err
  echo "cib $v rc=$? $(python3 -c "
import json,sys; d=json.load(open(sys.argv[1])); print([(s, d[s]['hash'], [round(x) for x in d[s]['order_all']], [round(x) for x in d[s]['index_all']]) for s in ('set_a', 'set_b')])" $RES/torus_cib_$v.json 2>&1 | head -c 400)"; date +%T
done
cli torus_before cli-before; date +%T
cli torus_after cli-after2; date +%T
