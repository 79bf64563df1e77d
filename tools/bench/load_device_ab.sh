#!/bin/bash
# Loader A/B from the page cache on the device machine (issue 33: binary
# PLY/LAS/PCD at >= 4 GB/s on its 16 cores). BEFORE and AFTER are
# rthdist-load-bench binaries (target rthdist_load_bench, both with
# --threads) built here and carried; the inputs are generated there with
# numpy (load_files.py): a 300M-point float32 PLY (3.6 GB, the torus's
# size per set) and 100M-point double PLY, LAS 1.4 format 6 and binary PCD.
#
#   bash tools/bench/load_device_ab.sh BEFORE AFTER [OUT]
#
# Prints load_ab.py's Markdown rows per thread count (0: every hardware
# thread) and writes each JSON to OUT (default $OUT, else /tmp).
set -euo pipefail
before=$1
after=$2
out=${3:-${OUT:-/tmp}}
dir=${RTHDIST_LOAD_DIR:-/tmp/rthdist-load}
here=$(dirname "$0")
nproc
python3 "$here/load_files.py" --out "$dir" --points 300000000 --only ply_float
python3 "$here/load_files.py" --out "$dir" --points 100000000 --only ply_double,las14_f6,pcd_binary
header="| file | MB | before MB/s | after MB/s | best after MB/s | speedup | before CPU s | after CPU s | load |"
ab() {  # threads, files...
    local threads=$1
    shift
    echo "threads $threads (0: all)"
    echo "$header"
    python3 "$here/load_ab.py" --before "$before" --after "$after" --dir "$dir" --rounds 3 --runs 3 \
        --warmup 1 --threads "$threads" --out "$out/load_ab_t$threads.json" "$@"
}
ab 0 ply_float.ply ply_double.ply las14_f6.las pcd_binary.pcd
ab 4 ply_float.ply
ab 1 ply_float.ply
