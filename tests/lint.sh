#!/usr/bin/env bash
# Static analysis of src/ with its checked-in configuration: cppcheck (tests/lint/
# cppcheck.supp: each suppression says why) and clang-tidy (.clang-tidy: each check left
# out says why), with the compile commands of build/lint (configured here, not built;
# SUPERBALL_BUILD_DIR picks another build tree configured with -DCMAKE_UNITY_BUILD=OFF).
# cppcheck and clang-tidy read the sources file by file, which also checks that each file
# compiles on its own, with its own includes (the builds compile batches: CMake's unity
# build). --ci runs clang-tidy on those batches instead (build/lint-batches), in 175 s where
# file by file took 383 (one core, 2026-11-29): the same checks of the same code, but a file
# that compiles only after another of its batch is no longer found there (the full run finds
# it). Exits non-zero on any finding.
#
#   tests/lint.sh                cppcheck (seconds) and clang-tidy with every check of .clang-tidy
#                                (6 minutes on 2 cores)
#   tests/lint.sh --no-analyzer  the same without clang-analyzer-* (about 5 minutes)
#   tests/lint.sh --ci           the same without clang-analyzer-*, performance-unnecessary-value-param
#                                and bugprone-reserved-identifier, clang-tidy on the batches (what
#                                tests/all runs)
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
ci=0
checks=()
case ${1:-} in
  --quick) quick=1 ;;
  --no-analyzer) checks=(-checks=-clang-analyzer-*) ;;
  --ci) ci=1; checks=(-checks=-clang-analyzer-*,-performance-unnecessary-value-param,-bugprone-reserved-identifier) ;;
  "") ;;
  *) echo "lint: unknown option $1 (accepted: --quick, --no-analyzer, --ci)" >&2; exit 2 ;;
esac
build=${SUPERBALL_BUILD_DIR:-$root/build/lint}
# Configuring only (seconds): version.hpp, the one generated header src/ includes, is written
# at configure time.
configure() {
  cmake -S "$root" -B "$1" -DCMAKE_BUILD_TYPE=Release -DCMAKE_UNITY_BUILD="$2" -DSUPERBALL_TESTS=OFF \
    -DSUPERBALL_BENCHMARKS=OFF >/dev/null
}
if [[ -z ${SUPERBALL_BUILD_DIR:-} ]]; then
  configure "$build" OFF
elif [[ ! -f $build/compile_commands.json ]]; then
  echo "lint: no $build/compile_commands.json: configure that build first" >&2
  exit 1
fi
# --ci: clang-tidy reads the batches the builds compile (build/lint-batches, configured the
# same way with the unity build on).
batches=""
if ((ci == 1)); then
  batches=$root/build/lint-batches
  configure "$batches" ON
fi

# The compile commands of src/ only (not the tests, not the benchmarks): file by file for
# cppcheck, and for clang-tidy unless --ci, which takes the batches of src/'s targets.
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir "$work/files" "$work/batches"
/usr/bin/python3 - "$root/src/" "$build" "$work/files" ${batches:+"$batches" "$work/batches"} <<'PY'
import json, os, sys
src = sys.argv[1]
def select(build, out, unity):
    entries = json.load(open(os.path.join(build, "compile_commands.json")))
    batched = any("/Unity/unity_" in e["file"] for e in entries)
    if batched != unity:
        sys.exit(f"lint: {build} compiles files " + ("in batches (unity build): configure it with -DCMAKE_UNITY_BUILD=OFF"
                                                      if batched else "one by one: configure it with -DCMAKE_UNITY_BUILD=ON"))
    def of_src(e):
        if e["file"].startswith(src):
            return True
        # A batch of a target of src/: its sources are src/'s.
        return unity and "/Unity/unity_" in e["file"] and any(
            line.startswith(f'#include "{src}') for line in open(e["file"]))
    entries = [e for e in entries if of_src(e)]
    if not entries:
        sys.exit(f"lint: no source of {src} in {build}")
    json.dump(entries, open(os.path.join(out, "compile_commands.json"), "w"), indent=1)
select(sys.argv[2], sys.argv[3], False)
if len(sys.argv) > 4:
    select(sys.argv[4], sys.argv[5], True)
PY
status=0
echo "lint: cppcheck" >&2
cppcheck --project="$work/files/compile_commands.json" --std=c++20 --enable=warning,performance,portability \
  --suppress=missingIncludeSystem --suppressions-list="$root/tests/lint/cppcheck.supp" --inline-suppr \
  --error-exitcode=1 --quiet -j"$(nproc)" || status=1

if ((quick == 0)); then
  echo "lint: clang-tidy" >&2
  tidy=$(command -v run-clang-tidy-14 || command -v run-clang-tidy || true)
  [[ -n $tidy ]] || { echo "lint: run-clang-tidy not found: apt-get install clang-tidy" >&2; exit 1; }
  database=$work/files
  if [[ -n $batches ]]; then
    database=$work/batches
    # A batch is src/'s .cpp files included one after the other, which is what
    # bugprone-suspicious-include reports: not a finding in the sources (the full run keeps it).
    checks=("${checks[0]},-bugprone-suspicious-include")
  fi
  # Every file of the database (it holds src/'s only).
  "$tidy" -p "$database" -j "$(nproc)" -quiet "${checks[@]}" >"$work/tidy.log" 2>&1 || true
  if grep -qE "(warning|error): " "$work/tidy.log"; then
    grep -E "(warning|error): " "$work/tidy.log" | sed 's/\x1b\[[0-9;]*m//g' | sort -u >&2
    status=1
  fi
fi
((status == 0)) && echo "lint: no findings" >&2
exit $status
