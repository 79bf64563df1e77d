#!/usr/bin/env bash
# Session 18, call 6 (kind nvidia-h200-x2): why a second H200 gains little.
# Session 16 found a lane's host upload on this 32-core host twice that of
# the 16-core one. The machine's NUMA layout and each GPU's node, then the
# torus quarter (--memory-budget 22400) and the one call on one device with
# the process free (all threads, and as many as GPU 0's node has) and bound
# (taskset) to GPU 0's node's CPUs, and the
# quarter on two devices; 2 rounds alternated (build 30091d3).
set -uo pipefail
B=.devs; S=/tmp/rthdist-scale; mkdir -p $OUT $S /tmp/res; trap "tar czf $OUT/res.tgz -C /tmp res" EXIT
for f in .gl/*.deb; do dpkg -x $f / >/dev/null; done; ldconfig
export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
nvidia-smi --query-gpu=name,driver_version,pci.bus_id --format=csv,noheader; nproc
lscpu | grep -iE "model name|socket|numa|thread" | tee /tmp/res/lscpu.txt
for n in /sys/devices/system/node/node*; do echo "$(basename $n) cpus $(cat $n/cpulist) mem $(grep MemTotal $n/meminfo | awk '{print $4, $5}')"; done | tee /tmp/res/nodes.txt
for id in $(nvidia-smi --query-gpu=pci.bus_id --format=csv,noheader); do
  p=/sys/bus/pci/devices/$(echo ${id#0000} | tr 'A-Z' 'a-z' | sed 's/^0*:/0000:/'); [ -e $p ] || p=$(ls -d /sys/bus/pci/devices/*$(echo ${id: -7} | tr 'A-Z' 'a-z') 2>/dev/null | head -1)
  echo "gpu $id numa_node $(cat $p/numa_node 2>/dev/null) local_cpus $(cat $p/local_cpulist 2>/dev/null)"
done | tee /tmp/res/gpus.txt
nvidia-smi topo -m > /tmp/res/topo.txt 2>&1; head -8 /tmp/res/topo.txt
cpus0=$(grep "^gpu" /tmp/res/gpus.txt | head -1 | sed 's/.*local_cpus //')
[ -n "$cpus0" ] || cpus0=$(head -1 /tmp/res/nodes.txt | awk '{print $3}')
n0=$(python3 -c "import sys; print(sum(int(b)-int(a)+1 if '-' in r else 1 for r in sys.argv[1].split(',') for a,b in [(r.split('-')+[r])[:2]]))" "$cpus0")
echo "GPU 0's CPUs: $cpus0 ($n0)"
one() {  # label prefix args...
  local label=$1 pre=$2; shift 2
  $pre $B/rthdist --json --quiet --backend rt-pipeline "$@" $S/a.ply $S/b.ply > /tmp/res/"$label".json 2> /tmp/res/"$label".err
  echo "$label rc=$? $(python3 -c "
import json,sys; d=json.load(open(sys.argv[1])); t=d['timings_ms']; g=d['gpu_ms']
print('H', d['hausdorff'], 'total', round(t['total']), 'pieces', round(t.get('pieces',0)), 'load', round(t['load']), 'host upload', round(t.get('upload',0)), 'index', round(t.get('index',0)), 'cull', round(t.get('cull',0)), '| gpu upload', round(g['upload']), 'index', round(g['index']), 'cull', round(g['cull']))" /tmp/res/"$label".json 2>&1 | head -c 400)"
}
(./$B/rthdist-scale-gen torus 300000000 11 $S/a.ply & ./$B/rthdist-scale-gen torus 400000000 12 $S/b.ply & wait); cat $S/*.ply > /dev/null
for r in 1 2; do
  one "call_free_$r" ""
  one "call_free${n0}t_$r" "" --threads $n0
  one "call_node0_$r" "taskset -c $cpus0" --threads $n0
  one "quarter_free_$r" "" --memory-budget 22400
  one "quarter_free${n0}t_$r" "" --memory-budget 22400 --threads $n0
  one "quarter_node0_$r" "taskset -c $cpus0" --memory-budget 22400 --threads $n0
  one "quarter_two_$r" "" --memory-budget 22400 --devices 0,1
done
