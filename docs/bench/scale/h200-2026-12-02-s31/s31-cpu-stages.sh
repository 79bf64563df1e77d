#!/usr/bin/env bash
# Session 31 (one H200 machine, 16 cores): where the CPU backend's time goes
# at the scale suite's sizes: the torus 300M x 400M (issue 32's inputs, the
# scale suite's seeds) on --backend cpu, one process after a warm-up read of
# the files, its JSON stages; and the crowded 20M pair the same way.
BUNDLE=.dev31  # (this script ran from docs/bench/scale/ as s31-cpu-stages.sh)
source tools/bench/device_prelude.sh
B=/tmp/b; mkdir -p $B; for f in rth-new gen; do xz -dc .dev31/$f.xz > $B/$f; chmod +x $B/$f; done
mv $B/gen $B/rthdist-scale-gen; mv $B/rth-new $B/rthdist
source tools/bench/scale_cases.sh
S=/tmp/scale; mkdir -p $S
for c in crowded-20M torus-300x400; do
  scale_specs $c; t0=$(date +%s%N); scale_files $B $S; echo "$c generated in $(( ($(date +%s%N) - t0) / 1000000 )) ms"
  cat "${files[@]}" > /dev/null
  /usr/bin/time -v $B/rthdist --json --quiet --backend cpu "${files[@]}" > $RES/$c.cpu.json 2> $RES/$c.cpu.err
  python3 -c "import json,sys; j=json.load(open(sys.argv[1])); print(sys.argv[2], j['hausdorff'], j['timings_ms'])" $RES/$c.cpu.json $c
  grep -E "Maximum resident|Elapsed" $RES/$c.cpu.err
  rm -f "${files[@]}"
done
