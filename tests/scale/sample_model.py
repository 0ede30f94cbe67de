#!/usr/bin/python3
"""The job-specific constants of the scaling simulation's cost model, from the job's
low-resolution sample computed at -n 1 (tests/scale/simulate.sh, validate.sh): the cost of
a wall bounce (the sample's compute time less NS_PER_POINT per point and US_PER_TILE per
tile, over its wall bounces; the calibration's value when the sample has none) and how the
data compress (raw bytes over stored bytes). Prints "NS_PER_ITERATION RATIO".

    sample_model.py SAMPLE.h5 SECONDS TILES NS_PER_POINT US_PER_TILE NS_PER_ITERATION
"""
import sys

import h5py
import numpy as np


def main():
    path = sys.argv[1]
    seconds, tiles, ns_point, us_tile, ns_iteration = (float(x) for x in sys.argv[2:7])
    with h5py.File(path) as f:
        data = [f[n] for n in ("wall_bounces", "outcome")]
        bounces = float(np.sum(f["wall_bounces"][()], dtype=np.float64))
        points = data[0].size
        ratio = sum(d.size * d.dtype.itemsize for d in data) / sum(d.id.get_storage_size() for d in data)
    if bounces > 0:
        ns_iteration = (seconds - points * ns_point * 1e-9 - tiles * us_tile * 1e-6) / bounces * 1e9
    print(f"{max(ns_iteration, 0.0):.3f} {ratio:.2f}")


if __name__ == "__main__":
    main()
