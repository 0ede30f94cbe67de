#!/usr/bin/env bash
# Builds the two libFuzzer targets with clang (AddressSanitizer + UndefinedBehaviorSanitizer,
# every report fatal) and fuzzes each for half the time given, from its seed corpus (side by
# side on two cores or more, so in half the time; one after the other on one):
#
#   fuzz_job     the job-file parser and validator (seeds: tests/fuzz/corpus and every job
#                file in jobs/)
#   fuzz_result  the file validator, ResultReader: inputs are edits applied to small valid
#                result and partial files (fuzz_result.cpp; seeds: tests/fuzz/result_corpus)
#
#   tests/fuzz/run.sh [SECONDS]          default 60 in all; 0 only builds and replays the seeds
#
# Exit status non-zero on a finding; the reproducer is left in build/fuzz/ (replay it with
# build/fuzz/fuzz_job FILE or build/fuzz/fuzz_result FILE). Needs clang and
# libclang-rt-14-dev (.ci/install-deps --dev).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
seconds=${1:-60}
out=$root/build/fuzz
mkdir -p "$out"
cxx=${CLANGXX:-clang++}
command -v "$cxx" >/dev/null || { echo "fuzz: $cxx not found: run .ci/install-deps --dev" >&2; exit 1; }

# What parse_job needs: the job layer and the model input checks. toml++ is compiled
# header-only so that the TOML parser is instrumented and fuzzed too.
job_sources=(src/job/job.cpp src/job/job_parse.cpp src/job/spelling.cpp src/core/input.cpp)
# What ResultReader needs, and the writers of its templates: what links, no more (core's
# count.cpp for the kernel grid.cpp names on a boundary plane; core/dynamics.cpp, the fixed
# points' Eigen solvers, once listed here, was 40 of the build's 94 CPU-seconds and linked to
# nothing). HDF5 itself is Debian's, not instrumented: coverage guides the fuzzer through our
# validation, not HDF5's parser.
result_sources=(src/io/result_reader.cpp src/io/result_schema.cpp src/io/file_identity.cpp src/io/hdf5.cpp src/io/layout.cpp src/io/partial_file.cpp src/io/posix_file.cpp src/io/page_buffer.cpp src/io/placed_chunks.cpp
                src/io/chunk_codec.cpp src/io/stored_tiles.cpp src/job/provenance.cpp "$out/generated/git_revision.cpp"
                src/io/result_metadata.cpp src/mpi/mpi.cpp src/job/grid.cpp src/job/tiles.cpp src/core/count.cpp)
# toml_assert.hpp: see there (toml++ 3.3.0 preconditions on the current character are
# passed over, as in release). -fno-sanitize=unreachable: toml++ 3.3.0's
# is_non_ascii_horizontal_whitespace() reaches TOML_UNREACHABLE for some non-ASCII
# characters after a value (e.g. "max_bounces = 1\u00e9"; marzer/tomlplusplus#190 and
# #295, fixed upstream by #305 after 3.3.0). The code Debian compiled from it reports a
# syntax error (tests/hardening/test_faults.py checks the shipped binary does); src/ has
# no __builtin_unreachable of its own, so no other check is lost.
flags=(-std=c++20 -g -O1 -fno-omit-frame-pointer -ffp-contract=off -DTOML_HEADER_ONLY=1 -I"$root/src"
       -include "$root/tests/fuzz/toml_assert.hpp"
       -fsanitize=fuzzer,address,undefined -fno-sanitize=unreachable -fno-sanitize-recover=all
       '-DSUPERBALL_BUILD_DESCRIPTION="fuzz build"')

# The version header CMake generates, for the result writers.
version=$(sed -n 's/^project(superball VERSION \([0-9.]*\).*/\1/p' "$root/CMakeLists.txt")
mkdir -p "$out/generated/superball"
sed "s/@PROJECT_VERSION@/$version/" "$root/src/version.hpp.in" >"$out/generated/superball/version.hpp.tmp"
cmp -s "$out/generated/superball/version.hpp.tmp" "$out/generated/superball/version.hpp" ||
  mv "$out/generated/superball/version.hpp.tmp" "$out/generated/superball/version.hpp"
rm -f "$out/generated/superball/version.hpp.tmp"
# The git commit the provenance attributes name (job/provenance.hpp), as the CMake build records it.
cmake -DSOURCE_DIR="$root" -DOUTPUT="$out/generated/git_revision.cpp" -P "$root/cmake/git_revision.cmake"
# shellcheck disable=SC2207
hdf5=($(pkg-config --cflags hdf5-openmpi libxxhash) -I/usr/include/eigen3 -I"$out/generated")
hdf5_libs=($(pkg-config --libs hdf5-openmpi libxxhash libdeflate) -lhdf5_hl -lfmt $(mpicxx --showme:link))

