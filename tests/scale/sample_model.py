#!/usr/bin/python3
"""The job-specific constant of the scaling simulation's cost model, from the job's
low-resolution sample computed at -n 1 (tests/scale/simulate.sh, validate.sh): the cost of
a wall bounce (the sample's compute time less NS_PER_POINT per point and US_PER_TILE per
tile, over its wall bounces; the calibration's value when the sample has none). Prints
NS_PER_ITERATION. (How the job's data compress: chunk_ratio.py, at full resolution.)

    sample_model.py SAMPLE.h5 SECONDS TILES NS_PER_POINT US_PER_TILE NS_PER_ITERATION
"""
import sys

import h5py
import numpy as np


def main():
    path = sys.argv[1]
    seconds, tiles, ns_point, us_tile, ns_iteration = (float(x) for x in sys.argv[2:7])
    with h5py.File(path) as f:
        bounces = float(np.sum(f["wall_bounces"][()], dtype=np.float64))
        points = f["wall_bounces"].size
    if bounces > 0:
        ns_iteration = (seconds - points * ns_point * 1e-9 - tiles * us_tile * 1e-6) / bounces * 1e9
    print(f"{max(ns_iteration, 0.0):.3f}")


if __name__ == "__main__":
    main()
