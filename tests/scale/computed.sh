#!/usr/bin/env bash
# The compute phase of `superball explore` ("computed in"), in seconds: the median of RUNS
# runs (default 3) at RANKS ranks (default 1), writing OUTPUT (default: the job's, replaced).
# A single run of a short job on this shared machine varies by +-25 % (a 0.13 s sample once
# took 0.18 s, and the cost model scaled that up eightfold).
#
#   tests/scale/computed.sh SUPERBALL JOB [RUNS] [RANKS] [OUTPUT]
set -euo pipefail
superball=$1 job=$2 runs=${3:-3} ranks=${4:-1} output=${5:-}
if [[ $(id -u) -eq 0 ]]; then export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1; fi
times=()
for ((r = 0; r < runs; r++)); do
  # "N points computed in T s (R points/s)": N / R, to 3 digits (T has 2 decimals only:
  # 8 % of a 0.12 s sample).
  t=$(mpirun -n "$ranks" --oversubscribe "$superball" explore "$job" ${output:+-o "$output"} --overwrite -q 2>&1 |
    sed -n 's/.* \([0-9]*\) points computed in [0-9.]* s (\([0-9.e+-]*\) points\/s).*/\1 \2/p' |
    awk '{ printf "%.4g\n", $1 / $2 }')
  [[ -n $t ]] || { echo "computed.sh: $superball explore $job failed" >&2; exit 1; }
  times+=("$t")
done
echo "computed.sh: ${times[*]}" >&2
printf '%s\n' "${times[@]}" | sort -g | sed -n "$(((runs + 1) / 2))p"
