#!/usr/bin/env bash
# The certificate's cost on the rows of docs/bench/gpu.md (issue 32): the
# builds before and after it, alternated in one session on one machine
# (rthdist-bench, median of 7 runs after 3 warm-ups, no CPU check).
#   tools/bench/gpu_certificate_ab.sh BUNDLE OUTDIR [ROUNDS]
# BUNDLE holds rthdist-bench (after), rthdist-bench-before and
# data/dragon_vrip{,_res2}.ply.gz; with SCALE="case ..." (tools/bench/scale_cases.sh)
# also rthdist-scale-gen, and those cases join the rows (3 runs after 1 warm-up). Writes OUTDIR/ab.jsonl (one line per round,
# build and case: the bench's JSON with "build" and "round") and prints a table.
set -uo pipefail
B=$(cd "${1:?bundle dir}" && pwd); OUT=${2:?out dir}; ROUNDS=${3:-2}; D=$B/data; S=/tmp/rthdist-samples
mkdir -p "$OUT" "$S"
here=$(cd "$(dirname "$0")" && pwd)
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > "$OUT/machine.txt" 2>&1
# The rows of docs/bench/gpu.md: their inputs and `cases`.
source "$here/gpu_rows.sh"
source "$here/scale_cases.sh"
for c in ${SCALE:-}; do
  scale_specs "$c" || exit 2
  scale_files "$B" "$S"
  cases+=("$c ${files[0]} ${files[1]} 3 1")
done
for round in $(seq 1 "$ROUNDS"); do
  for build in before after; do
    bin=$B/rthdist-bench; [ $build = before ] && bin=$B/rthdist-bench-before
    for c in "${cases[@]}"; do
      set -- $c
      "$bin" "$2" "$3" --name "$1" --backend rt-pipeline --runs "${4:-7}" --warmup "${5:-3}" --no-verify 2>> "$OUT/errors.txt" |
        python3 -c "import json,sys; d=json.load(sys.stdin); d['build']='$build'; d['round']=$round; print(json.dumps(d))" \
        >> "$OUT/ab.jsonl"
    done
  done
done
python3 - "$OUT/ab.jsonl" <<'PY' | tee "$OUT/table.txt"
import json, sys, statistics
rows = [json.loads(l) for l in open(sys.argv[1])]
names = []
for r in rows:
    if r["case"] not in names: names.append(r["case"])
print("case | before gpu ms | after gpu ms | certificate gpu ms | share of after | before total ms | after total ms | H equal")
for n in names:
    def med(build, key):
        return statistics.median(r["median_ms"].get(key, 0.0) for r in rows if r["case"] == n and r["build"] == build)
    hb = {r["hausdorff"] for r in rows if r["case"] == n and r["build"] == "before"}
    ha = {r["hausdorff"] for r in rows if r["case"] == n and r["build"] == "after"}
    ga, gc = med("after", "gpu_sum"), med("after", "gpu_certificate")
    print(f"{n} | {med('before', 'gpu_sum'):.3f} | {ga:.3f} | {gc:.3f} | {100 * gc / ga if ga else 0:.2f}% | "
          f"{med('before', 'total'):.2f} | {med('after', 'total'):.2f} | {hb == ha} {sorted(ha)}")
PY
