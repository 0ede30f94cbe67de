#!/usr/bin/python3
"""How far a job's result compresses, measured at full resolution on a random sample of its
chunks: the scaling simulation's compression ratio (tests/scale/simulate.sh).

A compressed result's chunk is a tile. This picks BOXES tiles of the job's tiling at
--box-points points (job/tiles.cpp default_tile_shape: the longest axis halved until the
tile holds at most that many points) uniformly at random, and computes each one with the
real superball (`explore` at -n 1) as a job of its own: the same model, the same samples
(sample i of a range is min + (i + 1/2) (max - min) / n, so a sub-range of the full one holds
exactly the job's samples), the job's compression level, once per --tile-points: tiles of
fewer points are the job's own tiles at that size (the halving goes on from the box, as it
would from the whole grid), so each run writes exactly the chunks the job would write there.
The sizes are what the binary stored (h5py: the storage of /wall_bounces and /outcome; the
file's own metadata, a few kB, left out: the job has one set of it, not one per box).

Prints one line per tile size:

    tile_points=T boxes=B raw_bytes=R stored_bytes=S ratio=X ratio_lo=L ratio_hi=H chunk_bytes=C seconds=W

ratio = R / S (the job's raw bytes over its stored bytes, estimated as the boxes' sums: the
boxes are a uniform sample of the grid); [L, H] is a 90 % bootstrap interval over the
boxes; chunk_bytes the mean stored bytes of one chunk; seconds the compute time of the runs;
compress_mbps the raw MB a core compresses per second in chunks of that size (with
--codec-speed: tests/scale/codec_speed, encoding each box's chunks as a rank does, on the
job's own data: flat regions compress several times faster than a basin's fine boundary).

    chunk_ratio.py JOB.toml --superball BIN [--box-points 65536] [--tile-points "8192 16384 65536"]
                   [--boxes 32] [--seed 1] [--work DIR] [--codec-speed BIN]
"""
import argparse
import os
import random
import re
import subprocess
import sys
import tomllib

import h5py
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from lowres_job import value  # noqa: E402  (the same TOML writer)


