#!/usr/bin/env bash
# Predicts how superball explore scales on a cluster, with SimGrid's SMPI running the real
# schedule (src/run/work_pool.cpp over src/run/schedule.cpp and src/mpi/mpi.cpp, built with smpicxx into
# OUT/sim_run) and cost models for counting and writing. Prints one line per job and rank
# count:
#
#   job=NAME ranks=N tile_points=T efficiency=E end_to_end=E2 predicted_s=S
#
# ideal = the job's total counting / N; efficiency = ideal / the compute phase (the first
# tile handed out to the last one reported, as explore's "computed in"); end_to_end =
# ideal / S, S the predicted time from mpirun starting to the result renamed: a stated
# start-up (--startup-seconds, default 2 s for MPI_Init at thousands of ranks: an
# assumption, see README.md), rank 0 creating the partial file and every rank opening it,
# the compute phase, rank 0's last write, journal and finish. T: the job's tile (= chunk)
# points at N ranks. The details of each run (schedule and finish times, the tail,
# messages rank 0 received, tiles given back, file-system operations, rank 0's writer: the
# bytes it wrote, its writes, its largest backlog, its busiest second of payload received)
# are in OUT/logs/NAME.N.log.
#
#   tests/scale/simulate.sh [--ranks "64 256 1024 4096"] [--startup-seconds S] [--tile-points T]
#                           [--ratio-boxes K] [--sample-points P] [--out DIR] [--no-build]
#                           [--latency-factor F] [--bandwidth-factor F] [--fs-bandwidth-factor F]
#                           [--metadata-factor F] [--noise SIGMA] [--slow-nodes FRACTION:SPEED]
#                           [--lose-node] [--requeue-seconds S]
#                           [JOB.toml...]
#
# Stresses (defaults: none, the platform of tests/scale/cluster.xml): --latency-factor
# multiplies the latencies of the links between nodes (10: ten times slower), --bandwidth-factor their
# bandwidths (0.1: ten times slower); --fs-bandwidth-factor multiplies the file system's
# bandwidth and one client's; --metadata-factor multiplies the file system's cost per
# operation (create, open, rename and every write's RPC); --noise SIGMA multiplies each tile's
# compute time by a lognormal factor of mean 1 (0.05: about +-5 %); --slow-nodes 0.05:0.5
# makes 5 % of the nodes (a seeded draw) count at half speed. The efficiencies stay relative
# to the unstressed ideal. --lose-node: a node is lost halfway through the ideal time, the
# MPI job dies with it, is requeued (--requeue-seconds S in the queue, default 0) and resumes
# from what its journal recorded; the line then adds lost_at_s, lost_work_s (core-seconds
# counted and lost) and recorded_tiles, and predicted_s / end_to_end are the whole: until the
# loss, the queue, the resumed run (efficiency: the resumed run's compute phase). A stressed
# run's logs are NAME.STRESS.N.log.
#
# Default: every job of jobs/cluster, OUT = build/scale. --tile-points: run the jobs in tiles
# of T points whatever they or the default say (the logs are then NAME.tpT.N.log).
# --sample-points P: the low-resolution sample of step 1 at about P points instead of 2.2
# million (4400000: twice as dense, the check that the prediction does not hang on the
# sampling; the sample and logs are then NAME.spP).
# --no-build: use the superball and scale_costs of build/release (or $SUPERBALL_BUILD_DIR)
# as they are (the ctest smoke run).
# The model, step by step:
#   1. the job at a lower resolution (tests/scale/lowres_job.py: about 2 million points),
#      computed here with the real superball at -n 1, uncompressed (once; kept in
#      OUT/lowres with its compute time, the median of 3 runs: run it on a machine doing
#      nothing else);
#   2. the cost of each tile of the job as `superball explore` tiles it for N ranks
#      (scale_costs): per point NS_PER_POINT + NS_PER_ITERATION x its wall bounces (from the
#      nearest low-resolution sample), plus US_PER_TILE. NS_PER_POINT, US_PER_TILE and the
#      write path's constants (INDEX_US_PER_TILE, COPY_GBPS) were measured on this machine
#      by tests/scale/calibrate.sh (tests/scale/calibration.env);
#      NS_PER_ITERATION is the job's own, from its low-resolution run (its compute time
#      less the points' and tiles' share, over its wall bounces);
#   3. how far the job's data compress in chunks of T points: tests/scale/chunk_ratio.py
#      computes K (--ratio-boxes, default 32) boxes of the job at full resolution picked at
#      random with the real superball, compressed, and sums what it stored (kept in
#      OUT/ratio; the low-resolution sample is no guide: its points lie 16-32 times farther
#      apart and its data compress 2-6 times less); on the same boxes, how fast a core
#      compresses them as a rank does (tests/scale/codec_speed);
#   4. smpirun on tests/scale/cluster.xml (128 nodes x 32 cores as fast as this machine's,
#      fat tree, a file system of 20 GB/s with 1 ms per operation, 2 GB/s for one client):
#      sim_run replays the tiles' costs, each tile's compression on its rank, the compressed
#      bytes sent to rank 0 with the reports, rank 0 copying them and its appender writing
#      them, its checkpoints every 10 s, and the finish (index, rename); uncompressed jobs,
#      every rank's writer.
#
# Installs SimGrid if missing (.ci/install-deps --scale). The simulated ranks run one
# after the other on one core: seconds for 64 ranks, minutes for 4096 (README.md here).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
cd "$root"
ranks="64 256 1024 4096"
startup=2
out=$root/build/scale
build=true
tile_points=
ratio_boxes=32
sample_points=2200000
latency_factor=1 bandwidth_factor=1 fs_bandwidth_factor=1 metadata_factor=1
stress_args=()
stress=
lose_node=false
requeue=0
jobs=()
while (($# > 0)); do
  case $1 in
    --ranks) ranks=$2; shift 2 ;;
    --startup-seconds) startup=$2; shift 2 ;;
    --tile-points) tile_points=$2; shift 2 ;;
    --ratio-boxes) ratio_boxes=$2; shift 2 ;;
    --sample-points) sample_points=$2; shift 2 ;;
    --latency-factor) latency_factor=$2; stress+=.lat$2; shift 2 ;;
    --bandwidth-factor) bandwidth_factor=$2; stress+=.bw$2; shift 2 ;;
    --fs-bandwidth-factor) fs_bandwidth_factor=$2; stress+=.fsbw$2; shift 2 ;;
    --metadata-factor) metadata_factor=$2; stress+=.meta$2; shift 2 ;;
    --noise) stress_args+=(--noise "$2"); stress+=.noise$2; shift 2 ;;
    --slow-nodes) stress_args+=(--slow-nodes "$2"); stress+=.slow${2/:/x}; shift 2 ;;
    --lose-node) lose_node=true; stress+=.lost; shift ;;
    --requeue-seconds) requeue=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    --no-build) build=false; shift ;;
    -h|--help) sed -n '2,70p' "$0"; exit 0 ;;
    -*) echo "simulate: unknown option $1 (accepted: --ranks, --startup-seconds, --tile-points, --ratio-boxes, --sample-points, --out, --no-build, --latency-factor, --bandwidth-factor, --fs-bandwidth-factor, --metadata-factor, --noise, --slow-nodes, --lose-node, --requeue-seconds, --help)" >&2; exit 2 ;;
    *) jobs+=("$1"); shift ;;
  esac
