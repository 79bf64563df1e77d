#!/usr/bin/env bash
# Records what rthdist, rthdist-masks and rthdist-bench print for a broad set
# of invocations (every flag, usage errors, bad input, output files, JSON),
# so that two builds can be compared byte for byte, e.g. before and after a
# change to the command-line front ends (issue 16: the CLI11/nlohmann swap).
#
#   tools/cli/compare_outputs.sh BUILD_DIR RECORD_DIR   # one record per build
#   diff -r RECORD_DIR_1 RECORD_DIR_2                    # empty = identical
#
# Each case runs in the same scratch directory (/tmp/rthdist-compare/run) on
# the same fixtures (/tmp/rthdist-compare/fixtures), so paths in messages are
# equal between builds. Per case the record holds the command, the exit code,
# stdout and stderr, and the size and SHA-256 of every file it wrote. Timing
# values are masked (they differ run to run): the summary's "time (ms)" line,
# the "timings_ms" objects, the masks CSV's total_ms and text "ms", and the
# bench's *_ms, median_ms, wall_ms_all and max_rss_kb. So are the counters
# that depend on thread and GPU scheduling (culled, surviving, candidate
# pairs: they vary between two runs of one build). GPU cases use
# --backend ray-query / rt-pipeline (lavapipe is enough); RTHDIST_COMPARE_GPU=0
# skips them.
set -uo pipefail

build=$(cd "$1" && pwd)
record=$2
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
shared=$(cd "$root/../shared/data" 2>/dev/null && pwd || echo /nonexistent)
scratch=/tmp/rthdist-compare
fx=$scratch/fixtures
run=$scratch/run
gpu=${RTHDIST_COMPARE_GPU:-1}

rm -rf "$record" "$fx"
mkdir -p "$record" "$fx"
record=$(cd "$record" && pwd)  # the cases run in $run

# ---- fixtures ---------------------------------------------------------------
printf '0 0 0\n1 0 0\n3 0 0\n' >"$fx/a.xyz"
printf '0 0 0\n0 2 0\n' >"$fx/b.xyz"
printf '0 0 0\n' >"$fx/single.xyz"
printf '0.5 0.25 0.125\n1.5 -2 3e-3\n-4 5.5 6\n' >"$fx/c.xyz"
printf '1e-40 0 0\n' >"$fx/tiny.xyz"
printf '0 0 0\n' >"$fx/zero.xyz"
printf '0.1 0.2 0.3\n123456.789 1 2\n' >"$fx/decimals.xyz"
printf '0 0 nan\n' >"$fx/nan.xyz"
printf '' >"$fx/empty.xyz"
printf 'ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nend_header\n1 2 3\n' >"$fx/bad.ply"
printf 'not a laz' >"$fx/scan.laz"
W=$fx/we\"ird\\\ name$'\t\001'x.xyz  # quote, backslash, tab, control character
X=$fx/b$'\377\376'.xyz                  # not UTF-8
U=$fx/donn$'\303\251'es$'\177'.xyz      # UTF-8 and DEL
printf '0 0 0\n1 0 0\n' >"$W"
printf '0 0 0\n' >"$X"
printf '0 0 0\n2 0 0\n' >"$U"
printf '0 0 0\n1 1 1\n' >"$fx/-dash.xyz"
printf '0 0 0\n1 1 1\n' >"$fx/[br,ack].xyz"
mkdir -p "$fx/dir.xyz"
# NumPy masks (format 1.0, little-endian int16, C order) without numpy.
python3 - "$fx" <<'EOF'
import struct, sys
def npy(path, shape, voxels, fortran=False):
    header = "{'descr': '<i2', 'fortran_order': %s, 'shape': (%d, %d, %d), }" % (
        "True" if fortran else "False", *shape)
    header += " " * (63 - (10 + len(header)) % 64) + "\n"
    data = bytearray(2 * shape[0] * shape[1] * shape[2])
    for (i, j, k), v in voxels.items():
        n = ((k * shape[1] + j) * shape[0] + i) if fortran else ((i * shape[1] + j) * shape[2] + k)
        struct.pack_into("<h", data, 2 * n, v)
    with open(path, "wb") as f:
        f.write(b"\x93NUMPY\x01\x00" + struct.pack("<H", len(header)) + header.encode() + data)
