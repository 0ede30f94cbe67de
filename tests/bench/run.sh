#!/usr/bin/env bash
# The speed benchmark of issue 4, in one go on this machine: the scalar and vectorised
# counting kernels alone, then `superball explore` end to end at 1 and 2 ranks, on the
# slice U = -1, xi in (0, 1), W in [-3, 3], e = alpha = 0.9, max_bounces 1000, 4096^2
# points; peak memory per rank at 4096^2 and 16384^2. Prints a table (markdown) with
# each figure's ratio to the scalar kernel.
#
#   tests/bench/run.sh            (builds the `native` preset: -march=native)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
cd "$root"
.ci/install-deps
cmake --preset native >/dev/null
cmake --build --preset native -j"$(nproc)" --target superball bench_kernel >/dev/null
if [[ $(id -u) -eq 0 ]]; then export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1; fi
python=/usr/bin/python3
[[ -x $python ]] || python=python3
exec "$python" tests/bench/run_benchmarks.py --build build/native "$@"