done
((${#jobs[@]} > 0)) || jobs=(jobs/cluster/*.toml)

out=$(realpath -m "$out")
bin=${SUPERBALL_BUILD_DIR:-$root/build/release}
if $build; then
  .ci/install-deps --scale
  cmake --preset release >/dev/null
  cmake --build build/release -j"$(nproc)" --target superball scale_costs codec_speed >/dev/null
fi
if [[ $(id -u) -eq 0 ]]; then export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1; fi
superball=$bin/src/superball
scale_costs=$bin/tests/scale/scale_costs
mkdir -p "$out/lowres" "$out/costs" "$out/logs" "$out/ratio" "$out/jobs"
tests/scale/build_sim_run.sh "$out/sim_run"
# The platform: cluster.xml with the stresses' factors (tests/scale/stress_platform.py).
platform=$out/platform$stress.xml
/usr/bin/python3 tests/scale/stress_platform.py tests/scale/cluster.xml "$platform" "$latency_factor" "$bandwidth_factor" \
  "$fs_bandwidth_factor" "$metadata_factor"
# The cluster of cluster.xml: 32 ranks a node, consecutive ranks on one node.
for ((i = 0; i < 128; i++)); do echo "node-$i:32"; done >"$out/hosts"

# shellcheck source=calibration.env
source tests/scale/calibration.env
smpi=(--cfg=smpi/host-speed:1Gf --cfg=smpi/simulate-computation:no --cfg=smpi/privatization:no
      --cfg=smpi/iprobe:0 --cfg=smpi/test:0 --cfg=smpi/grow-injected-times:no --cfg=smpi/async-small-thresh:65536)

for job in "${jobs[@]}"; do
  name=$(basename "$job" .toml)
  if [[ -n $tile_points ]]; then
    # The job in tiles of --tile-points points: a copy with [run] tile_points set.
    /usr/bin/python3 - "$job" "$out/jobs/$name.tp$tile_points.toml" "$tile_points" <<'EOF'
import sys, tomllib
sys.path.insert(0, "tests/scale")
from lowres_job import value
job = tomllib.load(open(sys.argv[1], "rb"))
job.setdefault("run", {})["tile_points"] = int(sys.argv[3])
with open(sys.argv[2], "w") as f:
    for t in ("model", "grid", "run"):
        if t in job:
            f.write(f"[{t}]\n" + "".join(f"{k} = {value(v)}\n" for k, v in job[t].items()))
EOF
    job=$out/jobs/$name.tp$tile_points.toml
    label=$name.tp$tile_points$stress
  else
    label=$name$stress
  fi
  # Another sample size (--sample-points): a sample, and lines, of their own.
  lowname=$name
  if ((sample_points != 2200000)); then
    lowname=$name.sp$sample_points
    label=$label.sp$sample_points
  fi
  "$superball" explore "$job" --dry-run >/dev/null
  # 1. The low-resolution sample, computed again only when the job changed (tile_points
  #    and output aside: lowres_job.py leaves them out). The candidate's name holds this
  #    process's id: two simulations of one job started together raced on a shared one.
  next=$out/lowres/$lowname.next.$$.toml
  /usr/bin/python3 tests/scale/lowres_job.py "$job" "$next" "$out/lowres/$lowname.h5" \
    --points "$sample_points"
  sed -i "1s|.*|# Lower-resolution sample of $name for the scaling simulation (tests/scale/lowres_job.py).|" "$next"
  if ! cmp -s "$next" "$out/lowres/$lowname.toml" || [[ ! -f $out/lowres/$lowname.seconds ]]; then
    mv "$next" "$out/lowres/$lowname.toml"
    echo "simulate: computing $out/lowres/$lowname.toml at -n 1 (3 runs; on a machine doing nothing else)" >&2
    tests/scale/computed.sh "$superball" "$out/lowres/$lowname.toml" 3 >"$out/lowres/$lowname.seconds" ||
      { rm -f "$out/lowres/$lowname.seconds"; echo "simulate: $out/lowres/$lowname.toml failed" >&2; exit 1; }
  else
    rm "$next"
  fi
  # The job's cost per wall bounce, from its sample.
  tiles=$("$superball" explore "$out/lowres/$lowname.toml" --dry-run | sed -n 's/^tiles: \([0-9]*\) .*/\1/p')
  ns_per_iteration=$(/usr/bin/python3 tests/scale/sample_model.py "$out/lowres/$lowname.h5" \
    "$(cat "$out/lowres/$lowname.seconds")" "$tiles" "$NS_PER_POINT" "$US_PER_TILE" "$NS_PER_ITERATION")
  for n in $ranks; do
    costs=$out/costs/$label.$n.bin
    log=$out/logs/$label.$n.log
    # 2. Tile costs for this rank count's tiling.
    "$scale_costs" "$job" "$n" "$out/lowres/$lowname.h5" "$NS_PER_POINT" "$ns_per_iteration" "$US_PER_TILE" "$costs" >"$log"
    echo "simulate: ns_per_iteration=$ns_per_iteration (from $out/lowres/$lowname.h5)" >>"$log"
    field() { sed -n "s/.* $1=\([^ ]*\).*/\1/p" "$log" | head -1; }
    granule=$(field granule) points=$(sed -n 's/.*tile_points=\([0-9]*\).*/\1/p' "$log" | head -1)
    if [[ $(field compression) == 0 ]]; then
      write=(--uncompressed)
    else
      # 3. The job's compression ratio in chunks of this size, at full resolution (kept
      #    per job content, chunk size and number of boxes).
      key=$(sed '/^ *\(output\|tile_points\) *=/d' "$job" | md5sum | cut -c1-10)
      ratio_file=$out/ratio/$name.$points.$ratio_boxes.$key.txt
      if [[ ! -s $ratio_file ]]; then
        echo "simulate: measuring how $name compresses in chunks of $points points ($ratio_boxes boxes at full resolution)" >&2
        /usr/bin/python3 tests/scale/chunk_ratio.py "$job" --superball "$superball" --boxes "$ratio_boxes" \
          --box-points $((points > 65536 ? points : 65536)) --tile-points "$points" --work "$out/chunks" --codec-speed "$bin/tests/scale/codec_speed" >"$ratio_file.next" ||
          { echo "simulate: chunk_ratio.py failed for $name" >&2; exit 1; }
        mv "$ratio_file.next" "$ratio_file"
      fi
      cat "$ratio_file" >>"$log"
      ratio=$(sed -n 's/.* ratio=\([^ ]*\).*/\1/p' "$ratio_file")
      compress_mbps=$(sed -n 's/.* compress_mbps=\([^ ]*\).*/\1/p' "$ratio_file")
      write=(--compress-mbps "$compress_mbps" --compress-ratio "$ratio" --index-us-per-tile "$INDEX_US_PER_TILE"
             --copy-gbps "$COPY_GBPS")
    fi
    # Serve is called every 512 points in the real counter; the model calls it at least
    # every 1/2000 of the ideal run time (0.05 s at 4096 ranks), which keeps the number of
    # simulated events per run the same at every rank count (answers come later than in
    # the real run by at most that).
    serve_every=$(field ideal_s | /usr/bin/python3 -c 'import sys; print(max(0.05, float(sys.stdin.read()) / 2000))')
    # 4. The simulated run.
    start=$SECONDS
    sim() {  # COSTS [more sim_run options]
      smpirun -np "$n" -platform "$platform" -hostfile "$out/hosts" "$out/sim_run" "$1" \
        --node-ranks 32 --idle-poll 0.02 --serve-every "$serve_every" --granule "$granule" "${write[@]}" \
        --startup-seconds "$startup" "${stress_args[@]}" "${@:2}" "${smpi[@]}" >>"$log" 2>&1
    }
    extra=
    if $lose_node; then
      # A node lost halfway through the ideal time: the job dies; it is requeued
      # (--requeue-seconds in the queue, default 0: the queue's wait is the cluster's) and
      # resumes from the tiles its journal recorded at the last checkpoint.
      ideal=$(field ideal_s)
      at=$(/usr/bin/python3 -c "print(float('$ideal') / 2)")
      sim "$costs" --lose-node-at "$at" --lost-record "$out/costs/$label.$n.lost"
      lost=$(grep '^lost_node_at_s=' "$log" | tail -1)
      [[ -n $lost ]] || { echo "simulate: no lost-node result for $label at $n ranks; see $log" >&2; exit 1; }
      "$scale_costs" "$job" "$n" "$out/lowres/$lowname.h5" "$NS_PER_POINT" "$ns_per_iteration" "$US_PER_TILE" "$costs.resumed" \
        "$out/costs/$label.$n.lost" >>"$log"
      sim "$costs.resumed"
      rm -f "$costs.resumed" "$out/costs/$label.$n.lost"
    else
      sim "$costs"
    fi
    echo "simulate: $label at $n ranks took $((SECONDS - start)) s of wall time" >>"$log"
    line=$(grep '^ranks=' "$log" | tail -1)
    [[ -n $line ]] || { echo "simulate: no result for $label at $n ranks; see $log" >&2; exit 1; }
    efficiency=$(sed -n 's/.* efficiency=\([^ ]*\).*/\1/p' <<<"$line")
    end_to_end=$(sed -n 's/.* end_to_end=\([^ ]*\).*/\1/p' <<<"$line")
    predicted=$(sed -n 's/.* predicted_s=\([^ ]*\).*/\1/p' <<<"$line")
    if $lose_node; then
      # The whole: the first run until the loss, the queue, the resumed run; against the
      # whole job's ideal. efficiency stays the resumed run's compute phase's.
      read -r predicted end_to_end extra < <(/usr/bin/python3 - "$lost" "$predicted" "$requeue" "$(field ideal_s)" <<'PYX'
import sys
kv = dict(x.split("=") for x in sys.argv[1].split())
lost_at, resumed, requeue, ideal = float(kv["lost_at_s"]), float(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4])
total = lost_at + requeue + resumed
print(f"{total:.6g} {ideal / total:.4f} lost_at_s={lost_at:.6g} lost_work_s={float(kv['lost_work_s']):.6g} "
      f"recorded_tiles={kv['recorded_tiles']} requeue_s={requeue:g}")
PYX
      )
    fi
    echo "job=$label ranks=$n tile_points=$points efficiency=$efficiency end_to_end=$end_to_end predicted_s=$predicted${extra:+ $extra}"
    rm -f "$costs"
  done
done
