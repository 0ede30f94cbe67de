#!/usr/bin/env bash
# Runs a job on this machine: installs what is missing, builds if needed, explores with
# one MPI rank per core, then draws the region map next to the result.
#
#   jobs/local.sh JOB.toml [superball explore options...]     e.g. --overwrite, --resume
#
# Environment: SUPERBALL_RANKS (default: number of cores), SUPERBALL_BUILD (build
# directory, default build/native: optimised for this host's instruction set). On one
# node superball asks Open MPI for its shared-memory layer (ob1) itself, unless
# OMPI_MCA_pml is set (docs/running.md: Start-up on one node).
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
root=$(dirname "$here")
if [[ $# -lt 1 || "$1" == -h || "$1" == --help ]]; then
  sed -n '2,10p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'
  exit $(( $# < 1 ? 2 : 0 ))
fi
job=$1; shift
[[ -f "$job" ]] || { echo "local.sh: no job file $job" >&2; exit 2; }

superball=$("$here/build.sh")

ranks=${SUPERBALL_RANKS:-$(nproc)}
mpi_flags=()
# Open MPI refuses to run as root unless told; only root needs this.
if [[ $(id -u) -eq 0 ]]; then export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1; fi
(( ranks > $(nproc) )) && mpi_flags+=(--oversubscribe)

# Checks the job before starting ranks, and learns where the result goes.
output=$("$superball" explore "$job" "$@" --dry-run | sed -n 's/^output: \(.*\)$/\1/p')

mpirun -n "$ranks" "${mpi_flags[@]}" "$superball" explore "$job" "$@"

python=/usr/bin/python3
[[ -x $python ]] || python=python3
if [[ -n "$output" && -f "$root/analysis/region_map.py" ]]; then
  # A 3-D (or 4-D) result is drawn at the middle of its leading axes; region_map.py
  # --slice draws any other slice.
  slices=$("$python" -c '
import sys, h5py
with h5py.File(sys.argv[1], "r") as f:
    names, shape = list(f.attrs["axis_names"]), f["wall_bounces"].shape
print(" ".join(f"--slice {n}={s // 2}" for n, s in zip(names, shape[:max(len(shape) - 2, 0)])))' "$output")
  # shellcheck disable=SC2086  # $slices is a list of options
  "$python" "$root/analysis/region_map.py" "$output" $slices --outcome -o "${output%.h5}.png"
  echo "figure: ${output%.h5}.png"
fi
