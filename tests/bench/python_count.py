#!/usr/bin/python3
"""Speed of the Python module's count() against the bare vectorised kernel (issue 23).

  count, 1 and 2 threads   superball.count(xi, U, W, e=0.9, alpha=0.9, threads=T) on N random
                           launches (default 4e6: xi in (0, 1), U in (-3, 0), W in (-3, 3),
                           float64 arrays, max_bounces 1000)
  kernel, 1 and 2 threads  bench_kernel's BM_count_launches: the same launches (written to a
                           file for it), the same kernel, each thread counting an equal
                           contiguous part in one call, with nothing in between
  2000^2 grid              superball.count(xi[:, None], -1.0, W[None, :], ...) on the
                           quickstart slice's plane (xi in (0, 1), W in [-3, 3], cell
                           centres) at 2000 x 2000, 2 threads (default: every core)

Targets: count on 2 threads >= 0.90 of the kernel on 2 threads, and >= 1.8 x the kernel on
1 thread; the 2000^2 grid <= 0.2 s. Each repetition runs every measurement once in the same
order (the load of a shared machine falls on all alike); a rate is points counted over
the time of calls repeated for at least --min-time seconds (Google Benchmark's rule for
the kernel). Figures are medians over the repetitions; ratios are taken within one
repetition, their median printed with the smallest and largest in brackets.

  /usr/bin/python3 tests/bench/python_count.py [--build build/release] [--repetitions 3]

Needs the build's superball module and bench_kernel (SUPERBALL_BENCHMARKS, on by default):
cmake --build build/release --target superball_python bench_kernel.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE = os.path.dirname(os.path.dirname(HERE))
MODEL = {"e": 0.9, "alpha": 0.9}


def load_module(build):
    path = os.path.join(build, "python")
    if not os.path.isdir(os.path.join(path, "superball")):
        sys.exit(f"python_count: no Python module in {path}: cmake --build {build} --target superball_python")
    sys.path.insert(0, path)
    import superball

    return superball


def launches(n, seed):
    rng = np.random.default_rng(seed)
    return rng.uniform(0.0, 1.0, n), rng.uniform(-3.0, 0.0, n), rng.uniform(-3.0, 3.0, n)


def rate(call, points, min_time):
    """Points per second of `call` (which counts `points`), repeated for at least min_time s."""
    calls, start = 0, time.perf_counter()
    while True:
        call()
        calls += 1
        elapsed = time.perf_counter() - start
        if elapsed >= min_time:
            return points * calls / elapsed, elapsed / calls


def kernel_rates(bench, launch_file, min_time):
    """{threads: points/s} of BM_count_launches on 1 and 2 threads."""
    env = dict(os.environ, SUPERBALL_BENCH_LAUNCHES=launch_file)
    env.pop("SUPERBALL_KERNEL", None)  # the kernel count() uses by default: the best one
    out = subprocess.run([bench, "--benchmark_filter=^BM_count_launches/", "--benchmark_format=json",
                          f"--benchmark_min_time={min_time}"], capture_output=True, text=True, check=True, env=env)
    report = json.loads(out.stdout)
    return {b["threads"]: b["items_per_second"] for b in report["benchmarks"]}, report["context"].get("superball", "")


def spread(values, fmt):
    return f"[{fmt.format(min(values))}, {fmt.format(max(values))}]"


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--build", default=os.path.join(SOURCE, "build", "release"), help="build tree (default build/release)")
    p.add_argument("--repetitions", type=int, default=3, help="interleaved repetitions, at least 3 (default 3)")
    p.add_argument("--points", type=float, default=4e6, help="random launches (default 4e6)")
    p.add_argument("--grid", type=int, default=2000, help="the grid's side (default 2000)")
    p.add_argument("--min-time", type=float, default=1.0, help="seconds each rate is measured over (default 1)")
    a = p.parse_args()
    if a.repetitions < 3:
        p.error("--repetitions: at least 3 (every figure is a median of at least 3)")
    build = os.path.abspath(a.build)
    bench = os.path.join(build, "tests", "bench", "bench_kernel")
    if not os.access(bench, os.X_OK):
        sys.exit(f"python_count: {bench} is missing: cmake --build {a.build} --target bench_kernel")
    superball = load_module(build)
    os.environ.pop("SUPERBALL_KERNEL", None)
    n = int(a.points)
    xi, U, W = launches(n, 1)
    side = a.grid
    grid_xi = (np.arange(side) + 0.5) / side
    grid_W = -3.0 + 6.0 * (np.arange(side) + 0.5) / side
    cores = os.cpu_count()

    # Identical results first: a fast wrong answer is no answer.
    one, two = superball.count(xi, U, W, **MODEL, threads=1), superball.count(xi, U, W, **MODEL, threads=2)
    assert np.array_equal(one.wall_bounces, two.wall_bounces) and np.array_equal(one.outcome, two.outcome)

    r = {k: [] for k in ("k1", "k2", "c1", "c2", "grid")}
    with tempfile.TemporaryDirectory(prefix="superball-pycount-") as d:
        launch_file = os.path.join(d, "launches.f64")
        np.concatenate([xi, U, W]).tofile(launch_file)  # bench_kernel's layout: all xi, all U, all W
        for rep in range(a.repetitions):
            print(f"repetition {rep + 1} of {a.repetitions}", file=sys.stderr, flush=True)
            kernel, label = kernel_rates(bench, launch_file, a.min_time)
            r["k1"].append(kernel[1])
            r["k2"].append(kernel[2])
            for t in (1, 2):
                r[f"c{t}"].append(rate(lambda: superball.count(xi, U, W, **MODEL, threads=t), n, a.min_time)[0])
            r["grid"].append(rate(lambda: superball.count(grid_xi[:, None], -1.0, grid_W[None, :], **MODEL), side * side,
                                  a.min_time)[1])

    med = {k: statistics.median(v) for k, v in r.items()}
    reps = range(a.repetitions)
    print(f"{superball.SOURCE}; {cores} cores; {label}")
    print(f"{n} random launches (xi in (0, 1), U in (-3, 0), W in (-3, 3)), e = alpha = 0.9, max_bounces 1000; "
          f"medians of {a.repetitions} interleaved repetitions")
    print("\n| counting | points/s |\n|---|---|")
    for key, text in (("k1", "bare kernel, 1 thread"), ("k2", "bare kernel, 2 threads"), ("c1", "`count`, 1 thread"),
                      ("c2", "`count`, 2 threads")):
        print(f"| {text} | {med[key]:.3g} |")
    ratios = [("`count` 2 threads / kernel 2 threads", [r["c2"][i] / r["k2"][i] for i in reps], "target >= 0.90"),
              ("`count` 2 threads / kernel 1 thread", [r["c2"][i] / r["k1"][i] for i in reps], "target >= 1.8"),
              ("`count` 1 thread / kernel 1 thread", [r["c1"][i] / r["k1"][i] for i in reps], ""),
              ("`count` 2 threads / `count` 1 thread", [r["c2"][i] / r["c1"][i] for i in reps], "")]
    for text, values, target in ratios:
        print(f"{text}: {statistics.median(values):.3f} {spread(values, '{:.3f}')}" + (f" ({target})" if target else ""))
    print(f"`count` on the {side}^2 grid (broadcast arrays, every core): {med['grid']:.3f} s "
          f"{spread(r['grid'], '{:.3f}')} (target <= 0.2 s)")


if __name__ == "__main__":
    main()
