#!/usr/bin/env bash
# H200 (device tool) timing of rthdist-masks on the 512 x 512 x 300 pairs of
# masks_bench.py (generated on the device as .npy: no nibabel there) and the
# aal atlas pairs (.nii.gz carried), each comparison --repeat 7 in one process
# (one Engine, as an evaluation loop holds it): GPU backend with the boundary
# compute pass, the same with --host-extraction, and the CPU backend.
# Bundle ($B, default .devrun3; recipe in docs/gpu.md): rthdist-masks.gz,
# rthdist_masks_tests.gz, lib/libnifti2.so.2 + libznz.so.3, data/atlas_*.nii.gz,
# layers/ (the Khronos validation layer, for the tests).
#   OUT=dir [B=.devrun3] [BACKEND=rt-pipeline] bash tools/bench/gpu_masks_run.sh
for f in .gl/*.deb; do dpkg -x $f / >/dev/null 2>&1; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
B=$PWD/${B:-.devrun3}; BACKEND=${BACKEND:-rt-pipeline}; W=/tmp/mw; mkdir -p $W $OUT
(cd $B && for f in *.gz layers/*.gz; do [ -e "$f" ] && gunzip -f $f; done; chmod +x rthdist-masks rthdist_masks_tests)
export LD_LIBRARY_PATH=$B/lib
{ nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader; nproc; } > $OUT/machine.txt 2>&1
python3 - $W <<'PY'
import sys, types, numpy as np
sys.modules['nibabel'] = types.ModuleType('nibabel')
sys.path.insert(0, 'tools/bench')
from masks_bench import organ
from scipy import ndimage as ndi
size=(512,512,300); spacing=(0.8,0.8,2.5); c=[s/2 for s in size]
ref = organ(size, spacing, c, (110.0, 80.0, 180.0), 6, 1)
pred = organ(size, spacing, [c[0] + 3, c[1] - 2, c[2] + 1], (112.0, 77.0, 176.0), 6, 2)
rng = np.random.default_rng(3)
band = ndi.binary_dilation(pred, iterations=3) & ~ndi.binary_erosion(pred, iterations=3)
noisy = pred ^ (band & (rng.random(size, dtype=np.float32) < 0.3))
noisy |= rng.random(size, dtype=np.float32) < 0.0002
for n, m in (("organ_ref", ref), ("organ_pred", pred), ("noisy_pred", noisy)): np.save(sys.argv[1] + "/" + n + ".npy", m.astype(np.uint8))
PY
cases=("organ $W/organ_ref.npy $W/organ_pred.npy --spacing 0.8,0.8,2.5"
       "noisy $W/organ_ref.npy $W/noisy_pred.npy --spacing 0.8,0.8,2.5"
       "atlas_l2_vs_dilated $B/data/atlas_l2_vs_dilated_a.nii.gz $B/data/atlas_l2_vs_dilated_b.nii.gz"
       "atlas_l1_vs_l2 $B/data/atlas_l1_vs_l2_a.nii.gz $B/data/atlas_l1_vs_l2_b.nii.gz")
for c in "${cases[@]}"; do
  set -- $c; name=$1; a=$2; b=$3; shift 3
  for mode in "$BACKEND" "$BACKEND --host-extraction" "cpu"; do
    # One JSON line per run in rows.jsonl (the device tool returns a bounded number of files).
    $B/rthdist-masks $a $b "$@" --convention monai --backend $mode --repeat 7 --json > /tmp/row.json 2>> $OUT/err.txt
    python3 -c "
import json; j=json.load(open('/tmp/row.json')); j['case']='$name'; j['mode']='$mode'
open('$OUT/rows.jsonl', 'a').write(json.dumps(j) + '\\n')"
    python3 -c "
import json, statistics; j=json.load(open('/tmp/row.json')); r=j['results'][0]; t=r['repeat_total_ms']
print('$name', '$mode'.ljust(28), r['extraction'], 'median %.2f ms (min %.2f, first %.2f)' % (statistics.median(t[1:]), min(t), t[0]),
      'last: extract %.2f distance %.2f' % (r['timings_ms']['extract'], r['timings_ms']['distance']),
      'hd95 %.7f' % r['hd_percentile'][0]['value'], 'points', r['a_to_b']['points'], r['b_to_a']['points'])"
  done
done
head -5 $OUT/err.txt
export VK_LAYER_PATH=$B/layers VK_LAYER_ENABLES=VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT
RTHDIST_TEST_BACKEND=$BACKEND timeout 200 $B/rthdist_masks_tests --gtest_filter='MasksBoundary.*:MasksBackend.*:MasksPrepared*:OrderStatistics.*' > $OUT/masks_tests.txt 2>&1
echo "masks tests rc=$?"; grep -h "PASSED\|FAILED" $OUT/masks_tests.txt | head
