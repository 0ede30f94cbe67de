#!/usr/bin/python3
"""Runs the issue-4 benchmark and prints its table; see tests/bench/run.sh."""
import argparse
import datetime
import json
import os
import platform
import re
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))


def kernel_rates(bench, n):
    """Points/s of the scalar and the vectorised kernel on the n x n slice."""
    out = subprocess.run([bench, f"--benchmark_filter=BM_count_slice<(false|true)>/{n}$", "--benchmark_format=json",
                          "--benchmark_min_time=1"], capture_output=True, text=True, check=True).stdout
    rates = {}
    for b in json.loads(out)["benchmarks"]:
        kind = "vectorised" if "<true>" in b["name"] else "scalar"
        rates[kind] = (b["items_per_second"], b["time_per_map_iteration"] * 1e9)
    return rates


def explore(superball, job, ranks, workdir, keep=None):
    """(points/s as explore reports it, wall seconds of the whole command, peak MiB per
    rank); the result is deleted unless `keep` names it."""
    out = os.path.join(workdir, keep or f"r{ranks}.h5")
    cmd = ["mpirun", "-n", str(ranks), "--oversubscribe", superball, "explore", job, "-o", out, "--overwrite", "-q"]
    start = datetime.datetime.now()
    r = subprocess.run(cmd, capture_output=True, text=True)
    wall = (datetime.datetime.now() - start).total_seconds()
    if r.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed:\n{r.stderr}")
    rate = float(re.search(r"\(([0-9.e+]+) points/s\)", r.stderr).group(1))
    peak = float(re.search(r"peak memory per rank: ([0-9.]+) MiB", r.stderr).group(1))
    if not keep:
        os.remove(out)
    return rate, wall, peak


def refinement(superball, job_text, name, workdir):
    """Full computation against refine = 8 on one grid, 2 ranks: (speed-up, mismatch)."""
    import h5py  # Debian's python3-h5py
    results = {}
    for refine in (0, 8):
        job = os.path.join(workdir, f"{name}-{refine}.toml")
        with open(job, "w") as f:
            f.write(job_text.replace("[run]", f"[run]\nrefine = {refine}"))
        rate, _, _ = explore(superball, job, 2, workdir, keep=f"{name}-{refine}.h5")
        with h5py.File(os.path.join(workdir, f"{name}-{refine}.h5"), "r") as f:
            results[refine] = (rate, f["wall_bounces"][()], f["outcome"][()])
    (rate0, w0, o0), (rate8, w8, o8) = results[0], results[8]
    return rate8 / rate0, float(((w0 != w8) | (o0 != o8)).mean())


def main():
    p = argparse.ArgumentParser(description=__doc__)
    p.add_argument("--build", default="build/native", help="build directory with superball and bench_kernel")
    p.add_argument("--skip-16384", action="store_true", help="skip the 16384^2 memory run (1.2 GB of output)")
    a = p.parse_args()
    bench = os.path.join(a.build, "tests/bench/bench_kernel")
    superball = os.path.abspath(os.path.join(a.build, "src/superball"))
    cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")), "?")
    print(f"machine: {cpu}, {os.cpu_count()} cores; {platform.platform()}; {datetime.date.today()}", flush=True)

    k = kernel_rates(bench, 4096)
    scalar = k["scalar"][0]
    rows = [("scalar kernel, 1 core", scalar, f"{k['scalar'][1]:.2f} ns/iteration"),
            ("vectorised kernel, 1 core", k["vectorised"][0], f"{k['vectorised'][1]:.2f} ns/iteration")]
    peaks = {}
    with tempfile.TemporaryDirectory(prefix="superball-bench-") as d:
        job = os.path.join(HERE, "slice_4096.toml")
        for ranks in (1, 2):
            rate, wall, peak = explore(superball, job, ranks, d)
            rows.append((f"explore -n {ranks}", rate, f"{wall:.2f} s wall incl. start-up, peak {peak:.0f} MiB/rank"))
            peaks[(4096, ranks)] = peak
        if not a.skip_16384:
            rate, wall, peak = explore(superball, os.path.join(HERE, "slice_16384.toml"), 2, d)
            rows.append(("explore -n 2, 16384^2", rate, f"{wall:.2f} s wall, peak {peak:.0f} MiB/rank"))
            peaks[(16384, 2)] = peak

        slice_text = open(os.path.join(HERE, "slice_4096.toml")).read()
        volume_text = slice_text.replace("U = -1.0", "U = { min = -3.0, max = -0.05, n = 256 }").replace(
            "n = 4096", "n = 256")
        refined = [("4096^2 slice", *refinement(superball, slice_text, "slice", d)),
                   ("256^3 volume, U in [-3, -0.05]", *refinement(superball, volume_text, "volume", d))]

    print("\n| run (4096^2 slice unless said) | points/s | vs scalar kernel | notes |")
    print("|---|---|---|---|")
    for name, rate, note in rows:
        print(f"| {name} | {rate:.3g} | {rate / scalar:.2f}x | {note} |")
    n1, n2 = rows[2][1], rows[3][1]
    print(f"\nvectorised / scalar kernel: {k['vectorised'][0] / scalar:.2f}x (target >= 2.5)")
    print(f"explore -n 2 / explore -n 1: {n2 / n1:.2f}x (target >= 1.8)")
    print(f"explore -n 1 / vectorised kernel: {n1 / k['vectorised'][0]:.2f} (target >= 0.85)")
    print("\n| refine = 8 against the full grid (2 ranks) | speed-up | points that differ |")
    print("|---|---|---|")
    for name, speedup, mismatch in refined:
        print(f"| {name} | {speedup:.2f}x | {100 * mismatch:.4f}% |")
    if (16384, 2) in peaks:
        ratio = peaks[(16384, 2)] / peaks[(4096, 2)]
        print(f"peak memory per rank 16384^2 / 4096^2 (2 ranks): {ratio:.3f} (target < 1.10)")


if __name__ == "__main__":
    main()
