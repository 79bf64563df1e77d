# The scale suite's cases (issue 32), sourced by gpu_scale_suite.sh and
# gpu_certificate_ab.sh: `scale_specs CASE` sets `specs` ("shape points seed"
# per set, rthdist-scale-gen's arguments) and fails on an unknown case.
#   torus-300x400    noisy torus (issue 32), 300M vs 400M points
#   shell-400x400    noisy unit spherical shells, 400M vs 400M
#   cluster-100M     100M points in a 2 mm cube beside 10 points 1-10 km away, each set
#   cube-300x300     uniform in the unit cube, 300M vs 300M
#   crowded-20M      issue 32's small noisy sphere in a unit box, 20M vs 20M
#   torus-1000x1000  1B vs 1B: past one device's memory (pieces; --memory-budget applies)
scale_specs() {
  case $1 in
    torus-300x400) specs=("torus 300000000 11" "torus 400000000 12") ;;
    shell-400x400) specs=("shell 400000000 21" "shell 400000000 22") ;;
    cluster-100M) specs=("cluster 100000000 31" "cluster 100000000 32") ;;
    cube-300x300) specs=("cube 300000000 41" "cube 300000000 42") ;;
    crowded-20M) specs=("crowded 20000000 51" "crowded 20000000 52") ;;
    torus-1000x1000) specs=("torus 1000000000 61" "torus 1000000000 62") ;;
    *) echo "unknown case $1" >&2; return 2 ;;
  esac
}

# `scale_files BUNDLE SCRATCH` after scale_specs: generates the case's inputs
# in SCRATCH where missing (all cores) and sets `files`. New files are
# written back (`sync`) before anything is timed: in session 19 the first
# process after generating 1B x 1B ran 9.5-10.7 s against 5.9-7.4 s for the
# next ones in three calls, and 7.4 s in the one call that synced first.
scale_files() {
  files=()
  local s shape n seed f made=0
  for s in "${specs[@]}"; do
    read -r shape n seed <<< "$s"
    f="$2/${shape}_${n}_${seed}.ply"
    files+=("$f")
    [ -f "$f" ] || { "$1/rthdist-scale-gen" "$shape" "$n" "$seed" "$f" && made=1; }
  done
  [ "$made" -eq 0 ] || sync
}
