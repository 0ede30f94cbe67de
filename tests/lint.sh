#!/usr/bin/env bash
# Static analysis of src/ with its checked-in configuration: cppcheck (tests/lint/
# cppcheck.supp: each suppression says why) and clang-tidy (.clang-tidy: each check left
# out says why), with the compile commands of build/lint (configured here, not built;
# SUPERBALL_BUILD_DIR picks another build tree configured with -DCMAKE_UNITY_BUILD=OFF).
# cppcheck and clang-tidy read the sources file by file, which also checks that each file
# compiles on its own, with its own includes (the builds compile batches: CMake's unity
# build). --ci runs clang-tidy on four large batches of src/'s files instead (below): the
# same checks of the same code, but a file that compiles only after another of its batch is
# not found there (the full run finds it), and two files of a batch that define the same name
# at namespace scope, even in unnamed namespaces, stop it (one definition, in the lower
# layer's header, is then the fix). Exits non-zero on any finding.
#
#   tests/lint.sh                cppcheck (seconds) and clang-tidy with every check of .clang-tidy
#                                (6 minutes on 2 cores)
#   tests/lint.sh --no-analyzer  the same without clang-analyzer-* (about 5 minutes)
#   tests/lint.sh --ci           the same without clang-analyzer-*, performance-unnecessary-value-param
#                                and bugprone-reserved-identifier, clang-tidy on four batches (what
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
if [[ -z ${SUPERBALL_BUILD_DIR:-} ]]; then
  cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release -DCMAKE_UNITY_BUILD=OFF -DSUPERBALL_TESTS=OFF \
    -DSUPERBALL_BENCHMARKS=OFF >/dev/null
elif [[ ! -f $build/compile_commands.json ]]; then
  echo "lint: no $build/compile_commands.json: configure that build first" >&2
  exit 1
fi

# The compile commands of src/ only (not the tests, not the benchmarks), file by file for
# cppcheck and clang-tidy; --ci groups them for clang-tidy (below).
# The batches are written under build/ (clang-tidy reads the .clang-tidy of the folders
# above a file).
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir "$work/files"
batches=$root/build/lint-batches
rm -rf "$batches"
((ci == 0)) || mkdir -p "$batches"
/usr/bin/python3 - "$root/src/" "$build" "$work/files" $((ci == 1 ? 1 : 0)) "$batches" <<'PY'
import json, os, shlex, sys
src, build, files, ci, batches = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4] == "1", sys.argv[5]
entries = json.load(open(os.path.join(build, "compile_commands.json")))
if any("/Unity/unity_" in e["file"] for e in entries):
    sys.exit(f"lint: {build} compiles files in batches (unity build): configure it with -DCMAKE_UNITY_BUILD=OFF")
entries = [e for e in entries if e["file"].startswith(src)]
if not entries:
    sys.exit(f"lint: no source of {src} in {build}")
json.dump(entries, open(os.path.join(files, "compile_commands.json"), "w"), indent=1)
if not ci:
    sys.exit(0)
# --ci: clang-tidy on a few large batches instead of file by file. It visits every template
# instantiation of every translation unit, headers included: the same Eigen, fmt and JSON code
# once per batch. Batches: the layers below run/ (core, job, measures, mpi, io), the layers
# from run/ up (run, api, serve, the command line), the Python bindings (pybind11's headers
# and flags), and each vectorised kernel variant alone (its -m flags). Each batch is compiled
# with the union of its files' options (include folders, and macros that only their own files
# read: a macro given two values stops the lint here).
lower = ("core", "job", "measures", "mpi", "io")
groups = {}
for e in entries:
    words = shlex.split(e["command"])
    options, i = [], 1  # each an option and its value, as a tuple of words
    while i < len(words):
        w = words[i]
        if w in ("-o", "-c"):
            i += 2 if w == "-o" else 1
        elif w == e["file"]:
            i += 1
        elif w in ("-isystem", "-I", "-D", "-include"):
            options.append((w, words[i + 1]))
            i += 2
        else:
            options.append((w,))
            i += 1
    rel = os.path.relpath(e["file"], src)
    if any(o[0].startswith("-m") for o in options):
        name = os.path.splitext(rel)[0].replace("/", "_") + f"_{len(groups)}"
    elif rel.startswith("python/"):
        name = "python"
    elif rel.split("/")[0] in lower:
        name = "below_run"
    else:
        name = "run_and_up"
    group = groups.setdefault(name, {"compiler": words[0], "directory": e["directory"], "options": [], "files": []})
    group["files"].append(e["file"])
    for o in options:
        if o not in group["options"]:
            group["options"].append(o)
out = []
for name, g in groups.items():
    values = {}
    for o in g["options"]:
        if o[0].startswith("-D"):
            macro, _, value = "".join(o)[2:].partition("=")
            if values.setdefault(macro, value) != value:
                sys.exit(f"lint: the batch {name} would define {macro} twice ({values[macro]!r} and {value!r})")
    path = os.path.join(batches, name + ".cpp")
    with open(path, "w") as f:
        f.writelines(f'#include "{file}"\n' for file in g["files"])
    words = [g["compiler"]] + [w for o in g["options"] for w in o] + ["-c", path]
    out.append({"directory": g["directory"], "command": shlex.join(words), "file": path})
json.dump(out, open(os.path.join(batches, "compile_commands.json"), "w"), indent=1)
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
  if ((ci == 1)); then
    database=$batches
    # A batch is src/'s .cpp files included one after the other, which is what
    # bugprone-suspicious-include reports: not a finding in the sources (the full run keeps it).
    checks=("${checks[0]},-bugprone-suspicious-include")
  fi
  # Every file of the database (it holds src/'s only).
  tidy_status=0
  "$tidy" -p "$database" -j "$(nproc)" -quiet "${checks[@]}" >"$work/tidy.log" 2>&1 || tidy_status=$?
  if grep -qE "(warning|error): " "$work/tidy.log"; then
    grep -E "(warning|error): " "$work/tidy.log" | sed 's/\x1b\[[0-9;]*m//g' | sort -u >&2
    status=1
  elif ((tidy_status != 0)); then
    # Not a finding: clang-tidy itself failed (no checks, no compile commands...).
    echo "lint: clang-tidy failed (status $tidy_status):" >&2
    tail -n 20 "$work/tidy.log" >&2
    status=1
  fi
fi
((status == 0)) && echo "lint: no findings" >&2
exit $status
