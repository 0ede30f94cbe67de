#!/usr/bin/python3
"""Summary of a superball result file: grid, model, completeness, and how the
grid's points divide among wall-bounce counts and outcomes.

The data are read in blocks of at most --block points (whole trailing axes,
runs along the first axes), so a 16384 x 16384 grid needs only one block's
memory.
"""

import argparse
import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from superball_results import (  # noqa: E402  (needs the path above)
    OUTCOME_NAMES,
    Result,
    format_number,
    iter_blocks,
    join_values,
    run_script,
    warn_if_incomplete,
)

# Points read at once (np.bincount widens them to 64-bit: 32 MiB per block).
BLOCK_POINTS = 1 << 22
# Above this largest count in a block, counts are tallied with np.unique instead
# of a dense np.bincount array (which would need one slot per possible count).
DENSE_COUNT_LIMIT = 1 << 22

DESCRIPTION = __doc__ + """
Output: a text report on standard output, or with --json one JSON object with
keys path, coordinates, axis_names, shape, points, axes, fixed, model,
max_bounces, complete, tiles_done, tiles, tile_fraction, wall_bounces (list of
{wall_bounces, points, fraction}) and outcome (list of {outcome, code, points,
fraction}).  Fractions are of all grid points, unfinished tiles included.

Exit status: 0 done, 2 bad input (message names it), 1 other failure.
"""


def add_counts(total, block):
    """Add the histogram of `block` to `total` (an int64 array indexed by value), growing it as needed."""
    largest = int(block.max(initial=0))
    if largest < DENSE_COUNT_LIMIT:
        histogram = np.bincount(block.ravel(), minlength=len(total))
    else:
        values, counts = np.unique(block, return_counts=True)
        histogram = np.zeros(largest + 1, dtype=np.int64)
        histogram[values] = counts
    if len(histogram) > len(total):
        total = np.pad(total, (0, len(histogram) - len(total)))
    total[: len(histogram)] += histogram
    return total


def histograms(result, block_points):
    """Points per wall-bounce count and per outcome code, accumulated block by block."""
    counts = np.zeros(0, dtype=np.int64)
    outcomes = np.zeros(len(OUTCOME_NAMES), dtype=np.int64)
    for index in iter_blocks(result.shape, block_points):
        block_counts, block_outcomes = result.read(index)
        counts = add_counts(counts, block_counts)
        outcomes = add_counts(outcomes, block_outcomes)
    return counts, outcomes


def summarise(result, block_points):
    """Everything the report shows, as plain data (the --json output)."""
    counts, outcomes = histograms(result, block_points)
    points = int(np.prod(result.shape, dtype=np.int64))
    tiles = result.tiles()
    return {
        "path": result.path,
        "coordinates": result.coordinates,
        "axis_names": result.axis_names,
        "shape": list(result.shape),
        "points": points,
        "axes": {
            name: {"n": len(v), "first": float(v[0]), "last": float(v[-1])} for name, v in result.axes.items()
        },
        "fixed": result.fixed(),
        "model": result.model(),
        "max_bounces": result.max_bounces,
        "complete": result.complete,
        "tiles_done": tiles[0] if tiles else None,
        "tiles": tiles[1] if tiles else None,
        "tile_fraction": tiles[0] / tiles[1] if tiles and tiles[1] else None,
        "wall_bounces": [
            {"wall_bounces": n, "points": int(c), "fraction": int(c) / points}
            for n, c in enumerate(counts)
            if c
        ],
        "outcome": [
            {"outcome": OUTCOME_NAMES[code], "code": code, "points": int(c), "fraction": int(c) / points}
            for code, c in enumerate(outcomes)
        ],
    }


def report(summary):
    """The summary as text for a terminal."""
    shape = " x ".join(str(n) for n in summary["shape"])
    names = " x ".join(summary["axis_names"])
    lines = [
        f"result:      {summary['path']}",
        f"coordinates: {summary['coordinates']}",
        f"grid:        {shape} ({names}) = {summary['points']} points",
    ]
    for name, axis in summary["axes"].items():
        first, last = format_number(axis["first"]), format_number(axis["last"])
        lines.append(f"  {name:<6} {axis['n']:>7} samples  {first} .. {last}")
    if summary["fixed"]:
        lines.append(f"fixed:       {join_values(summary['fixed'])}")
    lines.append(f"model:       {join_values(summary['model'], '=')}, max_bounces={summary['max_bounces']}")
    complete = {True: "yes", False: "NO (incomplete run)", None: "not recorded"}[summary["complete"]]
    if summary["tiles"] is not None:
        complete += (f"; tiles done {summary['tiles_done']} of {summary['tiles']} "
                     f"({100 * summary['tile_fraction']:.1f} %)")
    lines.append(f"complete:    {complete}")
    for key, title in (("wall_bounces", "wall bounces"), ("outcome", "outcome")):
        lines += ["", f"{title:>12} {'points':>12} {'fraction':>10}"]
        lines += [f"{row[key]:>12} {row['points']:>12} {row['fraction']:>10.6f}" for row in summary[key]]
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=DESCRIPTION, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("result", help="result file (HDF5) written by `superball explore`")
    parser.add_argument("--json", action="store_true", help="print one JSON object instead of the text report")
    parser.add_argument("--block", type=int, default=BLOCK_POINTS,
                        help=f"most grid points read at once (default {BLOCK_POINTS})")
    args = parser.parse_args(argv)
    if args.block < 1:
        parser.error(f"--block {args.block} is out of range: accepted >= 1")
    with Result(args.result) as result:
        summary = summarise(result, args.block)
        warn_if_incomplete(result)
    print(json.dumps(summary, indent=2) if args.json else report(summary))
    return 0


if __name__ == "__main__":
    run_script(main)
