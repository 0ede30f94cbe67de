#!/usr/bin/env bash
# Predicts how superball explore scales on a cluster, with SimGrid's SMPI running the real
# schedule (src/run/schedule.cpp over src/mpi/mpi.cpp, built with smpicxx into
# OUT/sim_run) and cost models for counting and writing. Prints one line per job and rank
# count:
#
#   job=NAME ranks=N efficiency=E end_to_end=E2 predicted_s=T
#
# ideal = the job's total counting / N; efficiency = ideal / the compute phase (the first
# tile handed out to the last one done, as explore reports it); end_to_end = ideal / T, T
# the predicted time from mpirun starting (a stated start-up, --startup-seconds, default 2
# s: MPI_Init at thousands of ranks, an assumption) to the result renamed. The details of
# each run (schedule and finish times, the tail, messages rank 0 received, tiles given back,
# file-system operations, the bytes rank 0 wrote and its writer's backlog) are in
# OUT/logs/NAME.N.log.
#
#   tests/scale/simulate.sh [--ranks "64 256 1024 4096"] [--startup-seconds S] [--out DIR] [--no-build] [JOB.toml...]
#
# Default: every job of jobs/cluster, OUT = build/scale. --no-build: use the superball and
# scale_costs of build/release (or $SUPERBALL_BUILD_DIR) as they are (the ctest smoke run).
# The model, step by step:
#   1. the job at a lower resolution (tests/scale/lowres_job.py: about 2 million points),
#      computed here with the real superball at -n 1 (once; kept in OUT/lowres with its
#      compute time, the median of 3 runs: run it on a machine doing nothing else);
#   2. the cost of each tile of the job as `superball explore` tiles it for N ranks
#      (scale_costs): per point NS_PER_POINT + NS_PER_ITERATION x its wall bounces (from the
#      nearest low-resolution sample), plus US_PER_TILE. NS_PER_POINT and US_PER_TILE were
#      measured on this machine by tests/scale/calibrate.sh (tests/scale/calibration.env);
#      NS_PER_ITERATION is the job's own, from its low-resolution run (its compute time
#      less the points' and tiles' share, over its wall bounces: a wall bounce costs more
#      map steps in some regions than in others). Blocks are multiples of the granule
#      explore uses ([run] alignment / bytes of a tile's counts);
#   3. smpirun on tests/scale/cluster.xml (128 nodes x 32 cores as fast as this machine's,
#      fat tree, a file system of 20 GB/s with 1 ms per operation, 2 GB/s for one client):
#      sim_run replays the tiles' costs, each tile's compression (at the speed and ratio
#      scale_costs measured compressing the sample's data as a rank does), the compressed
#      bytes sent to rank 0 with the reports, rank 0's writer appending them, its journal
#      every 10 s, and the finish (index, rename); uncompressed jobs, every rank's writer.
#
# Installs SimGrid if missing (.ci/install-deps --scale). The simulated ranks run one
# after the other on one core: seconds for 64 ranks, minutes for 4096 (README, Running on
# a cluster).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
cd "$root"
ranks="64 256 1024 4096"
startup=2
out=$root/build/scale
build=true
jobs=()
while (($# > 0)); do
  case $1 in
    --ranks) ranks=$2; shift 2 ;;
    --startup-seconds) startup=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    --no-build) build=false; shift ;;
    -h|--help) sed -n '2,42p' "$0"; exit 0 ;;
    -*) echo "simulate: unknown option $1 (accepted: --ranks, --startup-seconds, --out, --no-build, --help)" >&2; exit 2 ;;
    *) jobs+=("$1"); shift ;;
  esac
