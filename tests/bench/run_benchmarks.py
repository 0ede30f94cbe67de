#!/usr/bin/python3
"""Runs the speed benchmarks and prints their tables; see tests/bench/run.sh.

Every figure is the median of --repetitions (at least 3) repetitions, and the
repetitions are interleaved: each one runs every measurement once, in the same order, so
that the load of a shared machine falls on all of them alike. Every ratio is taken within
one repetition (the runs it compares ran back to back) and its median reported, with the
smallest and largest in brackets.
"""
import argparse
import datetime
import json
import os
import platform
import re
import shutil
import statistics
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))

# The benchmark slice (tests/bench/slice_4096.toml) at any size n.
SLICE = """[model]
e = 0.9
alpha = 0.9

[grid]
coordinates = "canonical"
xi = {{ min = 0.0, max = 1.0, n = {n} }}
U = -1.0
W = {{ min = -3.0, max = 3.0, n = {n} }}

[run]
max_bounces = 1000
{run}"""

# Issue 12's trivial grid: every launch misses the wall (xi >= 1), so a run costs what the
# tiles cost beyond their points.
TRIVIAL = """[model]
e = 0.9
alpha = 0.9

[grid]
xi = {{ min = 1.0, max = 2.0, n = 8192 }}
U = -1.0
W = {{ min = -3.0, max = 3.0, n = 8192 }}

[run]
max_bounces = 1000
tile_points = {tile}
"""


def median(values):
    return statistics.median(values)


def spread(values, fmt):
    return f"[{fmt.format(min(values))}, {fmt.format(max(values))}]"


class Builds:
    """The superball and bench_kernel binaries of one build tree."""

    def __init__(self, directory):
        self.dir = directory
        self.superball = os.path.abspath(os.path.join(directory, "src", "superball"))
        self.bench = os.path.abspath(os.path.join(directory, "tests", "bench", "bench_kernel"))
        for path in (self.superball, self.bench):
            if not os.access(path, os.X_OK):
                sys.exit(f"run_benchmarks: {path} is missing: build it (tests/bench/run.sh does)")
        version = subprocess.run([self.superball, "--version"], capture_output=True, text=True, check=True,
                                 env=without_kernel_choice())
        self.version = " ".join(version.stdout.split())
        self.kernel = re.search(r"counting kernel: (\S+)", version.stdout).group(1)
        self.kernel_text = re.search(r"counting kernel: ([^;]+);", version.stdout).group(1)


def without_kernel_choice(**extra):
    env = dict(os.environ)
    env.pop("SUPERBALL_KERNEL", None)
    env.update(extra)
    return env


def kernel_rates(build, n, kernels, min_time):
    """Points/s (wall time) and ns per iteration of G of `kernels` on the n x n slice."""
    names = "|".join(kernels)
    out = subprocess.run([build.bench, f"--benchmark_filter=^BM_count_slice/({names})/{n}/real_time$",
                          "--benchmark_format=json", f"--benchmark_min_time={min_time}"],
                         capture_output=True, text=True, check=True).stdout
    rates = {}
    for b in json.loads(out)["benchmarks"]:
        kernel = b["name"].split("/")[1]
        rates[kernel] = (b["items_per_second"], b["time_per_map_iteration"] * 1e9, b.get("label", kernel))
    missing = set(kernels) - set(rates)
    if missing:
        sys.exit(f"run_benchmarks: {build.bench} has no kernel {', '.join(sorted(missing))}")
    return rates


def runnable_kernels(build):
    out = subprocess.run([build.bench, "--benchmark_list_tests=true", "--benchmark_filter=^BM_count_slice/.*/4096/real_time$"],
                         capture_output=True, text=True, check=True).stdout
    return [line.split("/")[1] for line in out.split()]


