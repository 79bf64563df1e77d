#!/usr/bin/env bash
# Session 16, second call: tests with validation; one call and quarter before/after alternated;
# the one call and the quarter --verify'd; 1B before/after.
set -uo pipefail
B=.devs; S=/tmp/rthdist-scale; mkdir -p $S $OUT /tmp/res; trap "tar czf $OUT/res.tgz -C /tmp res" EXIT
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader; nproc
one() {  # label bin args...
  local label=$1 bin=$2; shift 2
  env RTHDIST_SUBMIT_TRACE=1 $B/$bin --json --quiet --backend rt-pipeline "$@" $S/a.ply $S/b.ply > /tmp/res/"${label// /_}".json 2> /tmp/res/"${label// /_}".err
  echo "$label rc=$? $(grep -o 'partition [0-9.]* ms.*' /tmp/res/"${label// /_}".err | head -1 | cut -c1-150)"
  python3 -c "
import json,sys; d=json.load(open(sys.argv[1])); t=d['timings_ms']; g=d['gpu_ms']
print('   H', d['hausdorff'], 'verify', (d['verify'].get('ok'), d['verify'].get('max_abs_diff')) if isinstance(d.get('verify'),dict) else None, 'cert', d['certificate']['a_to_b'].get('confirmed'), d['certificate']['b_to_a'].get('confirmed'), 'total', round(t['total']), 'pieces', round(t.get('pieces',0)), 'wall', round(t['wall']), 'load', round(t['load']), 'setup', round(t['setup']), 'host upload', round(t.get('upload',0)), 'index', round(t.get('index',0)), 'cull', round(t.get('cull',0)), 'check', round(t.get('check',0)), '| gpu upload', round(g['upload']), 'index', round(g['index']), 'cull', round(g['cull']), 'search', round(g['search']))" /tmp/res/"${label// /_}".json
}
if [ "${TESTS:-0}" = 1 ]; then
  VK_LAYER_PATH=$PWD/.devp/layers RTHDIST_TEST_BACKEND=rt-pipeline timeout 150 $B/rthdist_engine_tests --gtest_filter='OutOfCore*:*Pieces*' > /tmp/res/engine_out_of_core.txt 2>&1; echo "engine tests exit $?"; grep -E "^\[  (PASSED|FAILED)|tests ran" /tmp/res/engine_out_of_core.txt | head
  VK_LAYER_PATH=$PWD/.devp/layers RTHDIST_TEST_BACKEND=rt-pipeline timeout 120 $B/rthdist_gpu_tests --gtest_filter='*PerPointFloor*:*PerPointDistances*:LargeSizes.Chunked*' > /tmp/res/gpu_tests.txt 2>&1; echo "gpu tests exit $?"; grep -E "^\[  (PASSED|FAILED)|tests ran" /tmp/res/gpu_tests.txt | head
fi
(./$B/rthdist-scale-gen torus 300000000 11 $S/a.ply & ./$B/rthdist-scale-gen torus 400000000 12 $S/b.ply & wait); cat $S/*.ply > /dev/null
one "warm" rthdist --memory-budget 22400
for r in 1 2 3; do for v in rthdist-before rthdist; do one "quarter $v $r" $v --memory-budget 22400; done; done
[ "${BIG:-1}" = 1 ] || exit 0