d = sys.argv[1]
a = {(i, j, k): 1 for i in range(2, 7) for j in range(2, 7) for k in range(2, 6)}
a.update({(i, j, k): 2 for i in range(9, 11) for j in range(3, 5) for k in range(1, 3)})
b = {(i, j, k): 1 for i in range(3, 8) for j in range(2, 6) for k in range(2, 7)}
b.update({(i, j, k): 3 for i in range(0, 2) for j in range(0, 2) for k in range(0, 2)})
npy(d + "/a.npy", (12, 10, 8), a)
npy(d + "/b.npy", (12, 10, 8), b)
npy(d + "/bf.npy", (12, 10, 8), b, fortran=True)
npy(d + "/empty.npy", (12, 10, 8), {})
npy(d + "/other.npy", (6, 10, 8), {(1, 1, 1): 1})
EOF
A=$fx/a.xyz B=$fx/b.xyz S=$root/data/bunny.ply S2=$root/data/bunny_res2.ply
MA=$fx/a.npy MB=$fx/b.npy

# ---- runner -----------------------------------------------------------------
n=0
mask() {
    perl -0pe '
        s/("timings_ms": \{).*?(\n *\})/$1 MASKED$2/gs;
        s/^time \(ms\).*$/time (ms) MASKED/mg;
        s/("(?:load_ms|setup_ms|cpu_ms|max_rss_kb)":)[-0-9.e+]+/$1MASKED/g;
        s/("median_ms":)\{[^}]*\}/$1MASKED/g;
        s/("wall_ms_all":)\[[^]]*\]/$1MASKED/g;
        s/, [0-9.]+ ms\)$/, MASKED ms)/mg;
        s/,[0-9.e+-]+$/,MASKED/mg if /^label,convention/;
        s/\b(culled|surviving|candidate pairs) [0-9]+/$1 N/g;
        s/("(?:culled_by_neighbourhood|surviving_queries|candidate_pairs|tail_scanned|surviving|pairs)": ?)[0-9]+/$1N/g;
    '
}
case_() {  # case_ BINARY ARGS...: runs one invocation and records it
    local bin=$1
    shift
    n=$((n + 1))
    local dir
    dir=$record/$(printf '%03d' "$n")
    mkdir -p "$dir"
    rm -rf "$run" && mkdir -p "$run"
    printf '%s' "$bin" >"$dir/cmd"
    printf ' %q' "$@" >>"$dir/cmd"
    (cd "$run" && "$build/$bin" "$@" >"$dir/stdout.raw" 2>"$dir/stderr.raw" </dev/null)
    echo $? >"$dir/exit"
    mask <"$dir/stdout.raw" >"$dir/stdout"
    mask <"$dir/stderr.raw" >"$dir/stderr"
    rm -f "$dir/stdout.raw" "$dir/stderr.raw"
    (cd "$run" && find . -type f -printf '%P %s\n' | sort | while read -r f s; do
        echo "$f $s $(sha256sum <"$f" | cut -c1-64)"
    done) >"$dir/files"
}
r() { case_ rthdist "$@"; }
m() { case_ rthdist-masks "$@"; }
bench() { case_ rthdist-bench "$@"; }

# ---- rthdist: information ---------------------------------------------------
r --help
r -h
r --version
r --help "$A"
r --version --json
r --list-devices
r --list-devices --json
r --help=1
r --version= "$A" "$B"

