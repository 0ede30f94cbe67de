#!/usr/bin/env bash
# Checks the model of tests/scale/simulate.sh against real runs on this machine: the same
# simulation (the real schedule under SMPI; tile costs from the job at 1/8 of its points,
# computed at -n 1, whose compute time gives the job's cost per wall bounce, and
# tests/scale/calibration.env) on tests/scale/local.xml (one host of 2 cores, which
# oversubscribed ranks share), against the compute phase `superball explore` reports
# ("computed in"), median of REPS runs. Prints one line per case:
#
#   job=NAME ranks=N real_s=R predicted_s=P error=E
#
# with error = (P - R) / R. The cases: the 512^3 volume of jobs/full (light points), a
# small copy of the corner zoom of jobs/cluster (heavy-tailed costs), and the trivial grid
# with 1024-point tiles oversubscribed (65536 tiles: the schedule's own cost and the
# sharing of the cores).
#
#   tests/scale/validate.sh [REPS]
#
# --oversubscribed "16 32 64": the paths of a cluster run instead (rank 0 serving only, the
# interleaved hand-out, node leaders: pseudo-nodes of 16 ranks, --node-ranks), on the
# small corner-zoom copy, real and simulated at each of those rank counts. Times are not
# compared (64 ranks share 2 cores), the counts are, one line each:
#
#   ranks=N quantity=Q real=R simulated=S check=exact|10% agreement=yes|NO (E)
#
# exact where they do not depend on timing (tiles, ranks counting, two levels), within
# 10 % where they do (blocks rank 0 handed out, its requests and messages, the leaders'
# messages, tiles per rank, the write calls to the result's files and their bytes: the
# real run's counted by strace, tests/scale/write_calls.sh); the real figure is the median
# of REPS runs. Exits 1 when one disagrees.
#
#   tests/scale/validate.sh --oversubscribed "16 32 64" [REPS]
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
cd "$root"
oversubscribed=
if [[ ${1:-} == --oversubscribed ]]; then
  oversubscribed=${2:?--oversubscribed needs rank counts, e.g. \"16 32 64\"}
  shift 2
fi
reps=${1:-3}
.ci/install-deps --scale
[[ -z $oversubscribed ]] || .ci/install-deps --bench  # strace
cmake --preset release >/dev/null
cmake --build build/release -j"$(nproc)" --target superball scale_costs codec_speed core_wait >/dev/null
if [[ $(id -u) -eq 0 ]]; then export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1; fi
superball=$root/build/release/src/superball
scale_costs=$root/build/release/tests/scale/scale_costs
out=$root/build/scale/validate
mkdir -p "$out"
tests/scale/build_sim_run.sh "$root/build/scale/sim_run"
# shellcheck source=calibration.env
source tests/scale/calibration.env

# The cases: a job file and the rank counts it runs at.
cat >"$out/zoom.toml" <<EOF
[model]
e = 0.9999
alpha = 0.9999
[grid]
coordinates = "canonical"
xi = { min = 0.0, max = 0.01, n = 96 }
U = { min = -3.0, max = 0.0, n = 64 }
W = { min = -6.0, max = 3.0, n = 64 }
[run]
max_bounces = 20000
output = "$out/zoom.h5"
EOF
cat >"$out/trivial.toml" <<EOF
[model]
e = 0.9
alpha = 0.9
[grid]
coordinates = "canonical"
xi = { min = 1.0, max = 2.0, n = 8192 }
U = -1.0
W = { min = -3.0, max = 3.0, n = 8192 }
[run]
max_bounces = 1000
output = "$out/trivial.h5"
tile_points = 1024
EOF
cases=("jobs/full/volume.toml:1 2" "$out/zoom.toml:1 2 4" "$out/trivial.toml:2 4 8")
[[ -n $oversubscribed ]] && cases=("$out/zoom.toml:$oversubscribed")
node_ranks=16

computed() {  # compute-phase seconds of real runs, the median of REPS: JOB RANKS
  tests/scale/computed.sh "$superball" "$1" "$reps" "$2" "$out/real.h5"
}
compression_of() { sed -n 's/.* compression=\([0-9]*\).*/\1/p' <<<"$1"; }  # scale_costs' LINE
# SMPI's settings for every simulation here.
smpi_cfg=(--cfg=smpi/host-speed:1Gf --cfg=smpi/simulate-computation:no --cfg=smpi/privatization:no --cfg=smpi/iprobe:0
          --cfg=smpi/test:0 --cfg=smpi/grow-injected-times:no --cfg=smpi/async-small-thresh:65536)
# sim_run's write options in the array `write`: each tile's compression charged as
# simulate.sh charges it (CODEC: codec_speed's line; 650 MB/s without one) and payloads of
# the size the real result RESULT stored; --uncompressed where scale_costs' LINE says so.
# RESULT LINE CODEC
sim_write_args() {
  write=(--compress-mbps "$(/usr/bin/python3 -c '
import re, sys
m = re.search(r"raw_bytes=(\d+) seconds=(\S+)", sys.argv[1])
print(f"{int(m.group(1)) / float(m.group(2)) / 1e6:.0f}" if m else 650)' "$3")" --compress-ratio "$(/usr/bin/python3 -c '
import sys, h5py
with h5py.File(sys.argv[1]) as f:
    d = [f["wall_bounces"], f["outcome"]]
    print(sum(x.size * x.dtype.itemsize for x in d) / sum(x.id.get_storage_size() for x in d))' "$1")")
  [[ $(compression_of "$2") == 0 ]] && write=(--uncompressed)
  return 0
}
predicted() {  # schedule_s of the simulation: NAME JOB RANKS NS_PER_ITERATION
  local line granule write codec
  line=$("$scale_costs" "$2" "$3" "$out/$1.low.h5" "$NS_PER_POINT" "$4" "$US_PER_TILE" "$out/$1.$3.bin")
  granule=$(sed -n 's/.* granule=\([0-9]*\) .*/\1/p' <<<"$line")
  # The payloads of the size the last real run at this rank count stored ($out/real.h5).
  codec=$("$root/build/release/tests/scale/codec_speed" "$out/real.h5" "$(compression_of "$line")" 2>/dev/null || true)
  sim_write_args "$out/real.h5" "$line" "$codec"
  echo "node-0:$3" >"$out/hosts"
  smpirun -np "$3" -platform tests/scale/local.xml -hostfile "$out/hosts" "$root/build/scale/sim_run" "$out/$1.$3.bin" \
    --node-ranks "$3" --granule "$granule" "${write[@]}" --no-io "${smpi_cfg[@]}" 2>"$out/$1.$3.log" |
    sed -n 's/.* schedule_s=\([^ ]*\).*/\1/p'
  rm -f "$out/$1.$3.bin"
}

# The real runs' counts (medians of REPS runs) against the simulation's, one
# line each: NAME JOB RANKS NS_PER_ITERATION.
compare_counts() {
  local name=$1 job=$2 n=$3 ns=$4 r line granule codec write writes wait_s
  # The schedule's counts from REPS plain runs; the write calls from one more under strace
  # (which stops the process at every write: no timing of it is kept).
  : >"$out/$name.$n.real"
  for ((r = 0; r < reps; r++)); do
    mpirun -n "$n" --oversubscribe "$superball" explore "$job" -o "$out/$name.real.h5" --overwrite -q --stats \
      --node-ranks "$node_ranks" 2>&1 | sed -n 's/^schedule: //p' >>"$out/$name.$n.real"
  done
  writes=$(tests/scale/write_calls.sh "$out/$name.real" -- mpirun -n "$n" --oversubscribe "$superball" explore "$job" \
    -o "$out/$name.real.h5" --overwrite -q --node-ranks "$node_ranks" 2>"$out/$name.$n.strace.log")
  sed -i "s/\$/ $writes/" "$out/$name.$n.real"
  line=$("$scale_costs" "$job" "$n" "$out/$name.low.h5" "$NS_PER_POINT" "$ns" "$US_PER_TILE" "$out/$name.$n.bin")
  granule=$(sed -n 's/.* granule=\([0-9]*\) .*/\1/p' <<<"$line")
  codec=$("$root/build/release/tests/scale/codec_speed" "$out/$name.real.h5" "$(compression_of "$line")")
  sim_write_args "$out/$name.real.h5" "$line" "$codec"
  # The platform of the real runs: this machine, where a write (by a thread of its own, the
  # appender's) first waits for a core that n - 1 counting ranks share.
  wait_s=$("$root/build/release/tests/scale/core_wait" $((n - 1)) | sed -n 's/^core_wait_s=//p')
  sed "s|<prop id=\"op_latency\" value=\"[^\"]*\"/>|<prop id=\"op_latency\" value=\"$wait_s\"/>|" tests/scale/local.xml >"$out/local.$n.xml"
  echo "node-0:$n" >"$out/hosts"
  smpirun -np "$n" -platform "$out/local.$n.xml" -hostfile "$out/hosts" "$root/build/scale/sim_run" "$out/$name.$n.bin" \
    --node-ranks "$node_ranks" --granule "$granule" --startup-seconds 0 --serve-every 1e-9 --server-serve-every 1e-9 \
    "${write[@]}" --index-us-per-tile "$INDEX_US_PER_TILE" --copy-gbps "$COPY_GBPS" "${smpi_cfg[@]}" \
    >"$out/$name.$n.sim" 2>"$out/$name.$n.log"
  rm -f "$out/$name.$n.bin"
  echo "ranks=$n a write's wait for a core (core_wait $((n - 1))): $wait_s s" >&2
  /usr/bin/python3 tests/scale/compare_counts.py "$n" "$out/$name.$n.real" "$out/$name.$n.sim"
}

status=0
for c in "${cases[@]}"; do
  job=${c%%:*}
  name=$(basename "$job" .toml)
  # The cost model's sample: the job at half the resolution along each axis.
  /usr/bin/python3 tests/scale/lowres_job.py "$job" "$out/$name.low.toml" "$out/$name.low.h5" \
    --points "$(( $("$superball" explore "$job" --dry-run | sed -n 's/^points: //p') / 8 ))"
  # Computed at -n 1: its compute time gives the job's cost per wall bounce, as in simulate.sh.
  seconds=$(computed "$out/$name.low.toml" 1 2>/dev/null)
  mv "$out/real.h5" "$out/$name.low.h5"
  tiles=$("$superball" explore "$out/$name.low.toml" --dry-run | sed -n 's/^tiles: \([0-9]*\) .*/\1/p')
  read -r ns_per_iteration < <(/usr/bin/python3 tests/scale/sample_model.py "$out/$name.low.h5" "$seconds" "$tiles" \
    "$NS_PER_POINT" "$US_PER_TILE" "$NS_PER_ITERATION")
  for n in ${c#*:}; do
    if [[ -n $oversubscribed ]]; then
      compare_counts "$name" "$job" "$n" "$ns_per_iteration" || status=1
      continue
    fi
    real=$(computed "$job" "$n" 2>"$out/$name.$n.real")
    model=$(predicted "$name" "$job" "$n" "$ns_per_iteration")
    /usr/bin/python3 -c "print(f'job=$name ranks=$n real_s=$real predicted_s={$model:.3f} error={($model - $real) / $real:+.1%}  ($(sed 's/computed.sh: /real runs: /' "$out/$name.$n.real"); sample {$seconds} s; ns_per_iteration=$ns_per_iteration)')"
  done
done
exit $status
