#!/usr/bin/env bash
# Session 31 (one H200 machine, 16 cores): the CPU backend's index build at
# the torus 300M x 400M (the scale suite's seeds) by stage, cold and warm:
# cpu-index-bench --runs 3 (the first run in fresh memory, the next two
# reusing the kept blocks), after a read of the files into the page cache.
BUNDLE=.dev31
source tools/bench/device_prelude.sh
B=/tmp/b; mkdir -p $B; for f in gen cib; do xz -dc .dev31/$f.xz > $B/$f; chmod +x $B/$f; done
mv $B/gen $B/rthdist-scale-gen
source tools/bench/scale_cases.sh
S=/tmp/scale; mkdir -p $S
scale_specs torus-300x400; scale_files $B $S; cat "${files[@]}" > /dev/null
$B/cib "${files[@]}" --runs 3 > $RES/torus-300x400.cib.json 2> $RES/torus-300x400.cib.err
python3 -c "import json; j=json.load(open('$RES/torus-300x400.cib.json')); print({k: v for k, v in j.items() if k != 'runs'})"
grep -i "AnonHuge" /proc/meminfo; cat /sys/kernel/mm/transparent_hugepage/enabled