# ---- rthdist: usage errors --------------------------------------------------
r
r "$A"
r "$A" "$B" "$B"
r --frobnicate "$A" "$B"
r --frobnicate=3 "$A" "$B"
r -x "$A" "$B"
r -xyz "$A" "$B"
r -5 "$A" "$B"
r ---x "$A" "$B"
r --=x "$A" "$B"
r -=x "$A" "$B"
r -h=1 "$A" "$B"
r -hx "$A" "$B"
r --JSON "$A" "$B"
r --jso "$A" "$B"
r --json=yes "$A" "$B"
r --json= "$A" "$B"
r --json=true "$A" "$B"
r --directed=0 "$A" "$B"
r --verify=1 --json "$A" "$B"
r --list-devices "$A"
r --list-devices "$A" "$B"
r --list-devices=1
r --backend gpu "$A" "$B"
r --backend "" "$A" "$B"
r --backend= "$A" "$B"
r --backend=RAY-QUERY "$A" "$B"
r "$A" "$B" --backend
r "$A" "$B" --bits
r "$A" "$B" --threads
r "$A" "$B" --device
r "$A" "$B" --radius-growth
r "$A" "$B" --las-classes
r "$A" "$B" --percentile
r "$A" "$B" --histogram-bins
r "$A" "$B" --render
r "$A" "$B" --out-ply
r "$A" "$B" --out-csv
r "$A" "$B" --png
r "$A" "$B" --histogram-png
r "$A" "$B" --range
r "$A" "$B" --range 1
r --range=1 2 "$A" "$B"
r --range= "$A" "$B"
for v in abc -1 1.5 "" 7x 99999999999999999999 9 30 +1 " 1" 0x3 1e0; do r --bits "$v" "$A" "$B"; done
r --bits=seven "$A" "$B"
r --bits= "$A" "$B"
r --bits --json "$A" "$B"
r --bits -- "$A" "$B"
for v in x -2 1025 65536 -0; do r --threads "$v" "$A" "$B"; done
for v in -1 abc 1024; do r --device "$v" "$A" "$B"; done
for v in 0.5 nan inf 1.001 1.09 16.5 1e300 -2 0x2 1,5 " 2"; do r --radius-growth "$v" "$A" "$B"; done
r --radius-growth=1 "$A" "$B"
for v in 0 10001 -3 5.5; do r --histogram-bins "$v" "$A" "$B"; done
for v in 100.5 nan -1 -0.0 inf x; do r --percentile "$v" "$A" "$B"; done
r --range -1 2 "$A" "$B"
r --range 0 1e999 "$A" "$B"
r --range 1 1 "$A" "$B"
r --range 2 1 "$A" "$B"
r --range x 1 "$A" "$B"
r --range 0 --json "$A" "$B"
r --render opengl "$A" "$B"
r --render= "$A" "$B"
r --out-ply "" "$A" "$B"
r --out-ply= "$A" "$B"
r --png= "$A" "$B"
r --out-csv= "$A" "$B"
r --histogram-png= "$A" "$B"
for v in x 256 "2,,6" "" "2," ",2" -1 "2, 6" 2.0; do r --las-classes "$v" "$A" "$B"; done
r --las-classes 2 "$A" "$B"
r --las-classes=2 "$A" "$fx/scan.LAS.gz"
r --las-classes 2,6 "$fx/none.las" "$B"
# several errors: the first in argv order is reported
r --bits x --frobnicate "$A" "$B"
r --frobnicate --bits x "$A" "$B"
r --bits 9 --threads x "$A" "$B"
r --json=1 --bits x "$A" "$B"
r --bits x --json=1 "$A" "$B"
r -h --bits x
r --bits x -h
r --help --frobnicate
r --frobnicate --help
r --help "$A" "$B" "$B"
r --version --bits 99
r -x --range 1
r --range 1 2 3 "$A"
r --frobnicate -- --bits x
r --bits 3 --bits x "$A" "$B"
r --bits x --bits 3 "$A" "$B"
r "$A" -x "$B" --frobnicate
r "$A" "$B" -- --frobnicate
r --range 1 -- "$A" "$B"
r --range 0 --json "$A" "$B"
r --range -1 -2 "$A" "$B"
r -- -- "$A"
r --json -- --json "$B"
r --help -- -x
r "- x" "$A" "$B"
r -!x "$A" "$B"
r --bits:3 "$A" "$B"
r --json --json --backend cpu --backend=cpu "$A" "$B"
r --out-ply p --out-ply "" "$A" "$B"
r --percentile 5 --percentile x "$A" "$B"
r --backend cpu "$A" "$B" --
r --backend cpu "$A" "$B" -- -
r -- --help
r --version -- a b c

# ---- rthdist: bad input -------------------------------------------------------
r --backend cpu "$fx/missing.xyz" "$B"
r --backend cpu "$A" "$fx/missing.ply"
r --backend cpu "$fx/empty.xyz" "$B"
r --backend cpu "$fx/nan.xyz" "$B"
r --backend cpu "$fx/bad.ply" "$B"
r --backend cpu "$fx/scan.laz" "$B"
r --backend cpu "$fx/dir.xyz" "$B"
r --backend cpu "$A" "$fx/unknown.foo"

