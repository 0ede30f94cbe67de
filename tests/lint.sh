#!/usr/bin/env bash
# Static analysis of src/ with its checked-in configuration: cppcheck (tests/lint/
# cppcheck.supp: each suppression says why) and clang-tidy (.clang-tidy: each check left
# out says why), with the compile_commands.json of build/release (configured if missing;
# SUPERBALL_BUILD_DIR picks another build). Exits non-zero on any finding.
#
#   tests/lint.sh                cppcheck (seconds) and clang-tidy with every check of .clang-tidy
#                                (6 minutes on 2 cores)
#   tests/lint.sh --no-analyzer  the same without clang-analyzer-* (about 4 minutes)
#   tests/lint.sh --quick        cppcheck only (seconds: what tests/all runs)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
quick=0
analyzer=1
case ${1:-} in
  --quick) quick=1 ;;
  --no-analyzer) analyzer=0 ;;
  "") ;;
  *) echo "lint: unknown option $1 (accepted: --quick, --no-analyzer)" >&2; exit 2 ;;
esac
build=${SUPERBALL_BUILD_DIR:-$root/build/release}
if [[ ! -f $build/compile_commands.json ]]; then
  if [[ -n ${SUPERBALL_BUILD_DIR:-} ]]; then
    echo "lint: no $build/compile_commands.json: configure that build first" >&2
    exit 1
  fi
  cmake --preset release >/dev/null
fi

# The compile commands of src/ only (not the tests, not the benchmarks).
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
python3 - "$build/compile_commands.json" "$work/compile_commands.json" "$root/src/" <<'PY'
import json, sys
entries = [e for e in json.load(open(sys.argv[1])) if e["file"].startswith(sys.argv[3])]
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
  checks=()
  ((analyzer)) || checks=(-checks=-clang-analyzer-*)
  "$tidy" -p "$work" -j "$(nproc)" -quiet "${checks[@]}" "$root/src/" >"$work/tidy.log" 2>&1 || true
  if grep -qE "(warning|error): " "$work/tidy.log"; then
    grep -E "(warning|error): " "$work/tidy.log" | sed 's/\x1b\[[0-9;]*m//g' | sort -u >&2
    status=1
  fi
fi
((status == 0)) && echo "lint: no findings" >&2
exit $status
