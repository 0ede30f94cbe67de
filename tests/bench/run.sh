#!/usr/bin/env bash
# The speed benchmarks, in one go on this machine (tests/bench/run_benchmarks.py): the
# scalar kernel and every variant of the vectorised kernel alone, `superball explore` end
# to end at 1 and 2 ranks (the whole process against its compute phase and against the
# scalar kernel in a plain loop), the closing pass at 4096^2 to 16384^2 and on a
# 4096 x 4096 x 16 volume, the portable binary against a -march=native build, the cost of
# a tile, the write calls to the result file, the start-up of a small job, peak memory at
# 16384^2, result sizes (against another build's with --baseline) and refinement; on the
# slice U = -1, xi in (0, 1), W in [-3, 3], e = alpha = 0.9, max_bounces 1000. Prints
# markdown tables naming the kernel variant and instruction set of each build. Every
# figure is a median of interleaved repetitions.
#
#   tests/bench/run.sh [--quick] [--repetitions N] [--skip-16384] [--baseline SUPERBALL]
#
# Works on whatever build trees are there: build/release (portable, as tests/all leaves
# it) and build/native (-march=native, as jobs/local.sh leaves it) are configured with
# their presets when missing, SUPERBALL_BENCHMARKS is turned on where it is off, and only
# the superball and bench_kernel targets are built, one tree after the other.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
cd "$root"
.ci/install-deps --bench

prepare() {  # build directory, preset that makes it
  local dir=$1 preset=$2
  if [[ -f $dir/CMakeCache.txt ]]; then
    cmake -S "$root" -B "$dir" -DSUPERBALL_BENCHMARKS=ON >/dev/null
  else
    cmake --preset "$preset" -DSUPERBALL_BENCHMARKS=ON >/dev/null
  fi
  cmake --build "$dir" -j"$(nproc)" --target superball bench_kernel >/dev/null
}
prepare build/release release
prepare build/native native

if [[ $(id -u) -eq 0 ]]; then export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1; fi
python=/usr/bin/python3
[[ -x $python ]] || python=python3
exec "$python" tests/bench/run_benchmarks.py --portable build/release --native build/native "$@"