# ---- rthdist: runs on the cpu backend ------------------------------------------
r --backend cpu "$A" "$B"
r --backend=cpu --json "$A" "$B"
r --backend cpu --json --directed "$A" "$B"
r --backend cpu --directed "$A" "$B"
r --backend cpu --json --verify "$A" "$B"
r --backend cpu --verify "$A" "$B"
r --backend cpu --json "$fx/c.xyz" "$A"
r --backend cpu --json "$fx/decimals.xyz" "$fx/c.xyz"
r --backend cpu --json --verify "$fx/tiny.xyz" "$fx/zero.xyz"
r --backend cpu --json "$W" "$X"
r --backend cpu "$W" "$X"
r --backend cpu --json "$U" "$B"
r --backend cpu --json "$fx/[br,ack].xyz" "$B"
r --backend cpu --json -- "$fx/-dash.xyz" "$B"
r --backend cpu --json -- "$A" -- 
r --backend cpu --json -- "$A" "$B"
r --backend cpu --json "$A" -
r --backend cpu --json --threads 1 "$S" "$S2"
r --backend cpu --threads=0 --bits 5 --radius-growth 1.1 --device 0 "$S" "$S2"
r --backend cpu --json --verify --directed "$S2" "$S"
r --backend cpu --json --quiet --per-point "$A" "$B"
r --backend cpu --per-point "$A" "$B"
r --backend cpu --per-point --directed "$A" "$B"
r --backend cpu --json --per-point --directed "$A" "$B"
r --backend cpu --json --percentile 50 --percentile 100 --histogram-bins 3 "$A" "$B"
r --backend cpu --percentile 12.5 --percentile 99.9 --histogram-bins 7 --range 0 0.001 "$S" "$S2"
r --backend cpu --json --percentile 0 --range 0.5 2.5 --histogram-bins 4 "$A" "$B"
r --backend cpu --json --range 0 1e300 "$A" "$B"
r --backend cpu --out-ply p --out-csv c --png pic.png --render software --histogram-png h.png "$A" "$B"
r --backend cpu --json --out-ply=p --out-csv=c "$S" "$S2"
r --backend cpu --png pic.png --render=software "$S" "$S2"
r --backend cpu --out-csv /nonexistent/dir/c "$A" "$B"
r --backend cpu --out-ply no/such/dir/p "$A" "$B"
r --backend cpu --histogram-png /dev/full "$A" "$B"
if [ -d "$shared/lidar" ]; then
    r --backend cpu --json --verify "$shared/lidar/FSite8_red2-utm.ply" "$shared/lidar/FSite8_red1-utm.ply"
    r --backend cpu "$shared/lidar/FSite8_red2-utm.ply" "$shared/lidar/FSite8_red1-utm.ply"
    r --backend cpu --json "$shared/stanford/bunny/bun_zipper_res4.ply" "$shared/gltf/bun_zipper.glb"
    r --backend cpu --json --per-point "$shared/stanford/dragon/dragon_vrip_res4.ply.gz" "$shared/stanford/bunny/bun_zipper_res4.ply"
fi

# ---- rthdist: GPU backends (lavapipe is enough) ---------------------------------
if [ "$gpu" = 1 ]; then
    r --backend ray-query --json "$A" "$B"
    r --backend rt-pipeline --json --directed "$A" "$B"
    r --backend ray-query --verify "$S2" "$fx/c.xyz"
    r --backend ray-query --json --verify --bits 4 "$S" "$S2"
    r --backend rt-pipeline --verify --radius-growth 1.1 "$S" "$S2"
    r --backend ray-query --json --validation "$A" "$B"
    r --backend ray-query --device 1023 "$A" "$B"
    r --backend ray-query --per-point --png pic.png "$A" "$B"
    r --device 0 --json "$A" "$B"
    r "$S" "$S2"
fi

# ---- rthdist-masks --------------------------------------------------------------
m --help
m -h
m --version
m --help=x
m
m "$MA"
m "$MA" "$MB" "$MB"
m --frobnicate "$MA" "$MB"
m -x "$MA" "$MB"
m -- "$MA" "$MB"
m --=x "$MA" "$MB"
m --json=x "$MA" "$MB"
m --csv --json "$MA" "$MB"
m --label 2 --labels all "$MA" "$MB"
m --spacing 1,2,3 --affine 1,0,0,0,0,1,0,0,0,0,1,0 "$MA" "$MB"
for o in --label --labels --convention --percentile --connectivity --tolerance --spacing --affine --backend --device --threads; do
    m "$MA" "$MB" "$o"
