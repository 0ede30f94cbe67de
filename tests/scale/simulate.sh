#!/usr/bin/env bash
# Predicts how superball explore scales on a cluster, with SimGrid's SMPI running the real
# schedule (src/run/work_pool.cpp over src/run/schedule.cpp and src/mpi/mpi.cpp, built with smpicxx into
# OUT/sim_run) and cost models for counting and writing. Prints one line per job and rank
# count:
#
#   job=NAME ranks=N tile_points=T efficiency=E end_to_end=E2 predicted_s=S rank_mib=M
#
# ideal = the job's total counting / N; efficiency = ideal / the compute phase (the first
# tile handed out to the last one reported, as explore's "computed in"); end_to_end =
# ideal / S, S the predicted time from mpirun starting to the result renamed: the start-up
# (the launch and MPI_Init: 0.226 + 0.2417 sqrt(N) s, fitted to Open MPI's measured under
# srun, sim_run.cpp startup_law; --startup-seconds S states another), rank 0 creating the
# partial file and the writers opening it (each open queueing at the metadata server), the
# compute phase, the last writes, rank 0's journal and finish. T: the job's tile (= chunk)
# points at N ranks. M: the largest rank's modelled memory beyond the counting's own
# buffers (the hand-out list, rank 0's journal, the writers' and senders' buffers, a
# resume's done tiles; sim_run.cpp Memory), MiB. The details of each run (schedule and
# finish times, the tail, messages rank 0 received, tiles given back, file-system
# operations, the writers: the bytes each wrote, their waits, their busiest second of
# payload received; rank 0's own writer; memory by part) are in OUT/logs/NAME.N.log.
#
#   tests/scale/simulate.sh [--ranks "64 256 1024 4096"] [--startup-seconds S] [--tile-points T]
#                           [--weak F] [--writers N|auto] [--ratio-boxes K] [--sample-points P]
#                           [--out DIR] [--no-build]
#                           [--latency-factor F] [--bandwidth-factor F] [--fs-bandwidth-factor F]
#                           [--metadata-factor F] [--noise SIGMA] [--slow-nodes FRACTION:SPEED]
#                           [--lose-node] [--requeue-seconds S] [--collectives auto|default|trees]
#                           [JOB.toml...]
#
# --weak F: the job scaled up, its longest grid axis F times as many samples, its tiles F
# times as many points when the job sets them (else the default tiling grows them with the
# ranks' shares), so that the number of tiles, and the simulation's cost, stays about the
# same (logs NAME.weakF...). --writers: who writes the compressed result (explore
# --writers; default auto: one writer per node from 64 ranks on).
# Stresses (defaults: none, the platform of tests/scale/cluster.xml), each a flag, any of
# them at once: --latency-factor multiplies the latencies of the links between nodes (10:
# ten times slower), --bandwidth-factor their bandwidths (0.1: ten times slower);
# --fs-bandwidth-factor multiplies the file system's bandwidth and each client's;
# --metadata-factor multiplies the file system's cost per operation (every operation's
# latency, and the metadata server's time for each of its own); --noise SIGMA multiplies
# each tile's compute time by a lognormal factor of mean 1 (0.05: about +-5 %) and each
# rank's speed by another (a slow core stays slow); --slow-nodes 0.05:0.5 makes 5 % of the
# nodes (a seeded draw) count at half speed. The efficiencies stay relative to the
# unstressed ideal. --lose-node: a node is lost halfway through the ideal time and the MPI
# job dies with it at once (a crash: no tile in flight finishes, no checkpoint is written);
# it is requeued and resumes from what its journal recorded at its last checkpoint,
# paying a second start-up, the journal read, the done tiles broadcast and each checked
# against its checksum. The line then adds lost_at_s, lost_work_s (core-seconds counted
# and lost), recorded_tiles and requeue_s (--requeue-seconds S, default 420: Slurm's
# SlurmdTimeout of 300 s before a silent node is marked down and its requeue_delay of
# 120 s; stated, not counted), and predicted_s / end_to_end are the whole over both runs:
# until the loss, then the resumed run (efficiency: the resumed run's compute phase). A
# stressed run's logs are NAME.STRESS.N.log.
#
# --collectives: SMPI's algorithms for the collectives (MPI_Allreduce, MPI_Reduce,
# MPI_Barrier, MPI_Gather, MPI_Scatter; the schedule itself is point to point). SMPI's
# default ones are linear, rank 0 waiting on a request from every rank at once, which costs
# the simulator a time growing as the square of the ranks (at 16384 ranks one allreduce had
# not ended after 40 min); "trees" selects logarithmic ones of Open MPI's (recursive
# doubling for allreduce and barrier, binomial trees for the others), as the real program
# gets from Open MPI. (SMPI's whole "ompi" selector is not used: its broadcast sets up
# SMPI's per-node communicators and aborted sim_run.) auto (the default): "default" up to
# 4096 ranks (the results of README.md here were measured with it), "trees" beyond.
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
startup=
weak=1
writers=auto
out=$root/build/scale
build=true
tile_points=
ratio_boxes=32
sample_points=2200000
latency_factor=1 bandwidth_factor=1 fs_bandwidth_factor=1 metadata_factor=1
stress_args=()
stress=
lose_node=false
requeue=420
collectives=auto
jobs=()
while (($# > 0)); do
  case $1 in
    --ranks) ranks=$2; shift 2 ;;
    --startup-seconds) startup=$2; shift 2 ;;
    --weak) weak=$2; shift 2 ;;
    --writers) writers=$2; shift 2 ;;
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
    --collectives) collectives=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    --no-build) build=false; shift ;;
    -h|--help) sed -n '2,100p' "$0"; exit 0 ;;
    -*) echo "simulate: unknown option $1 (accepted: --ranks, --startup-seconds, --tile-points, --weak, --writers, --ratio-boxes, --sample-points, --out, --no-build, --latency-factor, --bandwidth-factor, --fs-bandwidth-factor, --metadata-factor, --noise, --slow-nodes, --lose-node, --requeue-seconds, --collectives, --help)" >&2; exit 2 ;;
    *) jobs+=("$1"); shift ;;
  esac
