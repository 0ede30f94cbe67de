#!/usr/bin/python3
"""Size and h5py read times of results at each compression level (docs/format.md: Size and read times).

Runs `superball explore` under mpirun on the quickstart region (xi in (0, 1), U = -1,
W in [-3, 3], e = alpha = 0.9, max_bounces 1000; a volume adds U in [-3, 0]) with
`[run] compression` 0, 1, 4 and 9, then reads each result with h5py: the whole
/wall_bounces, one column (the first axis at the middle of the others:
f["wall_bounces"][:, k]) and one row (the last axis: f["wall_bounces"][k, :]). Reads are
repeated --repeat times, the levels interleaved, and the median is printed; the files are
in the page cache (just written), so the times are the decompression's and h5py's, not the
disk's. Prints a markdown table.

    /usr/bin/python3 tests/bench/result_sizes.py --superball build/release/src/superball \
        --grid 4096x4096 --grid 2048x2048 --grid 64x64x64
"""
import argparse
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

import h5py

REGION = {"xi": (0.0, 1.0), "U": (-3.0, 0.0), "W": (-3.0, 3.0)}


def job_text(shape, level):
    names = ["xi", "W"] if len(shape) == 2 else ["xi", "U", "W"]
    lines = [f"{n} = {{ min = {REGION[n][0]}, max = {REGION[n][1]}, n = {k} }}" for n, k in zip(names, shape)]
    if len(shape) == 2:
        lines.insert(1, "U = -1.0")
    return ("[model]\ne = 0.9\nalpha = 0.9\n\n[grid]\ncoordinates = \"canonical\"\n" + "\n".join(lines) +
            f"\n\n[run]\nmax_bounces = 1000\ncompression = {level}\n")


def explore(superball, ranks, job, out):
    cmd = ["mpirun", "-n", str(ranks), "--oversubscribe", superball, "explore", job, "-o", out, "--overwrite", "-q"]
    env = dict(os.environ)
    if os.geteuid() == 0:
        env.update(OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    r = subprocess.run(cmd, capture_output=True, text=True, env=env)
    if r.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed:\n{r.stderr}")
    return float(re.search(r"written in ([0-9.]+) s", r.stderr).group(1))


def reads(path):
    """Seconds to read the whole array, one column and one row, each from a freshly opened
    file (HDF5's chunk cache would otherwise serve the second read from the first's)."""
    with h5py.File(path, "r") as f:
        shape, chunks = f["wall_bounces"].shape, f["wall_bounces"].chunks
    middle = tuple(n // 2 for n in shape)
    selections = {"whole": (), "column": (slice(None),) + middle[1:], "row": middle[:-1] + (slice(None),)}
    seconds = {}
    for what, sel in selections.items():
        with h5py.File(path, "r") as f:
            d = f["wall_bounces"]
            start = time.perf_counter()
            d[sel]
            seconds[what] = time.perf_counter() - start
    return seconds, chunks


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--superball", required=True)
    parser.add_argument("--ranks", type=int, default=2)
    parser.add_argument("--grid", action="append", required=True, help="e.g. 4096x4096 or 64x64x64")
    parser.add_argument("--level", action="append", type=int, help="compression levels (default 0, 1, 4, 9)")
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    levels = args.level or [0, 1, 4, 9]
    work = tempfile.mkdtemp(prefix="superball-sizes-")
    try:
        print("| grid | level | file / raw | file size | chunk | write (s) | whole read (ms) | column (ms) | row (ms) |")
        print("|---|---|---|---|---|---|---|---|---|")
        for grid in args.grid:
            shape = [int(n) for n in grid.split("x")]
            raw = 3
            for n in shape:
                raw *= n  # uint16 counts + uint8 outcomes
            files, writes = {}, {}
            for level in levels:
                job = os.path.join(work, f"{grid}-{level}.toml")
                with open(job, "w") as f:
                    f.write(job_text(shape, level))
                files[level] = os.path.join(work, f"{grid}-{level}.h5")
                writes[level] = explore(args.superball, args.ranks, job, files[level])
            times = {level: [] for level in levels}
            for _ in range(args.repeat):
                for level in levels:  # interleaved
                    seconds, chunks = reads(files[level])
                    times[level].append(seconds)
            for level in levels:
                size = os.path.getsize(files[level])
                med = {w: 1e3 * statistics.median(t[w] for t in times[level]) for w in ("whole", "column", "row")}
                chunk = "x".join(str(c) for c in reads(files[level])[1])
                print(f"| {grid} | {level} | {100 * size / raw:.2f} % | {size / 1e6:.3f} MB | {chunk} | "
                      f"{writes[level]:.2f} | {med['whole']:.1f} | {med['column']:.3f} | {med['row']:.3f} |")
    finally:
        shutil.rmtree(work, ignore_errors=True)


main()