done
((${#jobs[@]} > 0)) || jobs=(jobs/cluster/*.toml)

out=$(realpath -m "$out")
bin=${SUPERBALL_BUILD_DIR:-$root/build/release}
if $build; then
  .ci/install-deps --scale
  cmake --preset release >/dev/null
  cmake --build build/release -j"$(nproc)" --target superball scale_costs >/dev/null
fi
if [[ $(id -u) -eq 0 ]]; then export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1; fi
superball=$bin/src/superball
scale_costs=$bin/tests/scale/scale_costs
mkdir -p "$out/lowres" "$out/costs" "$out/logs"
tests/scale/build_sim_run.sh "$out/sim_run"
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
  if ! cmp -s "$out/lowres/$name.next.toml" "$out/lowres/$name.toml" || [[ ! -f $out/lowres/$name.seconds ]]; then
    mv "$out/lowres/$name.next.toml" "$out/lowres/$name.toml"
    echo "simulate: computing $out/lowres/$name.toml at -n 1 (3 runs; on a machine doing nothing else)" >&2
    tests/scale/computed.sh "$superball" "$out/lowres/$name.toml" 3 >"$out/lowres/$name.seconds" ||
      { rm -f "$out/lowres/$name.seconds"; echo "simulate: $out/lowres/$name.toml failed" >&2; exit 1; }
  else
    rm "$out/lowres/$name.next.toml"
  fi
  # The job's cost per wall bounce, and how its data compress, from its sample.
  tiles=$("$superball" explore "$out/lowres/$name.toml" --dry-run | sed -n 's/^tiles: \([0-9]*\) .*/\1/p')
  read -r ns_per_iteration ratio < <(/usr/bin/python3 tests/scale/sample_model.py "$out/lowres/$name.h5" \
    "$(cat "$out/lowres/$name.seconds")" "$tiles" "$NS_PER_POINT" "$US_PER_TILE" "$NS_PER_ITERATION")
  for n in $ranks; do
    costs=$out/costs/$name.$n.bin
    log=$out/logs/$name.$n.log
    # 2. Tile costs for this rank count's tiling; 3. the simulated run.
    "$scale_costs" "$job" "$n" "$out/lowres/$name.h5" "$NS_PER_POINT" "$ns_per_iteration" "$US_PER_TILE" "$costs" >"$log"
    echo "simulate: ns_per_iteration=$ns_per_iteration (from $out/lowres/$name.h5)" >>"$log"
    granule=$(sed -n 's/.* granule=\([0-9]*\) .*/\1/p' "$log")
    compress_mbps=$(sed -n 's/.* compress_mbps=\([0-9.e+]*\).*/\1/p' "$log")
    compress_ratio=$(sed -n 's/.* compress_ratio=\([0-9.e+]*\).*/\1/p' "$log")
    write=(--compress-mbps "$compress_mbps" --compress-ratio "$compress_ratio")
    [[ $compress_mbps == 0 ]] && write=(--uncompressed)
    # Serve is called every 512 points in the real counter; the model calls it at least
    # every 1/2000 of the ideal run time (0.05 s at 4096 ranks), which keeps the number of
    # simulated events per run the same at every rank count (answers come later than in
    # the real run by at most that).
    serve_every=$(sed -n 's/.* ideal_s=\([0-9.e+]*\).*/\1/p' "$log" | /usr/bin/python3 -c 'import sys; print(max(0.05, float(sys.stdin.read()) / 2000))')
    start=$SECONDS
    smpirun -np "$n" -platform tests/scale/cluster.xml -hostfile "$out/hosts" "$out/sim_run" "$costs" \
      --node-ranks 32 --idle-poll 0.02 --serve-every "$serve_every" --granule "$granule" "${write[@]}" --startup-seconds "$startup" \
      "${smpi[@]}" >>"$log" 2>&1
    echo "simulate: $name at $n ranks took $((SECONDS - start)) s of wall time" >>"$log"
    line=$(grep '^ranks=' "$log" | tail -1)
    [[ -n $line ]] || { echo "simulate: no result for $name at $n ranks; see $log" >&2; exit 1; }
    efficiency=$(sed -n 's/.* efficiency=\([^ ]*\).*/\1/p' <<<"$line")
    end_to_end=$(sed -n 's/.* end_to_end=\([^ ]*\).*/\1/p' <<<"$line")
    predicted=$(sed -n 's/.* predicted_s=\([^ ]*\).*/\1/p' <<<"$line")
    echo "job=$name ranks=$n efficiency=$efficiency end_to_end=$end_to_end predicted_s=$predicted"
    rm -f "$costs"
  done
done
