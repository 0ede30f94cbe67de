#!/usr/bin/env bash
# Builds sim_run (the real schedule under SimGrid's SMPI, tests/scale/sim_run.cpp) with
# smpicxx at PATH when it is missing or older than its sources; nothing otherwise.
#
#   tests/scale/build_sim_run.sh PATH
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
target=$1
sources=("$root/tests/scale/sim_run.cpp" "$root/src/run/schedule.cpp" "$root/src/run/work_pool.cpp" "$root/src/mpi/mpi.cpp")
headers=("$root/src/run/schedule.hpp" "$root/src/run/work_pool.hpp" "$root/src/mpi/mpi.hpp" "$root/src/job/tiles.hpp")
if [[ -x $target ]] && [[ -z $(find "${sources[@]}" "${headers[@]}" -newer "$target") ]]; then exit 0; fi
mkdir -p "$(dirname "$target")"
smpicxx -std=c++20 -O2 -Wall -Wextra -Werror -ffp-contract=off -I"$root/src" "${sources[@]}" -o "$target"