done
((${#jobs[@]} > 0)) || jobs=(jobs/cluster/*.toml)
case $collectives in
  auto|default|trees) ;;
  *) echo "simulate: --collectives $collectives: accepted auto, default or trees" >&2; exit 2 ;;
esac
[[ $weak =~ ^[1-9][0-9]*$ ]] || { echo "simulate: --weak $weak: accepted a whole factor >= 1" >&2; exit 2; }
case $writers in
  auto) writers_arg=0 ;;
  *) [[ $writers =~ ^[1-9][0-9]*$ ]] || { echo "simulate: --writers $writers: accepted auto or a count >= 1" >&2; exit 2; }
     writers_arg=$writers ;;
esac

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
# Beyond 4096 ranks, the same cluster with as many nodes as the most ranks need.
most=$(tr ' ' '\n' <<<"$ranks" | sort -n | tail -1)
nodes=$(( most > 4096 ? (most + 1023) / 1024 * 32 : 128 ))
((nodes == 128)) || platform=$out/platform$stress.n$nodes.xml
/usr/bin/python3 tests/scale/stress_platform.py tests/scale/cluster.xml "$platform" "$latency_factor" "$bandwidth_factor" \
  "$fs_bandwidth_factor" "$metadata_factor" "$nodes"
# The cluster of cluster.xml: 32 ranks a node, consecutive ranks on one node.
for ((i = 0; i < nodes; i++)); do echo "node-$i:32"; done >"$out/hosts.$nodes"

# shellcheck source=calibration.env
source tests/scale/calibration.env
# Stacks of 512 KiB for the simulated ranks (SimGrid's default 8 MiB: 1024 ranks of
# corner_zoom --weak 8 took 1.3 GB of memory, 0.8 GB with these; nothing in sim_run goes deep).
smpi=(--cfg=smpi/host-speed:1Gf --cfg=smpi/simulate-computation:no --cfg=smpi/privatization:no
      --cfg=smpi/iprobe:0 --cfg=smpi/test:0 --cfg=smpi/grow-injected-times:no --cfg=smpi/async-small-thresh:65536
      --cfg=contexts/stack-size:512)

for job in "${jobs[@]}"; do
  name=$(basename "$job" .toml)
  if ((weak > 1)); then
    # The job scaled up (--weak): its longest axis F times as many samples, its own tiles
    # (when it sets them) F times as many points.
    /usr/bin/python3 - "$job" "$out/jobs/$name.weak$weak.toml" "$weak" <<'EOF'
import sys, tomllib
sys.path.insert(0, "tests/scale")
from lowres_job import write_tables
job = tomllib.load(open(sys.argv[1], "rb"))
f = int(sys.argv[3])
axes = [k for k, v in job["grid"].items() if isinstance(v, dict)]
longest = max(axes, key=lambda k: job["grid"][k]["n"])
job["grid"][longest]["n"] *= f
if "tile_points" in job.get("run", {}):
    job["run"]["tile_points"] *= f
write_tables(job, open(sys.argv[2], "w"))
EOF
    job=$out/jobs/$name.weak$weak.toml
    name=$name.weak$weak
  fi
  if [[ -n $tile_points ]]; then
    # The job in tiles of --tile-points points: a copy with [run] tile_points set.
    /usr/bin/python3 - "$job" "$out/jobs/$name.tp$tile_points.toml" "$tile_points" <<'EOF'