def tile_shape(shape, target):
    """job/tiles.cpp default_tile_shape."""
    tile = list(shape)
    while np.prod(tile, dtype=np.int64) > target:
        k = tile.index(max(tile))  # std::max_element: the first longest
        if tile[k] == 1:
            break
        tile[k] = (tile[k] + 1) // 2
    return tile


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("job")
    p.add_argument("--superball", required=True)
    p.add_argument("--box-points", type=int, default=65536)
    p.add_argument("--tile-points", default="8192 16384 65536")
    p.add_argument("--boxes", type=int, default=32)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--work", default="build/scale/chunks")
    p.add_argument("--codec-speed", help="tests/scale/codec_speed, to time the compression of each box")
    a = p.parse_args()
    sizes = [int(x) for x in a.tile_points.split()]
    if max(sizes) > a.box_points:
        sys.exit("chunk_ratio: a tile size above --box-points")
    with open(a.job, "rb") as f:
        job = tomllib.load(f)
    # The range axes in the result's order: swept coefficients, then the grid's.
    ranges = [(t, k) for t in ("model", "grid") for k in job.get(t, {}) if isinstance(job[t][k], dict)]
    shape = [job[t][k]["n"] for t, k in ranges]
    box = tile_shape(shape, a.box_points)
    per_axis = [-(-n // b) for n, b in zip(shape, box)]
    boxes = int(np.prod(per_axis, dtype=np.int64))
    rng = random.Random(a.seed)
    chosen = sorted(rng.sample(range(boxes), min(a.boxes, boxes)))
    os.makedirs(a.work, exist_ok=True)
    env = dict(os.environ)
    if os.getuid() == 0:
        env.update(OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    level = job.get("run", {}).get("compression", 4)
    if level == 0:
        sys.exit("chunk_ratio: the job is uncompressed ([run] compression = 0)")
    raw = {s: [] for s in sizes}
    stored = {s: [] for s in sizes}
    chunks = {s: 0 for s in sizes}
    seconds = {s: 0.0 for s in sizes}
    codec = {s: [0, 0.0] for s in sizes}  # raw bytes, seconds
    name = os.path.splitext(os.path.basename(a.job))[0]
    for i, b in enumerate(chosen):
        # Box b's first sample along each axis (the last axis varies fastest).
        start, rest = [0] * len(shape), b
        for k in reversed(range(len(shape))):
            start[k] = (rest % per_axis[k]) * box[k]
            rest //= per_axis[k]
        count = [min(box[k], shape[k] - start[k]) for k in range(len(shape))]
        sub = {t: dict(job.get(t, {})) for t in ("model", "grid")}
        for (t, k), s, c in zip(ranges, start, count):
            r = job[t][k]
            h = (r["max"] - r["min"]) / r["n"]
            sub[t][k] = {"min": r["min"] + s * h, "max": r["min"] + (s + c) * h, "n": c}
        for size in sizes:
            out = os.path.abspath(f"{a.work}/{name}.{i}.{size}.h5")
            run = {k: v for k, v in job.get("run", {}).items() if k not in ("output", "tile_points")}
            run.update(output=out, tile_points=size, compression=level)
            path = f"{a.work}/{name}.{i}.{size}.toml"
            with open(path, "w") as f:
                for t, table in (("model", sub["model"]), ("grid", sub["grid"]), ("run", run)):
                    if table:
                        f.write(f"[{t}]\n" + "".join(f"{k} = {value(v)}\n" for k, v in table.items()))
            r = subprocess.run(["mpirun", "-n", "1", a.superball, "explore", path, "--overwrite"], env=env,
                               capture_output=True, text=True)
            if r.returncode != 0:
                sys.exit(f"chunk_ratio: {path} failed:\n{r.stdout}{r.stderr}")
            m = re.search(r"computed in ([0-9.]+) s", r.stdout + r.stderr)
            seconds[size] += float(m.group(1)) if m else 0.0
            with h5py.File(out) as f:
                data = [f["wall_bounces"], f["outcome"]]
                if list(data[0].shape) != count:
                    sys.exit(f"chunk_ratio: {out} has shape {data[0].shape}, expected {count}")
                raw[size].append(sum(d.size * d.dtype.itemsize for d in data))
                stored[size].append(sum(d.id.get_storage_size() for d in data))
                chunks[size] += int(np.prod([-(-n // c) for n, c in zip(count, data[0].chunks)]))
            if a.codec_speed:
                r = subprocess.run([a.codec_speed, out, str(level)], capture_output=True, text=True)
                m = re.search(r"raw_bytes=(\d+) seconds=([0-9.e+-]+)", r.stdout)
                if r.returncode != 0 or not m:
                    sys.exit(f"chunk_ratio: {a.codec_speed} {out} failed:\n{r.stdout}{r.stderr}")
                codec[size][0] += int(m.group(1))
                codec[size][1] += float(m.group(2))
            os.remove(out)
            xmf = os.path.splitext(out)[0] + ".xmf"
            if os.path.exists(xmf):
                os.remove(xmf)
        print(f"chunk_ratio: box {i + 1} of {len(chosen)} (#{b}, start {start})", file=sys.stderr)
    boot = np.random.default_rng(a.seed)
    for size in sizes:
        r, s = np.array(raw[size], float), np.array(stored[size], float)
        draws = boot.integers(0, len(r), (2000, len(r)))
        ratios = r[draws].sum(1) / s[draws].sum(1)
        lo, hi = np.percentile(ratios, [5, 95])
        print(f"tile_points={size} boxes={len(r)} raw_bytes={r.sum():.0f} stored_bytes={s.sum():.0f} "
              f"ratio={r.sum() / s.sum():.4g} ratio_lo={lo:.4g} ratio_hi={hi:.4g} chunk_bytes={s.sum() / chunks[size]:.0f} "
              f"seconds={seconds[size]:.1f}"
              + (f" compress_mbps={codec[size][0] / codec[size][1] / 1e6:.0f}" if codec[size][1] > 0 else ""))


if __name__ == "__main__":
    main()
