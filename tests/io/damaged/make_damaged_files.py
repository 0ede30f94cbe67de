#!/usr/bin/python3
"""Writes every damaged-file case of tests/hardening/damages.py (the table the command line's
and the analysis scripts' refusals are tested with) into OUT, for the C++ test of the
reader's refusals (test_reader_refusals.cpp): a real result and partial file made by the
binary ($SUPERBALL), each case applied to a copy of its base, and OUT/cases.json listing
{what, base, path, expected} (expected: texts of which the refusal must contain one).

    make_damaged_files.py OUT"""
import json
import os
import shutil
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", ".."))
sys.path.insert(0, os.path.join(HERE, "..", "..", "hardening"))
from superball_testing import interrupted_run, mpi_env, superball_binary  # noqa: E402
from damages import CASES, JOB  # noqa: E402


def main():
    out = os.path.abspath(sys.argv[1])
    shutil.rmtree(out, ignore_errors=True)
    os.makedirs(out)
    binary = superball_binary()
    job = os.path.join(out, "job.toml")
    with open(job, "w") as f:
        f.write(JOB)
    result = os.path.join(out, "result.h5")
    r = subprocess.run([binary, "explore", job, "-o", result, "-q"], capture_output=True, text=True, env=mpi_env(),
                       timeout=300)
    if r.returncode != 0:
        sys.exit(f"make_damaged_files.py: {binary} explore failed: {r.stderr}")
    partial = interrupted_run(binary, job, os.path.join(out, "interrupted.h5"), result, lambda t: t % 2 == 0)
    cases = []
    for i, (what, base, damage, expected) in enumerate(CASES):
        path = os.path.join(out, f"d{i}.h5" + (".partial" if base == "P" else ""))
        shutil.copyfile(partial if base == "P" else result, path)
        damage(path)
        cases.append({"what": what, "base": base, "path": path,
                      "expected": [expected] if isinstance(expected, str) else list(expected)})
    with open(os.path.join(out, "cases.json"), "w") as f:
        json.dump(cases, f, indent=1)
    print(f"make_damaged_files.py: {len(cases)} damaged files in {out}")


if __name__ == "__main__":
    main()
