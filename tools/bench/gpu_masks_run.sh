#!/usr/bin/env bash
# H200 (device tool) timing of rthdist-masks on the 512 x 512 x 300 pairs of
# masks_bench.py, generated on the device as .npy (no nibabel there); bundle:
# .devrun/rthdist-masks, .devrun/lib/libnifti2.so.2 + libznz.so.3 (docs/gpu.md).
#   OUT=dir bash tools/bench/gpu_masks_run.sh
for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig; export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
export LD_LIBRARY_PATH=$PWD/.devrun/lib; W=/tmp/mw; mkdir -p $W $OUT
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
nproc
for pair in "organ organ_ref organ_pred" "noisy organ_ref noisy_pred"; do
  set -- $pair
  for be in rt-pipeline cpu; do
    for run in 1 2 3 4 5 6; do
      .devrun/rthdist-masks $W/$2.npy $W/$3.npy --spacing 0.8,0.8,2.5 --convention monai --backend $be --json > $OUT/${1}_${be}_${run}.json 2>> $OUT/err.txt
      python3 -c "
import json; j=json.load(open('$OUT/${1}_${be}_${run}.json')); r=j['results'][0]; print('$1 $be run $run', j.get('device'), 'hd95', r['hd_percentile'][0]['value'], 'hd', r['hd'], 'points', r['a_to_b']['points'], r['b_to_a']['points'], 'ms', r['timings_ms'])"
    done
  done
done
cat $OUT/err.txt | head -5
