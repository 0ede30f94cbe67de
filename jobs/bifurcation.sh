#!/usr/bin/env bash
# Draws a bifurcation diagram on this machine: builds if needed, runs `superball continue`
# with one MPI rank per core (the branches are shared among them), then the figure.
#
#   jobs/bifurcation.sh                      the README example: the fixed points of e = 0.9
#                                            (interior and corner plane) over alpha in
#                                            [0.95, 1], into results/bifurcation_e0.9_alpha.*
#   jobs/bifurcation.sh NAME OPTIONS...      superball continue OPTIONS into results/NAME.csv
#
# Writes NAME.csv (superball continue's CSV), NAME.png and NAME.pdf (analysis/bifurcation_plot.py
# --y U,moduli). Environment: SUPERBALL_RANKS (default: number of cores), SUPERBALL_RESULTS
# (folder, default results), SUPERBALL (the binary; default: build build/native as local.sh does).
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
root=$(dirname "$here")
if [[ "${1:-}" == -h || "${1:-}" == --help ]]; then
  sed -n '2,12p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'
  exit 0
fi
if [[ $# -eq 0 ]]; then
  set -- bifurcation_e0.9_alpha --e 0.9 --alpha 0.99 --param alpha --min 0.95 --max 1 --corner --max-step 0.005
elif [[ $# -eq 1 || "$1" == -* ]]; then
  echo "bifurcation.sh: give NAME and the options of superball continue, or nothing (see --help)" >&2
  exit 2
fi
name=$1; shift

binary=${SUPERBALL:-}
if [[ -z "$binary" ]]; then
  binary=$(SUPERBALL_BUILD=$root/build/native "$root/jobs/build.sh")
fi

ranks=${SUPERBALL_RANKS:-$(nproc)}
mpi_flags=()
# Open MPI refuses to run as root unless told; only root needs this.
if [[ $(id -u) -eq 0 ]]; then export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1; fi
(( ranks > $(nproc) )) && mpi_flags+=(--oversubscribe)

results=${SUPERBALL_RESULTS:-results}
mkdir -p "$results"
csv=$results/$name.csv
mpirun -n "$ranks" "${mpi_flags[@]}" "$binary" continue "$@" --format csv -o "$csv"
echo "branches: $csv"

python=/usr/bin/python3
[[ -x $python ]] || python=python3
"$python" "$root/analysis/bifurcation_plot.py" "$csv" --y U,moduli -o "$results/$name.png" | sed 's/^/figure: /'
