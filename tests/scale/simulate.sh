#!/usr/bin/env bash
# Predicts how superball explore scales on a cluster, with SimGrid's SMPI running the real
# schedule (src/run/schedule.cpp over src/mpi/mpi.cpp, built with smpicxx into
# build/scale/sim_run) and cost models for counting and writing. Prints one line per job
# and rank count:
#
#   job=NAME ranks=N efficiency=E predicted_s=T
#
# efficiency = ideal / predicted, ideal = the job's total compute / N. The details of each
# run (schedule and finishing times, the tail, messages rank 0 received, tiles given back,
# file-system operations) are in build/scale/logs/NAME.N.log.
#
#   tests/scale/simulate.sh [--ranks "64 256 1024 4096"] [JOB.toml...]
#
# Default: every job of jobs/cluster. The model, step by step:
#   1. the job at a lower resolution (tests/scale/lowres_job.py: about 2 million points),
#      computed here with the real superball (once; kept in build/scale/lowres);
#   2. the cost of each tile of the job as `superball explore` tiles it for N ranks
#      (scale_costs): per point NS_PER_POINT + NS_PER_ITERATION x its wall bounces (from the
#      nearest low-resolution sample), plus US_PER_TILE; constants measured on this machine
#      by tests/scale/calibrate.sh (tests/scale/calibration.env);
#   3. smpirun on tests/scale/cluster.xml (128 nodes x 32 cores, fat tree, a file system of
#      20 GB/s): sim_run replays the tiles' costs and the writer's I/O (flushes of ~8 MiB,
#      1 ms per operation, a resume journal on rank 0 every 10 s, a closing pass that reads
#      the raw data back, compresses it at COMPRESS_MBPS per core and writes 1/COMPRESS_RATIO).
#
# Installs SimGrid if missing (.ci/install-deps --scale). Slow: the simulated ranks run one
# after the other on one core, minutes to an hour per line (see README_section.md).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
cd "$root"
ranks="64 256 1024 4096"
jobs=()
while (($# > 0)); do
  case $1 in
    --ranks) ranks=$2; shift 2 ;;
    -h|--help) sed -n '2,30p' "$0"; exit 0 ;;
    *) jobs+=("$1"); shift ;;
  esac
done
((${#jobs[@]} > 0)) || jobs=(jobs/cluster/*.toml)

.ci/install-deps --scale
cmake --preset release >/dev/null
cmake --build build/release -j"$(nproc)" --target superball scale_costs >/dev/null
if [[ $(id -u) -eq 0 ]]; then export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1; fi
superball=$root/build/release/src/superball
scale_costs=$root/build/release/tests/scale/scale_costs
out=$root/build/scale
mkdir -p "$out/lowres" "$out/costs" "$out/logs"

sources=(tests/scale/sim_run.cpp src/run/schedule.cpp src/mpi/mpi.cpp)
if [[ ! -x $out/sim_run ]] || [[ -n $(find "${sources[@]}" src/run/schedule.hpp src/mpi/mpi.hpp -newer "$out/sim_run") ]]; then
  smpicxx -std=c++20 -O2 -Wall -Wextra -I"$root/src" "${sources[@]}" -o "$out/sim_run"
fi
# The cluster of cluster.xml: 32 ranks a node, consecutive ranks on one node.
for ((i = 0; i < 128; i++)); do echo "node-$i:32"; done >"$out/hosts"

# shellcheck source=calibration.env
source tests/scale/calibration.env
smpi=(--cfg=smpi/host-speed:1Gf --cfg=smpi/simulate-computation:no --cfg=smpi/privatization:no
      --cfg=smpi/iprobe:0 --cfg=smpi/test:0 --cfg=smpi/grow-injected-times:no --cfg=smpi/async-small-thresh:65536)

for job in "${jobs[@]}"; do
  name=$(basename "$job" .toml)
  "$superball" explore "$job" --dry-run >/dev/null
  # 1. The low-resolution sample, computed again only when the job changed.
  /usr/bin/python3 tests/scale/lowres_job.py "$job" "$out/lowres/$name.next.toml" "$out/lowres/$name.h5"
  if ! cmp -s "$out/lowres/$name.next.toml" "$out/lowres/$name.toml" || [[ ! -f $out/lowres/$name.h5 ]]; then
    mv "$out/lowres/$name.next.toml" "$out/lowres/$name.toml"
    echo "simulate: computing $out/lowres/$name.toml" >&2
    mpirun -n "$(nproc)" "$superball" explore "$out/lowres/$name.toml" --overwrite -q >&2
  else
    rm "$out/lowres/$name.next.toml"
  fi
  for n in $ranks; do
    costs=$out/costs/$name.$n.bin
    log=$out/logs/$name.$n.log
    # 2. Tile costs for this rank count's tiling; 3. the simulated run.
    "$scale_costs" "$job" "$n" "$out/lowres/$name.h5" "$NS_PER_POINT" "$NS_PER_ITERATION" "$US_PER_TILE" "$costs" >"$log"
    smpirun -np "$n" -platform tests/scale/cluster.xml -hostfile "$out/hosts" "$out/sim_run" "$costs" \
      --node-ranks 32 --idle-poll 0.02 --compress-mbps "$COMPRESS_MBPS" --compress-ratio "$COMPRESS_RATIO" \
      "${smpi[@]}" >>"$log" 2>&1
    line=$(grep '^ranks=' "$log" | tail -1)
    [[ -n $line ]] || { echo "simulate: no result for $name at $n ranks; see $log" >&2; exit 1; }
    efficiency=$(sed -n 's/.* efficiency=\([^ ]*\).*/\1/p' <<<"$line")
    predicted=$(sed -n 's/.* predicted_s=\([^ ]*\).*/\1/p' <<<"$line")
    echo "job=$name ranks=$n efficiency=$efficiency predicted_s=$predicted"
    rm -f "$costs"
  done
done
