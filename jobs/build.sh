#!/usr/bin/env bash
# Installs what is missing and builds superball for this machine, once: the build step of
# jobs/local.sh and jobs/bifurcation.sh. Prints the path of the binary.
#
#   jobs/build.sh            build/native (optimised for this host's instruction set)
#
# Environment: SUPERBALL_BUILD (build directory, default build/native). A new build tree
# is configured for Ninja (installed by .ci/install-deps): it compiles the libraries side by
# side where Make builds them one after the other (docs/building.md); a tree configured
# before keeps its generator.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
"$root/.ci/install-deps" >&2  # its apt output is not the path this prints
build=${SUPERBALL_BUILD:-$root/build/native}
if [[ ! -f "$build/CMakeCache.txt" ]]; then
  generator=()
  command -v ninja >/dev/null && generator=(-G Ninja)
  cmake -S "$root" -B "$build" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release -DSUPERBALL_NATIVE=ON \
        -DSUPERBALL_TESTS=OFF -DSUPERBALL_BENCHMARKS=OFF >/dev/null
fi
cmake --build "$build" -j"$(nproc)" --target superball >/dev/null
echo "$build/src/superball"
