# The rows of docs/bench/gpu.md, sourced by the device scripts
# (gpu_device_run.sh, gpu_certificate_ab.sh): writes the Dragon's surface
# samplings (1M and 5M points a side, fixed seeds 1-4) and its copies moved by
# 0.3 / 0.5 / 0.7 of its x-extent into $S, each once, and sets `cases`
# ("name A B" per row). Needs D (the bundle's data/), S (a scratch folder)
# and here (tools/bench).
for spec in "1000000 1 s1m_a" "1000000 2 s1m_b" "5000000 3 s5m_a" "5000000 4 s5m_b"; do
  set -- $spec
  [ -f "$S/$3.ply" ] || python3 "$here/sample_surface.py" "$D/dragon_vrip.ply.gz" "$1" "$2" "$S/$3.ply" &
done
python3 - "$D/dragon_vrip.ply.gz" "$S" "$here" <<'PY' &
import sys; sys.path.insert(0, sys.argv[3])
from ply_points import read_ply, write_ply
a = read_ply(sys.argv[1])
for t in (0.3, 0.5, 0.7):
    b = a.copy(); b[:, 0] += (float(a[:, 0].max()) - float(a[:, 0].min())) * t
    write_ply("%s/dragon_t%s.ply" % (sys.argv[2], t), b)
PY
wait
cases=(
  "dragon-res2 $D/dragon_vrip.ply.gz $D/dragon_vrip_res2.ply.gz"
  "dragon-t0.3 $D/dragon_vrip.ply.gz $S/dragon_t0.3.ply"
  "dragon-t0.5 $D/dragon_vrip.ply.gz $S/dragon_t0.5.ply"
  "dragon-t0.7 $D/dragon_vrip.ply.gz $S/dragon_t0.7.ply"
  "surface-1M $S/s1m_a.ply $S/s1m_b.ply"
  "surface-5M $S/s5m_a.ply $S/s5m_b.ply"
)
