#!/usr/bin/env bash
# Builds side by side on the rows of docs/bench/gpu.md (issue 32: the
# certificate's cost; issue 35: the house unchanged; issue 33: speed at
# scale): the builds alternated in one session on one machine
# (rthdist-bench, median of 7 runs after 3 warm-ups, no CPU check).
#   tools/bench/gpu_certificate_ab.sh BUNDLE OUTDIR [ROUNDS]
# BUNDLE holds rthdist-bench (build "after"), rthdist-bench-NAME for every
# other build NAME of BUILDS (default "before after") and
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
  for build in ${BUILDS:-before after}; do
    bin=$B/rthdist-bench; [ $build != after ] && bin=$B/rthdist-bench-$build
    for c in "${cases[@]}"; do
      set -- $c
      "$bin" "$2" "$3" --name "$1" --backend rt-pipeline --runs "${4:-7}" --warmup "${5:-3}" --no-verify 2>> "$OUT/errors.txt" |
        python3 -c "import json,sys; d=json.load(sys.stdin); d['build']='$build'; d['round']=$round; print(json.dumps(d))" \
        >> "$OUT/ab.jsonl"
    done
  done
done
python3 - "$OUT/ab.jsonl" ${BUILDS:-before after} <<'PY' | tee "$OUT/table.txt"
import json, sys, statistics
rows = [json.loads(l) for l in open(sys.argv[1])]
builds = sys.argv[2:]
names = []
for r in rows:
    if r["case"] not in names: names.append(r["case"])
def med(n, build, key):
    v = [r["median_ms"].get(key, 0.0) for r in rows if r["case"] == n and r["build"] == build]
    return statistics.median(v) if v else float("nan")
print("case | " + " | ".join("%s gpu ms" % b for b in builds) + " | " +
      " | ".join("%s total ms" % b for b in builds) + " | last / first (gpu) | H equal")
for n in names:
    hs = [{r["hausdorff"] for r in rows if r["case"] == n and r["build"] == b} for b in builds]
    g = [med(n, b, "gpu_sum") for b in builds]
    t = [med(n, b, "total") for b in builds]
    print(f"{n} | " + " | ".join(f"{x:.3f}" for x in g) + " | " + " | ".join(f"{x:.2f}" for x in t) +
          f" | {g[-1] / g[0] if g[0] else 0:.3f} | {all(h == hs[0] for h in hs)} {sorted(hs[-1])}")
PY