# Both targets are rebuilt when a file of src/, tests/fuzz/ (this script too) or generated/
# is newer than the last build. The sources are compiled in a few units, each a file that
# includes a group of them (as CMake's unity build does for the libraries: the headers they
# share are read once a unit), as many units at once as there are cores (one clang++ call
# for all of a target's sources ran on one core: 130 s of the CI stage on two); each target
# is linked from the units it needs. (`tests/fuzz/run.sh 0` from nothing: 73 s in units, 105 s file
# by file, one core free, 2026-11-29; without core/dynamics.cpp 94 CPU-seconds became 68, the
# build 52 s then 55 s, each time beside other work.)
units=$out/units
mkdir -p "$units"
# unit NAME SOURCE...: writes $units/NAME.cpp including the sources (kept as it is when
# unchanged) and prints its path.
unit() {
  local name=$1 source; shift
  for source in "$@"; do [[ $source == /* ]] || source=$root/$source; echo "#include \"$source\""; done >"$units/$name.cpp.tmp"
  if cmp -s "$units/$name.cpp.tmp" "$units/$name.cpp"; then rm "$units/$name.cpp.tmp"; else mv "$units/$name.cpp.tmp" "$units/$name.cpp"; fi
  echo "$units/$name.cpp"
}
job_units=("$(unit job "${job_sources[@]}")")
result_units=("$(unit result_a "${result_sources[@]:0:6}")" "$(unit result_b "${result_sources[@]:6:7}")"
              "$(unit result_c "${result_sources[@]:13}")")
objects=$out/objects
object() { local name=${1#"$out/"}; echo "$objects/${name//\//_}.o"; }
compile() { (cd "$root" && "$cxx" "${flags[@]}" "${hdf5[@]}" -c "$1" -o "$2.tmp") && mv "$2.tmp" "$2"; }
link() {
  local name=$1; shift
  local inputs=() source
  for source in "$@"; do inputs+=("$(object "$source")"); done
  "$cxx" "${flags[@]}" "${inputs[@]}" "${hdf5_libs[@]}" -o "$out/$name.tmp" && mv "$out/$name.tmp" "$out/$name"
}
stamp=$out/fuzz.stamp
if [[ ! -x $out/fuzz_job || ! -x $out/fuzz_result || ! -f $stamp ]] ||
   [[ -n $(cd "$root" && find src tests/fuzz "$out/generated" -type f -newer "$stamp" -print -quit) ]]; then
  cores=$(nproc)
  echo "fuzz: building $out/fuzz_job and $out/fuzz_result ($cores compilations at once)" >&2
  mkdir -p "$objects"
  running=0 failed=0
  for source in "${result_units[@]}" tests/fuzz/fuzz_job.cpp tests/fuzz/fuzz_result.cpp "${job_units[@]}"; do
    if ((running >= cores)); then wait -n || failed=1; running=$((running - 1)); fi
    compile "$source" "$(object "$source")" &
    running=$((running + 1))
  done
  while ((running > 0)); do wait -n || failed=1; running=$((running - 1)); done
  ((failed == 0)) || { echo "fuzz: a compilation failed (above)" >&2; exit 1; }
  link fuzz_job tests/fuzz/fuzz_job.cpp "${job_units[@]}"
  link fuzz_result tests/fuzz/fuzz_result.cpp "${result_units[@]}" "${job_units[@]}"
  touch "$stamp"
fi

# libFuzzer writes new inputs into the first corpus directory: scratch copies, so the
# checked-in seeds stay as they are.
rm -rf "$out/corpus" "$out/result_corpus"
mkdir -p "$out/corpus" "$out/result_corpus"
cp "$root"/tests/fuzz/corpus/* "$out/corpus"/
find "$root/jobs" -name '*.toml' -exec cp {} "$out/corpus"/ \;
cp "$root"/tests/fuzz/result_corpus/* "$out/result_corpus"/

export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=0}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
# The result target's templates are parallel HDF5's files, written without MPI started.
if [[ $(id -u) -eq 0 ]]; then export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1; fi
if ((seconds == 0)); then
  "$out/fuzz_job" -runs=0 "$out/corpus"
  exec "$out/fuzz_result" -runs=0 "$out/result_corpus"
fi
half=$(((seconds + 1) / 2))
fuzz_job() {
  echo "fuzz: fuzzing parse_job for ${half} s" >&2
  "$out/fuzz_job" "$out/corpus" -dict="$root/tests/fuzz/toml.dict" -max_total_time="$half" -max_len=8192 \
    -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix="$out/" -close_fd_mask=1
}
fuzz_result() {
  echo "fuzz: fuzzing ResultReader for $((seconds - half)) s" >&2
  "$out/fuzz_result" "$out/result_corpus" -max_total_time="$((seconds - half))" -max_len=128 -len_control=0 \
    -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix="$out/" -close_fd_mask=1
}
if (($(nproc) < 2)); then
  fuzz_job
  fuzz_result
  exit
fi
# Side by side, each into a log of its own, printed whole once both have ended.
fuzz_job >"$out/fuzz_job.log" 2>&1 &
job=$!
status=0
fuzz_result >"$out/fuzz_result.log" 2>&1 || status=1
wait "$job" || status=1
cat "$out/fuzz_job.log" "$out/fuzz_result.log" >&2
exit $status
