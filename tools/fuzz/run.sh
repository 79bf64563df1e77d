#!/usr/bin/env bash
# Builds the libFuzzer targets (tests/fuzz) with clang-14 in build-fuzz/ and
# runs each for RTHDIST_FUZZ_SECONDS (default 60) from the seed corpus in
# tests/fuzz/corpus/<target>/ with the dictionary tests/fuzz/dict/<target>.dict.
# Fails (exit 1) on any crash, sanitizer report, leak, timeout (-timeout=10)
# or memory blow-up (-rss_limit_mb=2048) in any target; the reproducer is
# left in build-fuzz/artifacts/<target>/.
#
#   tools/fuzz/run.sh                         # every target, 60 s each
#   RTHDIST_FUZZ_SECONDS=45 tools/fuzz/run.sh # 13 targets in about 5 min on 2 cores (CI: 10 s each)
#   tools/fuzz/run.sh ply gltf                # some targets
#
# Targets run side by side, RTHDIST_FUZZ_PARALLEL at a time (default: the
# number of cores): each fuzzer is one single-threaded process, so each still
# gets a whole core for its RTHDIST_FUZZ_SECONDS; their reports are printed
# in target order once all have finished.
#
# Environment: RTHDIST_FUZZ_SECONDS, RTHDIST_FUZZ_BUILD (build dir),
# RTHDIST_FUZZ_JOBS (build parallelism, default 2), RTHDIST_FUZZ_PARALLEL.
# New inputs are kept in build-fuzz/corpus/<target>/; the repo's seed corpus
# is only read.
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
seconds=${RTHDIST_FUZZ_SECONDS:-60}
build=${RTHDIST_FUZZ_BUILD:-$root/build-fuzz}
jobs=${RTHDIST_FUZZ_JOBS:-2}
parallel=${RTHDIST_FUZZ_PARALLEL:-$(nproc)}
all_targets=(ply xyz obj gltf glb stl off pcd las gz nifti npy cli_args)
targets=("$@")
[ ${#targets[@]} -eq 0 ] && targets=("${all_targets[@]}")

command -v clang++-14 >/dev/null || { echo "run.sh: clang++-14 not found (apt-get install clang-14 libclang-rt-14-dev)" >&2; exit 1; }

cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_C_COMPILER=clang-14 -DCMAKE_CXX_COMPILER=clang++-14 \
    -DRTHDIST_FUZZ=ON -DRTHDIST_BUILD_TESTS=OFF -DRTHDIST_BUILD_TOOLS=OFF >/dev/null
cmake --build "$build" -j"$jobs" --target "${targets[@]/#/fuzz_}"

# One target: its fuzzer's output in build-fuzz/fuzz_<target>.log, its exit
# status in build-fuzz/fuzz_<target>.status.
fuzz_one() {
    local t=$1 seeds=$root/tests/fuzz/corpus/$1 work=$build/corpus/$1 artifacts=$build/artifacts/$1 rc=0
    local dict=()
    mkdir -p "$work" "$artifacts"
    [ -f "$root/tests/fuzz/dict/$t.dict" ] && dict=(-dict="$root/tests/fuzz/dict/$t.dict")
    "$build/tests/fuzz/fuzz_$t" "${dict[@]}" -max_total_time="$seconds" -timeout=10 \
        -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix="$artifacts/" \
        "$work" "$seeds" >"$build/fuzz_$t.log" 2>&1 || rc=$?
    echo "$rc" >"$build/fuzz_$t.status"
}

echo "== ${#targets[@]} targets, ${seconds}s each, $parallel at a time"
for t in "${targets[@]}"; do
    rm -f "$build/fuzz_$t.status"
    while [ "$(jobs -rp | wc -l)" -ge "$parallel" ]; do wait -n || true; done
    fuzz_one "$t" &
done
wait

failed=()
for t in "${targets[@]}"; do
    echo "== fuzz_$t: ${seconds}s"
    if [ "$(cat "$build/fuzz_$t.status" 2>/dev/null)" != 0 ]; then
        failed+=("$t")
        tail -n 60 "$build/fuzz_$t.log"
    fi
    execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$build/fuzz_$t.log" | grep -o '[0-9]*$' || echo '?')
    echo "   executions: $execs, corpus: $(ls "$build/corpus/$t" | wc -l) files"
done

if [ ${#failed[@]} -ne 0 ]; then
    echo "run.sh: fuzzing found problems in: ${failed[*]} (reproducers in $build/artifacts/)" >&2
    exit 1
fi
echo "run.sh: ${#targets[@]} targets, no crash, leak or timeout"
