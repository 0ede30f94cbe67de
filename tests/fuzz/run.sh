#!/usr/bin/env bash
# Builds the libFuzzer target for the job-file parser and validator with clang
# (AddressSanitizer + UndefinedBehaviorSanitizer, every report fatal) and fuzzes it for
# a bounded time from the seed corpus (tests/fuzz/corpus and every job file in jobs/).
#
#   tests/fuzz/run.sh [SECONDS]          default 60; 0 only builds and replays the seeds
#
# Exit status non-zero on a finding; the reproducer is left in build/fuzz/ (replay it with
# build/fuzz/fuzz_job FILE). Needs clang and libclang-rt-14-dev (.ci/install-deps --dev).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
seconds=${1:-60}
out=$root/build/fuzz
mkdir -p "$out"
cxx=${CLANGXX:-clang++}
command -v "$cxx" >/dev/null || { echo "fuzz: $cxx not found: run .ci/install-deps --dev" >&2; exit 1; }

# What parse_job needs: the job layer and the model input checks. toml++ is compiled
# header-only so that the TOML parser is instrumented and fuzzed too.
sources=(tests/fuzz/fuzz_job.cpp src/job/job.cpp src/job/job_parse.cpp src/job/spelling.cpp src/core/input.cpp)
# toml_assert.hpp: see there (toml++ 3.3.0 preconditions on the current character are
# passed over, as in release). -fno-sanitize=unreachable: toml++ 3.3.0's
# is_non_ascii_horizontal_whitespace() reaches TOML_UNREACHABLE for some non-ASCII
# characters after a value (e.g. "max_bounces = 1\u00e9"; marzer/tomlplusplus#190 and
# #295, fixed upstream by #305 after 3.3.0). The code Debian compiled from it reports a
# syntax error (tests/hardening/test_faults.py checks the shipped binary does); src/ has
# no __builtin_unreachable of its own, so no other check is lost.
flags=(-std=c++20 -g -O1 -fno-omit-frame-pointer -ffp-contract=off -DTOML_HEADER_ONLY=1 -I"$root/src"
       -include "$root/tests/fuzz/toml_assert.hpp"
       -fsanitize=fuzzer,address,undefined -fno-sanitize=unreachable -fno-sanitize-recover=all)
stamp=$out/fuzz_job.stamp
if [[ ! -x $out/fuzz_job ]] || [[ -n $(cd "$root" && find "${sources[@]}" src/job/job.hpp src/job/spelling.hpp src/core/input.hpp \
      src/core/model.hpp src/core/state.hpp tests/fuzz/toml_assert.hpp tests/fuzz/run.sh -newer "$stamp" 2>/dev/null) ]]; then
  echo "fuzz: building $out/fuzz_job" >&2
  (cd "$root" && "$cxx" "${flags[@]}" "${sources[@]}" -o "$out/fuzz_job.tmp")
  mv "$out/fuzz_job.tmp" "$out/fuzz_job"
  touch "$stamp"
fi

# libFuzzer writes new inputs into the first corpus directory: a scratch copy, so the
# checked-in seeds stay as they are.
work=$out/corpus
rm -rf "$work"
mkdir -p "$work"
cp "$root"/tests/fuzz/corpus/* "$work"/
find "$root/jobs" -name '*.toml' -exec cp {} "$work"/ \;

export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=0}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
if ((seconds == 0)); then
  exec "$out/fuzz_job" -runs=0 "$work"
fi
echo "fuzz: fuzzing parse_job for ${seconds} s" >&2
exec "$out/fuzz_job" "$work" -dict="$root/tests/fuzz/toml.dict" -max_total_time="$seconds" -max_len=8192 \
  -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix="$out/" -close_fd_mask=1
