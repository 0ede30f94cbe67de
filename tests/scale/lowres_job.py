#!/usr/bin/python3
"""Writes a lower-resolution copy of a job: the same model, ranges and max_bounces, fewer
samples (the longest range halved until the grid has at most --points points), its own
output, uncompressed (the sample's time is the counting's). Its result is the sample the cost model of the scaling simulation scales up
(tests/scale/simulate.sh).

    lowres_job.py JOB.toml OUT.toml OUTPUT.h5 [--points 2200000]
"""
import argparse
import tomllib


def value(v):
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{k} = {value(x)}" for k, x in v.items()) + " }"
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    return repr(v)


def write_tables(job, f, gap=""):
    """The job's [model], [grid] and [run] tables as TOML into `f`, `gap` before each."""
    for table in ("model", "grid", "run"):
        if table in job:
            f.write(f"{gap}[{table}]\n" + "".join(f"{k} = {value(v)}\n" for k, v in job[table].items()))


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("job")
    p.add_argument("out")
    p.add_argument("output")
    p.add_argument("--points", type=int, default=2_200_000)
    a = p.parse_args()
    with open(a.job, "rb") as f:
        job = tomllib.load(f)
    ranges = [t[k] for t in (job.get("model", {}), job["grid"]) for k in t if isinstance(t[k], dict)]

    def points():
        n = 1
        for r in ranges:
            n *= r["n"]
        return n

    while points() > a.points:
        longest = max(ranges, key=lambda r: r["n"])
        longest["n"] = (longest["n"] + 1) // 2
    run = {k: v for k, v in job.get("run", {}).items() if k not in ("tile_points", "output", "compression")}
    run["output"] = a.output
    # Counting only: compression is charged apart (scale_costs measures it on these data).
    run["compression"] = 0
    job["run"] = run
    with open(a.out, "w") as f:
        f.write(f"# Lower-resolution sample of {a.job} for the scaling simulation (tests/scale/lowres_job.py).\n")
        write_tables(job, f, gap="\n")


if __name__ == "__main__":
    main()