import sys, tomllib
sys.path.insert(0, "tests/scale")
from lowres_job import write_tables
job = tomllib.load(open(sys.argv[1], "rb"))
job.setdefault("run", {})["tile_points"] = int(sys.argv[3])
write_tables(job, open(sys.argv[2], "w"))
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
  # Tree collectives asked for at every rank count: lines of their own.
  if [[ $collectives == trees ]]; then label=$label.trees; fi
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
      alignment=$(/usr/bin/python3 -c 'import sys, tomllib; print(tomllib.load(open(sys.argv[1], "rb")).get("run", {}).get("alignment", 1048576))' "$job")
      write=(--compress-mbps "$compress_mbps" --compress-ratio "$ratio" --index-us-per-tile "$INDEX_US_PER_TILE"
             --copy-gbps "$COPY_GBPS" --hash-gbps "$HASH_GBPS" --journal-us-per-run "$JOURNAL_US_PER_RUN" --writers "$writers_arg" --alignment "$alignment")
    fi
    # Serve is called every 512 points in the real counter; the model calls it at least
    # every 1/2000 of the ideal run time (0.05 s at 4096 ranks), which keeps the number of
    # simulated events per run the same at every rank count (answers come later than in
    # the real run by at most that).
    serve_every=$(field ideal_s | /usr/bin/python3 -c 'import sys; print(max(0.05, float(sys.stdin.read()) / 2000))')
    # 4. The simulated run.
    start=$SECONDS
    coll=()
    if [[ $collectives == trees ]] || { [[ $collectives == auto ]] && ((n > 4096)); }; then
      coll=(--cfg=smpi/allreduce:rdb --cfg=smpi/reduce:ompi_binomial --cfg=smpi/barrier:ompi_recursivedoubling
            --cfg=smpi/gather:ompi_binomial --cfg=smpi/scatter:ompi_binomial --cfg=smpi/bcast:binomial_tree)
    fi
    sim() {  # COSTS [more sim_run options]; the simulator's own time and memory in the log
      /usr/bin/time -a -o "$log" -f "simulate: the simulator took %e s of wall time and %M KiB of memory at most" \
        smpirun -np "$n" -platform "$platform" -hostfile "$out/hosts.$nodes" "$out/sim_run" "$1" \
        --node-ranks 32 --idle-poll 0.02 --serve-every "$serve_every" --granule "$granule" "${write[@]}" \
        ${startup:+--startup-seconds "$startup"} "${stress_args[@]}" "${@:2}" "${smpi[@]}" "${coll[@]}" >>"$log" 2>&1
    }
    extra=
    if $lose_node; then
      # A node lost halfway through the ideal time: the job dies at once; it is requeued
      # (--requeue-seconds, stated) and resumes from the tiles its journal recorded at the
      # last checkpoint, paying what a resume pays (sim_run --resumed).
      ideal=$(field ideal_s)
      at=$(/usr/bin/python3 -c "print(float('$ideal') / 2)")
      sim "$costs" --lose-node-at "$at" --lost-record "$out/costs/$label.$n.lost"
      lost=$(grep '^lost_node_at_s=' "$log" | tail -1)
      [[ -n $lost ]] || { echo "simulate: no lost-node result for $label at $n ranks; see $log" >&2; exit 1; }
      "$scale_costs" "$job" "$n" "$out/lowres/$lowname.h5" "$NS_PER_POINT" "$ns_per_iteration" "$US_PER_TILE" "$costs.resumed" \
        "$out/costs/$label.$n.lost" >>"$log"
      sim "$costs.resumed" --resumed
      rm -f "$costs.resumed" "$out/costs/$label.$n.lost"
    else
      sim "$costs"
    fi
    echo "simulate: $label at $n ranks took $((SECONDS - start)) s of wall time" >>"$log"
    line=$(grep '^ranks=' "$log" | tail -1)
    [[ -n $line ]] || { echo "simulate: no result for $label at $n ranks; see $log" >&2; exit 1; }
    rank_mib=$(sed -n 's/.* rank_mib=\([^ ]*\).*/\1/p' <<<"$line")
    efficiency=$(sed -n 's/.* efficiency=\([^ ]*\).*/\1/p' <<<"$line")
    end_to_end=$(sed -n 's/.* end_to_end=\([^ ]*\).*/\1/p' <<<"$line")
    predicted=$(sed -n 's/.* predicted_s=\([^ ]*\).*/\1/p' <<<"$line")
    if $lose_node; then
      # The whole: the first run until the loss, then the resumed run; against the whole
      # job's ideal (the queue's wait stated, not counted: it is the cluster's). efficiency
      # stays the resumed run's compute phase's.
      read -r predicted end_to_end extra < <(/usr/bin/python3 - "$lost" "$predicted" "$requeue" "$(field ideal_s)" <<'PYX'
import sys
kv = dict(x.split("=") for x in sys.argv[1].split())
lost_at, resumed, requeue, ideal = float(kv["lost_at_s"]), float(sys.argv[2]), float(sys.argv[3]), float(sys.argv[4])
total = lost_at + resumed
print(f"{total:.6g} {ideal / total:.4f} lost_at_s={lost_at:.6g} lost_work_s={float(kv['lost_work_s']):.6g} "
      f"recorded_tiles={kv['recorded_tiles']} requeue_s={requeue:g}")
PYX
      )
    fi
    echo "job=$label ranks=$n tile_points=$points efficiency=$efficiency end_to_end=$end_to_end predicted_s=$predicted rank_mib=$rank_mib${extra:+ $extra}"
    rm -f "$costs"
  done
done