class Explorer:
    def __init__(self, workdir):
        self.workdir = workdir
        self.serial = 0

    def job(self, text):
        self.serial += 1
        path = os.path.join(self.workdir, f"job{self.serial}.toml")
        with open(path, "w") as f:
            f.write(text)
        return path

    def run(self, build, job, ranks, keep=None, wrap=(), env=None, singleton=False):
        """Runs explore; returns (points/s as explore reports it, seconds of its compute
        phase, wall seconds of the whole command, peak MiB per rank, output path). The
        result is deleted unless `keep`."""
        out = os.path.join(self.workdir, keep or "run.h5")
        launcher = [] if singleton else ["mpirun", "-n", str(ranks), "--oversubscribe"]
        cmd = [*wrap, *launcher, build.superball, "explore", job, "-o", out, "--overwrite", "-q"]
        start = datetime.datetime.now()
        r = subprocess.run(cmd, capture_output=True, text=True, env=env or without_kernel_choice())
        wall = (datetime.datetime.now() - start).total_seconds()
        if r.returncode != 0:
            sys.exit(f"{' '.join(cmd)} failed:\n{r.stderr}")
        m = re.search(r"(\d+) points computed in [0-9.]+ s \(([0-9.e+]+) points/s\)", r.stderr)
        points, rate = int(m.group(1)), float(m.group(2))
        peak = float(re.search(r"peak memory per rank: ([0-9.]+) MiB", r.stderr).group(1))
        # From the last tile counted to the result under its name, as explore reports it.
        closing = re.search(r"finished ([0-9.e+-]+) ms after the last tile", r.stderr)
        size = os.path.getsize(out) if os.path.exists(out) else 0
        if not keep:
            remove_outputs(out)
        return {"rate": rate, "compute": points / rate, "wall": wall, "peak": peak, "output": out, "stderr": r.stderr,
                "closing": float(closing.group(1)) / 1e3 if closing else float("nan"), "size": size}


def remove_outputs(out):
    """A result, the file a run writes before renaming it, and the XDMF sidecar."""
    for path in (out, out + ".partial", out + ".partial.undo", os.path.splitext(out)[0] + ".xmf"):
        if os.path.exists(path):
            os.remove(path)


def write_calls(explorer, build, job, ranks, name):
    """Write system calls to the result file (any path containing its base name, so that a
    `.partial` file written first counts too), as /work/shared/tools/write-calls.sh counts
    them: strace of every process, the calls write, pwrite64, pwritev, pwritev2."""
    trace = os.path.join(explorer.workdir, "trace")
    shutil.rmtree(trace, ignore_errors=True)
    os.makedirs(trace)
    strace = ["strace", "-ff", "-qq", "-y", "-e", "trace=write,pwrite64,pwritev,pwritev2", "-o",
              os.path.join(trace, "t")]
    if subprocess.run(["strace", "--seccomp-bpf", "-f", "-qq", "-e", "trace=none", "true"],
                      capture_output=True).returncode == 0:
        strace.insert(1, "--seccomp-bpf")  # only the traced calls stop the processes
    explorer.run(build, job, ranks, keep=name, wrap=strace)
    calls = 0
    written = 0
    for entry in os.listdir(trace):
        with open(os.path.join(trace, entry), errors="replace") as f:
            for line in f:
                m = re.search(r"= (\d+)$", line.rstrip())
                if name in line and m:
                    calls += 1
                    written += int(m.group(1))
    shutil.rmtree(trace)
    remove_outputs(os.path.join(explorer.workdir, name))
    return calls, written


def scalar_loop(build, min_time):
    """Seconds and total wall bounces of the 8192^2 slice counted by the scalar kernel in a
    plain loop on one core (bench_kernel's BM_scalar_loop)."""
    out = subprocess.run([build.bench, "--benchmark_filter=^BM_scalar_loop/8192/real_time$", "--benchmark_format=json",
                          f"--benchmark_min_time={min_time}"], capture_output=True, text=True, check=True).stdout
    b = json.loads(out)["benchmarks"][0]
    return {"seconds": b["real_time"] / 1e3, "total": int(b["total_wall_bounces"])}


def total_wall_bounces(path):
    import h5py  # Debian's python3-h5py
    import numpy as np
    with h5py.File(path, "r") as f:
        return int(f["wall_bounces"][()].astype(np.uint64).sum())


