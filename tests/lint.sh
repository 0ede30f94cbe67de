#!/usr/bin/env bash
# Static analysis of src/ with its checked-in configuration: cppcheck (tests/lint/
# cppcheck.supp: each suppression says why) and clang-tidy (.clang-tidy: each check left
# out says why), file by file, with the compile commands of build/lint (configured here, not
# built; SUPERBALL_BUILD_DIR picks another build tree configured with -DCMAKE_UNITY_BUILD=OFF).
# Not in the batches the builds compile (CMake's unity build): file by file, clang-tidy also
# checks that each file compiles on its own, with its own includes, which nothing else does
# once the builds compile batches. (In batches, clang-tidy took 175 s where file by file took
# 383, one core free, 2026-11-29.) Exits non-zero on any finding.
#
#   tests/lint.sh                cppcheck (seconds) and clang-tidy with every check of .clang-tidy
#                                (6 minutes on 2 cores)
#   tests/lint.sh --no-analyzer  the same without clang-analyzer-* (about 5 minutes)
#   tests/lint.sh --ci           the same without clang-analyzer-*, performance-unnecessary-value-param
#                                and bugprone-reserved-identifier (what tests/all runs)
#   tests/lint.sh --quick        cppcheck only (seconds)
#
# Why --ci leaves those three out (clang-tidy 14 runs every check over the whole AST, headers
# included, and reports only src/'s findings): the static analyzer is 5/6 of the full run;
# performance-unnecessary-value-param took 13.3 of the 34 s that src/cli/fixed_points_command.cpp
# took with the others (it visits every template instantiation of CLI11, nlohmann-json and
# fmt), bugprone-reserved-identifier 3.0 s for 33,000 warnings on the standard library's own
# names, all suppressed (clang-tidy --enable-check-profile, 2026-11-27). src/ passes all three.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
quick=0
checks=()
case ${1:-} in
  --quick) quick=1 ;;
  --no-analyzer) checks=(-checks=-clang-analyzer-*) ;;
  --ci) checks=(-checks=-clang-analyzer-*,-performance-unnecessary-value-param,-bugprone-reserved-identifier) ;;
  "") ;;
  *) echo "lint: unknown option $1 (accepted: --quick, --no-analyzer, --ci)" >&2; exit 2 ;;
esac
build=${SUPERBALL_BUILD_DIR:-$root/build/lint}
if [[ -z ${SUPERBALL_BUILD_DIR:-} ]]; then
  # Configuring only (seconds): version.hpp, the one generated header src/ includes, is
  # written at configure time.
  cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release -DCMAKE_UNITY_BUILD=OFF -DSUPERBALL_TESTS=OFF \
    -DSUPERBALL_BENCHMARKS=OFF >/dev/null
elif [[ ! -f $build/compile_commands.json ]]; then
  echo "lint: no $build/compile_commands.json: configure that build first" >&2
  exit 1
fi

# The compile commands of src/ only (not the tests, not the benchmarks).
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
/usr/bin/python3 - "$build/compile_commands.json" "$work/compile_commands.json" "$root/src/" <<'PY'
import json, sys
entries = json.load(open(sys.argv[1]))
if any("/Unity/unity_" in e["file"] for e in entries):
    sys.exit(f"lint: {sys.argv[1]} compiles files in batches (unity build): configure with -DCMAKE_UNITY_BUILD=OFF")
entries = [e for e in entries if e["file"].startswith(sys.argv[3])]
if not entries:
    sys.exit(f"lint: no source of {sys.argv[3]} in {sys.argv[1]}")
json.dump(entries, open(sys.argv[2], "w"), indent=1)
PY

status=0
echo "lint: cppcheck" >&2
cppcheck --project="$work/compile_commands.json" --std=c++20 --enable=warning,performance,portability \
  --suppress=missingIncludeSystem --suppressions-list="$root/tests/lint/cppcheck.supp" --inline-suppr \
  --error-exitcode=1 --quiet -j"$(nproc)" || status=1

if ((quick == 0)); then
  echo "lint: clang-tidy" >&2
  tidy=$(command -v run-clang-tidy-14 || command -v run-clang-tidy || true)
  [[ -n $tidy ]] || { echo "lint: run-clang-tidy not found: apt-get install clang-tidy" >&2; exit 1; }
  "$tidy" -p "$work" -j "$(nproc)" -quiet "${checks[@]}" "$root/src/" >"$work/tidy.log" 2>&1 || true
  if grep -qE "(warning|error): " "$work/tidy.log"; then
    grep -E "(warning|error): " "$work/tidy.log" | sed 's/\x1b\[[0-9;]*m//g' | sort -u >&2
    status=1
  fi
fi
((status == 0)) && echo "lint: no findings" >&2
exit $status