done
for v in x 99999999999 -99999999999 1.5 ""; do m --label "$v" "$MA" "$MB"; done
m --label= "$MA" "$MB"
m --labels some "$MA" "$MB"
m --convention scipy "$MA" "$MB"
for v in x 101 -1; do m --percentile "$v" "$MA" "$MB"; done
for v in 7 x 0; do m --connectivity "$v" "$MA" "$MB"; done
for v in -1 x; do m --tolerance "$v" "$MA" "$MB"; done
for v in 1,2 1,0,1 1,2,x 1,2,3,4 ""; do m --spacing "$v" "$MA" "$MB"; done
for v in 1,2,3 1,0,0,0,0,1,0,0,0,0,0,0 1,0,0,0,0,1,0,0,0,0,1,x; do m --affine "$v" "$MA" "$MB"; done
m --backend gpu "$MA" "$MB"
for v in -1 1024 x; do m --device "$v" "$MA" "$MB"; done
for v in -1 1025 x; do m --threads "$v" "$MA" "$MB"; done
m --label x --frobnicate "$MA" "$MB"
m --frobnicate --label x "$MA" "$MB"
m --label 1 -- "$MA" "$MB"
m "$MA" "$MB" --
m -h=1 "$MA" "$MB"
m --version=1 --frobnicate
m --labels=all --label=1 "$MA" "$MB"
m --convention all --convention monai --backend cpu "$MA" "$MB"
m --json=1 --csv=0 "$MA" "$MB"
m - "$MA"
m "$fx/missing.npy" "$MB"
m "$MA" "$fx/other.npy"
m "$fx/a.xyz" "$MB"
m --backend cpu "$MA" "$MB"
m --backend cpu --json "$MA" "$MB"
m --backend cpu --csv "$MA" "$MB"
m --backend=cpu --convention all --percentile 50 --percentile 95 --connectivity 26 "$MA" "$MB"
m --backend cpu --json --convention all --labels all "$MA" "$MB"
m --backend cpu --csv --convention monai --convention itk --labels all "$MA" "$MB"
m --backend cpu --label 2 --tolerance 2.5 --spacing 0.5,1,2 "$MA" "$MB"
m --backend cpu --json --label 3 "$MA" "$MB"
m --backend cpu --json "$MA" "$fx/empty.npy"
m --backend cpu --convention all "$fx/empty.npy" "$fx/empty.npy"
m --backend cpu --json --affine 0.5,0.1,0,10,0,1,0,-5,0,0,2,3 "$MA" "$fx/bf.npy"
m --backend cpu --threads 1 --json "$MA" "$fx/bf.npy"
if [ -d "$shared/nifti" ]; then
    m --backend cpu --label 5 "$shared/nifti/aal.nii.gz" "$shared/nifti/aal.nii.gz"
    m --backend cpu --json --label 2001 --convention monai "$shared/nifti/aal.nii.gz" "$shared/nifti/aal.nii.gz"
    m --backend cpu "$shared/nifti/aal.nii.gz" "$shared/nifti/JHU-WhiteMatter-labels-1mm.nii.gz"
fi
if [ "$gpu" = 1 ]; then
    m --backend ray-query --json "$MA" "$MB"
    m --backend rt-pipeline --csv --convention all "$MA" "$MB"
fi

# ---- rthdist-bench ----------------------------------------------------------------
bench
bench "$A"
bench --frobnicate "$A" "$B"
bench - "$A" "$B"
bench -- "$A" "$B"
bench --runs=1 "$A" "$B"
bench --runs 0 "$A" "$B"
bench --runs x "$A" "$B"
bench --warmup -1 "$A" "$B"
bench --budget 0 "$A" "$B"
bench --backend gpu "$A" "$B"
bench "$A" "$B" --runs
bench "$A" "$B" --name
bench --no-verify=1 "$A" "$B"
bench --runs 2 --name "$A" "$B"
bench --budget -1 "$A" "$B"
bench -x "$A" "$B"
bench --backend cpu --runs 1 --warmup 0 "$fx/missing.xyz" "$B"
bench --backend cpu --runs 1 --warmup 0 "$A" "$B"
bench --backend cpu --runs 2 --warmup 1 --name tiny --no-verify --per-point --growth 3 --bits 4 "$A" "$B"
bench --backend cpu --runs 1 --warmup 0 --translate 0.5 --budget 10 "$S" "$S2"
if [ "$gpu" = 1 ]; then
    bench --backend ray-query --runs 1 --warmup 0 "$S" "$S2"
fi
echo "compare_outputs: $n invocations recorded in $record"