def refinement_mismatch(a, b):
    import h5py  # Debian's python3-h5py
    with h5py.File(a, "r") as fa, h5py.File(b, "r") as fb:
        return float(((fa["wall_bounces"][()] != fb["wall_bounces"][()]) | (fa["outcome"][()] != fb["outcome"][()])).mean())


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--portable", default="build/release", help="portable build tree (default build/release)")
    p.add_argument("--native", default="build/native",
                   help="-march=native build tree (default build/native); 'none' to skip the comparison")
    p.add_argument("--repetitions", type=int, default=3, help="interleaved repetitions, at least 3 (default 3)")
    p.add_argument("--quick", action="store_true",
                   help="shorter kernel timings; no 16384^2 run, no volume and no refinement table")
    p.add_argument("--skip-16384", action="store_true", help="skip the 16384^2 run")
    p.add_argument("--baseline", metavar="SUPERBALL",
                   help="another superball binary (e.g. one built from an earlier commit) whose result sizes are "
                        "compared with this build's, on the quickstart and benchmark slices")
    a = p.parse_args()
    if a.repetitions < 3:
        p.error("--repetitions: at least 3 (every figure is a median of at least 3)")
    if shutil.which("strace") is None:
        sys.exit("run_benchmarks: strace is missing (.ci/install-deps --bench installs it)")
    portable = Builds(a.portable)
    native = Builds(a.native) if a.native != "none" else None
    min_time = 0.3 if a.quick else 1.0
    kernels = runnable_kernels(portable)
    best = portable.kernel
    cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")), "?")
    print(f"machine: {cpu}, {os.cpu_count()} cores; {platform.platform()}; {datetime.date.today()}")
    print(f"portable build ({portable.dir}): {portable.version}")
    if native:
        print(f"native build ({native.dir}): {native.version}")
    print(f"{a.repetitions} interleaved repetitions; medians, [smallest, largest] of the ratios", flush=True)
    r = {key: [] for key in ("kernel", "native_kernel", "n1", "n2", "p8192", "n8192", "s1_8192", "s2_8192", "single_8192", "scalar",
                             "tile1024", "tile262144", "calls", "single", "single_before", "mpirun", "mpirun_before",
                             "n2_16384", "volume", "refine_slice", "refine_volume", "full_slice", "coarse_slice",
                             "full_volume", "coarse_volume")}
    mismatch = {}
    totals = {}
    sizes = {}
    with tempfile.TemporaryDirectory(prefix="superball-bench-") as d:
        ex = Explorer(d)
        slice_4096 = os.path.join(HERE, "slice_4096.toml")
        slice_8192 = ex.job(SLICE.format(n=8192, run=""))
        slice_64 = ex.job(SLICE.format(n=64, run=""))
        tiles_1024 = ex.job(TRIVIAL.format(tile=1024))
        tiles_262144 = ex.job(TRIVIAL.format(tile=262144))
        slice_text = SLICE.format(n=4096, run="")
        # Issue 21's volume: 4096 x 4096 x 16 (U in [-3, -0.05]).
        volume_16 = ex.job(slice_text.replace("U = -1.0", "U = { min = -3.0, max = -0.05, n = 16 }"))
        volume_text = slice_text.replace("U = -1.0", "U = { min = -3.0, max = -0.05, n = 256 }").replace(
            "n = 4096", "n = 256")
        refine_jobs = {(name, refine): ex.job(text.replace("[run]", f"[run]\nrefine = {refine}"))
                       for name, text in (("slice", slice_text), ("volume", volume_text)) for refine in (0, 8)}
        # The result's total of wall bounces, against the scalar loop's (once: it is deterministic).
        first = ex.run(portable, slice_8192, 2, keep="total-8192.h5")
        totals["explore"] = total_wall_bounces(first["output"])
        remove_outputs(first["output"])
        for rep in range(a.repetitions):
            print(f"repetition {rep + 1} of {a.repetitions}", file=sys.stderr, flush=True)
            # Each pair runs A B in even repetitions and B A in odd ones: neither always
            # follows the other (the page cache's writeback of one run's output slows the next).
            def pair(key_a, run_a, key_b, run_b):
                for key, run in ((key_a, run_a), (key_b, run_b)) if rep % 2 == 0 else ((key_b, run_b), (key_a, run_a)):
                    r[key].append(run())
            if native:
                pair("kernel", lambda: kernel_rates(portable, 4096, kernels, min_time),
                     "native_kernel", lambda: kernel_rates(native, 4096, [native.kernel], min_time)[native.kernel])
            else:
                r["kernel"].append(kernel_rates(portable, 4096, kernels, min_time))
            pair("n1", lambda: ex.run(portable, slice_4096, 1), "n2", lambda: ex.run(portable, slice_4096, 2))
            # Issue 21: the whole process on the 8192^2 slice at 1 and 2 ranks, and the
            # scalar kernel counting the same points in a plain loop.
            pair("s1_8192", lambda: ex.run(portable, slice_8192, 1), "s2_8192", lambda: ex.run(portable, slice_8192, 2))
            # The same rank alone, without mpirun (a singleton: what mpirun and its daemon cost).
            r["single_8192"].append(ex.run(portable, slice_8192, 1, singleton=True))
            r["scalar"].append(scalar_loop(portable, 0.1))
            # Issue 14: the portable binary against the native build, one rank, 8192^2.
            if native:
                pair("p8192", lambda: ex.run(portable, slice_8192, 1), "n8192", lambda: ex.run(native, slice_8192, 1))
            # Cost of a tile beyond its points, one rank, whole process.
            pair("tile1024", lambda: ex.run(portable, tiles_1024, 1), "tile262144",
                 lambda: ex.run(portable, tiles_262144, 1))
            r["calls"].append(write_calls(ex, portable, slice_8192, 2, "calls-8192.h5"))
            # Start-up of a 64^2 job: superball's choice on one node (ob1; no daemon for a
            # singleton) and Open MPI's own (the parameters set by hand, to nothing and to
            # its default, which superball leaves alone).
            own = without_kernel_choice(OMPI_MCA_pml="", OMPI_MCA_ess_singleton_isolated="0")
            for _ in range(2):
                pair("single", lambda: ex.run(portable, slice_64, 1, singleton=True)["wall"],
                     "single_before", lambda: ex.run(portable, slice_64, 1, singleton=True, env=own)["wall"])
                pair("mpirun", lambda: ex.run(portable, slice_64, 2)["wall"],
                     "mpirun_before", lambda: ex.run(portable, slice_64, 2, env=own)["wall"])
            if not (a.quick or a.skip_16384):
                r["n2_16384"].append(ex.run(portable, os.path.join(HERE, "slice_16384.toml"), 2))
            if not a.quick:
                r["volume"].append(ex.run(portable, volume_16, 2))
                for name in ("slice", "volume"):
                    pair(f"full_{name}", lambda: ex.run(portable, refine_jobs[(name, 0)], 2, keep=f"{name}-0.h5"),
                         f"coarse_{name}", lambda: ex.run(portable, refine_jobs[(name, 8)], 2, keep=f"{name}-8.h5"))
                    full, coarse = r[f"full_{name}"][-1], r[f"coarse_{name}"][-1]
                    r[f"refine_{name}"].append(coarse["rate"] / full["rate"])
                    mismatch[name] = refinement_mismatch(full["output"], coarse["output"])
                    remove_outputs(full["output"])
                    remove_outputs(coarse["output"])
        # Result sizes at the default level: deterministic, measured once.
        quickstart = os.path.join(HERE, os.pardir, os.pardir, "jobs", "quickstart.toml")
        for name, job in (("quickstart slice (1024^2)", quickstart), ("benchmark slice (8192^2)", slice_8192)):
            sizes[name] = [ex.run(portable, job, 2)["size"]]
            if a.baseline:
                sizes[name].append(baseline_size(a.baseline, job, d))

    reps = range(a.repetitions)
    def kernel_rate(k):
        return [r["kernel"][i][k][0] for i in reps]
    scalar = median(kernel_rate("scalar"))
    print("\n| run (4096^2 slice unless said) | points/s | vs scalar kernel | notes |")
    print("|---|---|---|---|")
    for k in kernels:
        ns = median([r["kernel"][i][k][1] for i in reps])
        label = "scalar kernel, 1 core" if k == "scalar" else f"vectorised kernel {k}, 1 core"
        note = f"{ns:.2f} ns per iteration of G"
        if k == best:
            note += "; the portable binary's choice here"
        if k != "scalar":
            note = re.search(r"\((.*)\)", r["kernel"][0][k][2]).group(1) + "; " + note
        print(f"| {label} | {median(kernel_rate(k)):.3g} | {median(kernel_rate(k)) / scalar:.2f}x | {note} |")
    if native:
        rates = [x[0] for x in r["native_kernel"]]
        print(f"| vectorised kernel, native build ({native.kernel_text}) | {median(rates):.3g} | "
              f"{median(rates) / scalar:.2f}x | {median([x[1] for x in r['native_kernel']]):.2f} ns per iteration of G |")
    for key, label in (("n1", "`explore -n 1`"), ("n2", "`explore -n 2`")):
        rate = median([x["rate"] for x in r[key]])
        print(f"| {label} | {rate:.3g} | {rate / scalar:.2f}x | {median([x['wall'] for x in r[key]]):.2f} s wall incl. "
              f"start-up, peak {median([x['peak'] for x in r[key]]):.0f} MiB/rank |")
    if r["n2_16384"]:
        rate = median([x["rate"] for x in r["n2_16384"]])
        print(f"| `explore -n 2`, 16384^2 | {rate:.3g} | {rate / scalar:.2f}x | "
              f"{median([x['wall'] for x in r['n2_16384']]):.2f} s wall, "
              f"peak {median([x['peak'] for x in r['n2_16384']]):.0f} MiB/rank |")

    def ratio_line(text, values, fmt, target):
        print(f"{text}: {fmt.format(median(values))} {spread(values, fmt)} ({target})")

    print("\nThe whole process (mpirun started to exit) on the 8192^2 slice:")
    for key, ranks in (("s1_8192", 1), ("s2_8192", 2)):
        ratio_line(f"  explore -n {ranks}: wall / its own compute phase", [x["wall"] / x["compute"] for x in r[key]],
                   "{:.2f}x", f"{median([x['wall'] for x in r[key]]):.2f} s against "
                   f"{median([x['compute'] for x in r[key]]):.2f} s; target <= 1.15")
    ratio_line("  explore, one rank without mpirun (singleton): wall / its own compute phase",
               [x["wall"] / x["compute"] for x in r["single_8192"]], "{:.2f}x",
               f"{median([x['wall'] for x in r['single_8192']]):.2f} s against "
               f"{median([x['compute'] for x in r['single_8192']]):.2f} s (for comparison with -n 1)")
    ratio_line("  explore -n 1 / scalar kernel in a plain loop, one core",
               [r["s1_8192"][i]["wall"] / r["scalar"][i]["seconds"] for i in reps], "{:.2f}x",
               f"{median([x['seconds'] for x in r['scalar']]):.2f} s for the loop; totals of wall bounces "
               f"{'identical' if all(x['total'] == totals['explore'] for x in r['scalar']) else 'DIFFERENT'} "
               f"({totals['explore']}); target <= 1.0")
    ratio_line("  explore -n 2 / explore -n 1", [r["s2_8192"][i]["wall"] / r["s1_8192"][i]["wall"] for i in reps],
               "{:.2f}x", "target <= 0.56")
    print("\nThe closing pass (from the last tile counted to the result under its name), -n 2 except the 8192^2 -n 1:")
    closing = [("4096^2 slice", r["n2"]), ("8192^2 slice, -n 1", r["s1_8192"]), ("8192^2 slice", r["s2_8192"]),
               ("16384^2 slice", r["n2_16384"]), ("4096 x 4096 x 16 volume", r["volume"])]
    for label, runs in closing:
        if runs:
            ratio_line(f"  {label}: closing / wall", [x["closing"] / x["wall"] for x in runs], "{:.1%}",
                       f"{1e3 * median([x['closing'] for x in runs]):.2g} ms of {median([x['wall'] for x in runs]):.2f} s; "
                       "target <= 5 %")
    tiles = 8192 * 8192 // 1024 - 8192 * 8192 // 262144
    ratio_line("\ncost per tile, whole process (trivial 8192^2 grid, -n 1, 1024- against 262144-point tiles)",
               [(r["tile1024"][i]["wall"] - r["tile262144"][i]["wall"]) / tiles * 1e6 for i in reps], "{:.1f} us",
               f"wall {median([x['wall'] for x in r['tile1024']]):.2f} s with 1024-point tiles, "
               f"{median([x['wall'] for x in r['tile262144']]):.2f} s with 262144; target <= 3 us")
    calls = [c for c, _ in r["calls"]]
    ratio_line("write calls to the result file per million points (8192^2 slice, -n 2)",
               [c / (8192 * 8192 / 1e6) for c in calls], "{:.2f}",
               f"{median(calls):.0f} calls, {median([b for _, b in r['calls']]) / 1e6:.2f} MB")
    if native:
        ratio_line("portable / native build, explore -n 1 points/s (8192^2 slice)",
                   [r["p8192"][i]["rate"] / r["n8192"][i]["rate"] for i in reps], "{:.2f}",
                   f"{median([x['compute'] for x in r['p8192']]):.2f} s against "
                   f"{median([x['compute'] for x in r['n8192']]):.2f} s; target >= 0.95")
        ratio_line("portable / native build, bare kernel (4096^2 slice)",
                   [kernel_rate(best)[i] / r["native_kernel"][i][0] for i in reps], "{:.2f}",
                   f"{best} against {native.kernel}")
    for key, label in (("single", "singleton `superball explore`"), ("mpirun", "`mpirun -n 2 superball explore`")):
        print(f"64^2 job, {label}: {median(r[key]):.2f} s wall {spread(r[key], '{:.2f}')}; with Open MPI's own "
              f"start-up (OMPI_MCA_pml= OMPI_MCA_ess_singleton_isolated=0): {median(r[key + '_before']):.2f} s "
              f"{spread(r[key + '_before'], '{:.2f}')} (target <= 0.20 s)")
    if r["n2_16384"]:
        ratio_line("peak memory per rank 16384^2 / 4096^2 (2 ranks)",
                   [r["n2_16384"][i]["peak"] / r["n2"][i]["peak"] for i in reps], "{:.3f}", "target < 1.10")
    print("\n| result at the default level (-n 2) | bytes | baseline | ratio |")
    print("|---|---|---|---|")
    for name, values in sizes.items():
        base = f"{values[1]} | {values[0] / values[1]:.3f}" if len(values) > 1 else "- | -"
        print(f"| {name} | {values[0]} | {base} |")
    if mismatch:
        print("\n| refine = 8 against the full grid (2 ranks) | speed-up | points that differ |")
        print("|---|---|---|")
        for name, label in (("slice", "4096^2 slice"), ("volume", "256^3 volume, U in [-3, -0.05]")):
            values = r[f"refine_{name}"]
            print(f"| {label} | {median(values):.2f}x {spread(values, '{:.2f}')} | {100 * mismatch[name]:.4f}% |")


def baseline_size(binary, job, workdir):
    """Bytes of the result `binary` (another superball) writes for `job` at 2 ranks."""
    out = os.path.join(workdir, "baseline.h5")
    cmd = ["mpirun", "-n", "2", "--oversubscribe", binary, "explore", job, "-o", out, "--overwrite", "-q"]
    r = subprocess.run(cmd, capture_output=True, text=True, env=without_kernel_choice())
    if r.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed:\n{r.stderr}")
    size = os.path.getsize(out)
    for path in (out, os.path.join(workdir, "baseline.xmf")):
        if os.path.exists(path):
            os.remove(path)
    return size


if __name__ == "__main__":
    main()
