#!/usr/bin/python3
"""Region map of a superball result: which launches bounce how many times on the wall.

A 2-D result is drawn as a map, a 3-D result as a 2-D slice (--slice fixes one
axis), a 1-D result (or a 2-D one sliced once more) as a line with a colour strip.
Only the requested slice is read from the file.
"""

import argparse
import math
import os
import re
import sys
from typing import NamedTuple, Optional

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from superball_results import (  # noqa: E402  (needs the path above)
    CAPPED,
    INVALID,
    OUTCOME_NAMES,
    Result,
    ScriptError,
    axis_label,
    cell_edges,
    format_number,
    new_figure,
    parse_size,
    pyplot,
    run_script,
    warn_if_incomplete,
)

# More distinct counts than this are grouped into bins so colours stay distinguishable.
MAX_COUNT_CLASSES = 15
# Colours (8-bit RGB) with a fixed meaning in every map.
INVALID_COLOUR = (153, 153, 153)  # neutral grey
CAPPED_COLOUR = (0, 0, 0)
OUTCOME_COLOURS = np.array([INVALID_COLOUR, (31, 119, 180), (255, 127, 14), CAPPED_COLOUR], dtype=np.uint8)
# Colour map for counts, sampled away from its dark and light ends (which could pass for grey/black).
COUNT_COLOURMAP = "turbo"
COUNT_COLOURMAP_RANGE = (0.1, 0.95)
# count_bins tries at most this many times max_classes bins before settling.
MAX_BINNING_TRIES = 64
# A figure shows at most this many samples per axis; larger grids are read with a stride.
MAX_FIGURE_SAMPLES = 2048
DPI = 100
# A line plot whose counts reach beyond this uses a symlog scale, so capped points do not flatten the rest.
SYMLOG_ABOVE = 30
# Default figure sizes in pixels, by (plotted dimensions, with outcome panel).
DEFAULT_SIZES = {(2, False): (1000, 700), (2, True): (1800, 700), (1, False): (1000, 500), (1, True): (1000, 600)}

DESCRIPTION = __doc__ + """
Colours: one per wall-bounce count N (more than %d distinct counts are grouped
into bins, the last one ">= k"; the legend says which counts each colour holds
and their share of the map); outcome invalid in grey, capped in black.

Output: a PNG (OUT, default next to the result: RESULT[_AXISINDEX].png) sized
--size pixels, plus OUT.pdf with --pdf.  --bare writes instead an image with
exactly one pixel per grid cell and nothing else (first axis to the right,
second axis up), for further processing; with --outcome also OUT_outcome.png.

Exit status: 0 done, 2 bad input (message names it), 1 other failure.
""" % MAX_COUNT_CLASSES


def parse_slice(text):
    """argparse type of --slice: 'AXIS=INDEX' (a non-negative integer) or 'AXIS=VALUE' (any other number)."""
    match = re.fullmatch(r"\s*(\w+)\s*=\s*(\S+)\s*", text)
    if not match:
        raise argparse.ArgumentTypeError(f"slice {text!r} is not AXIS=INDEX or AXIS=VALUE")
    name, number = match.groups()
    if re.fullmatch(r"\d+", number):
        return name, "index", int(number)
    try:
        value = float(number)
    except ValueError:
        raise argparse.ArgumentTypeError(f"slice {text!r}: {number!r} is neither an index nor a number")
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"slice {text!r}: the value must be finite")
    return name, "value", value


def parse_args(argv):
    parser = argparse.ArgumentParser(description=DESCRIPTION, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("result", help="result file (HDF5) written by `superball explore`")
    parser.add_argument("-o", "--output", help="output PNG (default: next to the result, named after it)")
    parser.add_argument("--pdf", action="store_true", help="also write the figure as PDF (OUT with .pdf)")
    parser.add_argument(
        "--slice",
        action="append",
        default=[],
        type=parse_slice,
        metavar="AXIS=INDEX|VALUE",
        help="fix an axis: by sample index (an integer, 0-based, e.g. U=5) or by the nearest sample "
        "to a value (a number with a sign, point or exponent, e.g. U=-1.0); repeatable. "
        "Needed once for a 3-D result.",
    )
    parser.add_argument(
        "--outcome", action="store_true", help="add a panel with the outcome (invalid/left/missed/capped)"
    )
    parser.add_argument(
        "--bare", action="store_true", help="write only the map pixels, one pixel per grid cell (no axes, no legend)"
    )
    parser.add_argument(
        "--stride",
        type=int,
        help=f"read every STRIDE-th sample of each plotted axis (default: 1 for --bare, otherwise the "
        f"smallest stride that keeps at most {MAX_FIGURE_SAMPLES} samples per axis)",
    )
    parser.add_argument("--size", type=parse_size, metavar="WxH", help="figure size in pixels (default by layout)")
    parser.add_argument(
        "--max-classes",
        type=int,
        default=MAX_COUNT_CLASSES,
        help=f"most colours for counts before grouping into bins (default {MAX_COUNT_CLASSES})",
    )
    args = parser.parse_args(argv)
    if args.bare and args.pdf:
        parser.error("--bare writes a raw PNG; it cannot be combined with --pdf")
    if args.stride is not None and args.stride < 1:
        parser.error(f"--stride {args.stride} is out of range: accepted >= 1")
    if args.max_classes < 1:
        parser.error(f"--max-classes {args.max_classes} is out of range: accepted >= 1")
    return args


def resolve_slices(result, slices):
    """Turn --slice requests into {dimension: sample index}, refusing what the file cannot satisfy."""
    fixed = {}
    for name, kind, number in slices:
        if name not in result.axis_names:
            why = f"{name} is fixed in this file ({result.fixed_text()})" if name in result.fixed() else (
                f"{result.path} has no axis {name!r}"
            )
            raise ScriptError(f"--slice {name}: {why}; its axes are {', '.join(result.axis_names)}")
        dim = result.axis_names.index(name)
        if dim in fixed:
            raise ScriptError(f"--slice {name} is given twice")
        samples = result.axes[name]
        if kind == "index":
            if number >= len(samples):
                raise ScriptError(
                    f"--slice {name}={number}: index out of range, axis {name} has {len(samples)} samples"
                )
            fixed[dim] = number
        else:
            low, high = sorted(cell_edges(samples))
            if not low <= number <= high:
                raise ScriptError(
                    f"--slice {name}={number}: value outside the axis range "
                    f"[{format_number(low)}, {format_number(high)}]"
                )
            fixed[dim] = int(np.argmin(np.abs(samples - number)))
    remaining = len(result.axis_names) - len(fixed)
    if remaining > 2:
        raise ScriptError(
            f"{result.path} is {len(result.axis_names)}-D: give --slice AXIS=INDEX|VALUE for one of "
            f"{', '.join(result.axis_names)} to choose a 2-D slice"
        )
    if remaining < 1:
        raise ScriptError("every axis is fixed by --slice: nothing left to plot")
    return fixed


def read_map(result, fixed, stride):
    """Read only the requested slice of counts and outcomes, with its axes' names and samples.

    With a stride, the sample in the middle of each run of `stride` is read, so
    its widened cell still sits (within half a cell) where that run lies.
    """
    every = slice(stride // 2, None, stride)
    index = tuple(fixed[dim] if dim in fixed else every for dim in range(len(result.axis_names)))
    names = [name for dim, name in enumerate(result.axis_names) if dim not in fixed]
    samples = [result.axes[name][every] for name in names]
    counts, outcomes = result.read(index)
    return counts, outcomes, names, samples


def count_bins(values, max_classes):
    """Group distinct counts into at most `max_classes` runs (first, last present value).

    Few counts get one class each.  Otherwise bins grow geometrically (counts
    spread over decades: 0, 1, 2, ... 8-11, 12-19, ...), and the finest such
    binning that fits is chosen; each bin's bounds are the counts really present.
    """
    values = np.unique(np.asarray(values, dtype=np.int64))
    if len(values) <= max_classes:
        return [(int(v), int(v)) for v in values]
    best = None
    for n in range(max_classes, MAX_BINNING_TRIES * max_classes):
        groups = np.searchsorted(geometric_starts(values[0], values[-1], n), values, side="right") - 1
        if len(np.unique(groups)) > max_classes:
            break
        best = groups
    edges = np.flatnonzero(np.diff(best)) + 1
    return [(int(run[0]), int(run[-1])) for run in np.split(values, edges)]


def geometric_starts(low, high, n):
    """Up to n increasing integer bin starts from low, spaced geometrically in (count + 1) below high.

    Where rounding would merge neighbours (small counts), starts step by one
    instead, so small counts keep a class each.
    """
    starts = [int(low)]
    for target in np.geomspace(low + 1, high + 1, n + 1)[1:-1] - 1:
        start = max(int(round(target)), starts[-1] + 1)
        if start > high:
            break
        starts.append(start)
    return np.array(starts, dtype=np.int64)


class CountClasses:
    """Colour classes of a map: one per count bin, then invalid (grey) and capped (black).

    Built from the data being drawn, so the legend lists exactly what is on the map.
    """

    def __init__(self, counts, outcomes, max_classes):
        regular = counts[(outcomes != INVALID) & (outcomes != CAPPED)]
        self.bins = count_bins(regular, max_classes)
        self.grouped = any(low != high for low, high in self.bins)
        self.lows = np.array([low for low, _ in self.bins], dtype=np.int64)
        self.invalid = len(self.bins)
        self.capped = len(self.bins) + 1
        self.palette = np.vstack([sequential_colours(len(self.bins)), [INVALID_COLOUR, CAPPED_COLOUR]]).astype(np.uint8)
        self.labels = [bin_label(low, high, last=i == len(self.bins) - 1) for i, (low, high) in enumerate(self.bins)]
        self.labels += ["invalid", "capped (N = max_bounces)"]

    def classify(self, counts, outcomes):
        """Class index of every point (same shape as counts)."""
        classes = np.searchsorted(self.lows, counts.astype(np.int64), side="right") - 1
        classes[outcomes == INVALID] = self.invalid
        classes[outcomes == CAPPED] = self.capped
        return classes


def sequential_colours(k):
    """k distinct 8-bit colours in count order from the count colour map."""
    import matplotlib

    low, high = COUNT_COLOURMAP_RANGE
    positions = np.linspace(low, high, k) if k > 1 else np.full(k, 0.5 * (low + high))
    return np.round(matplotlib.colormaps[COUNT_COLOURMAP](positions)[:, :3] * 255).astype(np.uint8).reshape(k, 3)


def bin_label(low, high, last):
    """Legend text of a count bin; a grouped top bin reads '>= k' and says its maximum."""
    if low == high:
        return f"N = {low}"
    if last:
        return f"N >= {low} (max {high})"
    return f"N = {low}-{high}"


def outcome_classes(outcomes):
    """Outcome codes as class indices into OUTCOME_COLOURS (Result.read has checked them: 0 to 3)."""
    return outcomes.astype(np.intp)


def legend_handles(palette, labels, classes):
    """Legend patches for the classes present in the map, each with its share of the points."""
    from matplotlib.patches import Patch

    shares = np.bincount(classes.ravel(), minlength=len(labels)) / max(classes.size, 1)
    return [
        Patch(facecolor=palette[i] / 255, edgecolor="0.3", label=f"{labels[i]}  ({percent(shares[i])})")
        for i in range(len(labels))
        if shares[i] > 0
    ]


def percent(share):
    """A share as a percentage that never rounds a present class to 0."""
    return "< 0.1 %" if 0 < share < 0.001 else f"{100 * share:.1f} %"


def image_rows(rgb):
    """Rows of an image from a map indexed [first axis, second axis]: second axis upward, origin at bottom."""
    return rgb.swapaxes(0, 1) if rgb.ndim == 3 else rgb[np.newaxis, :]


def draw_map(ax, rgb, names, samples):
    """Draw a 2-D map as an image placed on the cell-centred samples; axis directions follow the samples."""
    extent = (*cell_edges(samples[0]), *cell_edges(samples[1]))
    ax.imshow(image_rows(rgb), origin="lower", extent=extent, interpolation="none", aspect="auto")
    ax.set_xlabel(axis_label(names[0]))
    ax.set_ylabel(axis_label(names[1]))


def draw_strip(ax, rgb, samples, label):
    """Draw a 1-D map as a one-row colour strip over the sample range."""
    ax.imshow(image_rows(rgb), origin="lower", extent=(*cell_edges(samples), 0, 1), interpolation="none", aspect="auto")
    ax.set_yticks([])
    ax.set_ylabel(label, rotation=0, ha="right", va="center")


def add_legend(ax, handles, title):
    ax.legend(handles=handles, title=title, loc="upper left", bbox_to_anchor=(1.02, 1), fontsize="small",
              title_fontsize="small", frameon=False)


def title_text(result, names, fixed, stride):
    """Figure title: file and what is mapped, fixed coordinates and slice, model and max_bounces."""
    plotted = " vs ".join(reversed(names)) if len(names) == 2 else f"along {names[0]}"
    first = f"{os.path.basename(result.path)}: wall bounces, {plotted}"
    if result.complete is False:
        first += " (incomplete)"
    details = [f"fixed: {result.fixed_text()}"] if result.fixed() else []
    if fixed:
        pairs = ((result.axis_names[dim], index) for dim, index in sorted(fixed.items()))
        details.append("slice: " + ", ".join(
            f"{name} = {format_number(result.axes[name][index])} (index {index})" for name, index in pairs))
    if stride > 1:
        details.append(f"1 sample in {stride} shown along each axis")
    return "\n".join([first] + (["; ".join(details)] if details else []) + [result.model_text()])


class View(NamedTuple):
    """What a map shows: plotted axes, the counts read, and each point's colour class."""

    names: list
    samples: list
    counts: np.ndarray
    classes: CountClasses
    count_idx: np.ndarray
    outcome_idx: Optional[np.ndarray]  # None unless --outcome

    @property
    def counts_rgb(self):
        return self.classes.palette[self.count_idx]

    @property
    def outcome_rgb(self):
        return OUTCOME_COLOURS[self.outcome_idx]


def write_figure(view, title, size, outputs):
    """Draw the map(s) with legends and title, and save to every path in `outputs` (PNG, PDF)."""
    fig = new_figure(size, DPI)
    count_handles = legend_handles(view.classes.palette, view.classes.labels, view.count_idx)
    count_title = "wall bounces N" + (" (grouped)" if view.classes.grouped else "")
    with_outcome = view.outcome_idx is not None
    if with_outcome:
        outcome_handles = legend_handles(OUTCOME_COLOURS, OUTCOME_NAMES, view.outcome_idx)
    if len(view.names) == 2:
        axes = fig.subplots(1, 2 if with_outcome else 1, squeeze=False)[0]
        draw_map(axes[0], view.counts_rgb, view.names, view.samples)
        add_legend(axes[0], count_handles, count_title)
        if with_outcome:
            draw_map(axes[1], view.outcome_rgb, view.names, view.samples)
            add_legend(axes[1], outcome_handles, "outcome")
    else:
        ratios = [4, 1, 1] if with_outcome else [4, 1]
        axes = fig.subplots(len(ratios), 1, sharex=True, gridspec_kw={"height_ratios": ratios})
        x = view.samples[0]
        axes[0].step(x, view.counts, where="mid", color="0.6", linewidth=0.8)
        axes[0].scatter(x, view.counts, c=view.counts_rgb / 255, s=12, zorder=3)
        axes[0].set_ylabel("wall bounces N")
        if view.counts.max(initial=0) > SYMLOG_ABOVE:
            axes[0].set_yscale("symlog", linthresh=SYMLOG_ABOVE / 3)
        add_legend(axes[0], count_handles, count_title)
        draw_strip(axes[1], view.counts_rgb, x, "N")
        if with_outcome:
            draw_strip(axes[2], view.outcome_rgb, x, "outcome")
            add_legend(axes[2], outcome_handles, "outcome")
        axes[-1].set_xlabel(axis_label(view.names[0]))
    fig.suptitle(title, fontsize="medium")
    for path in outputs:
        fig.savefig(path, dpi=DPI)
    pyplot().close(fig)


def write_bare(path, rgb):
    """Save map pixels only: one pixel per cell, first axis to the right, second axis up."""
    from PIL import Image

    Image.fromarray(np.ascontiguousarray(np.flipud(image_rows(rgb)))).save(path)


def default_output(args, result, fixed):
    """RESULT.png next to the result, with the slice in the name (RESULT_U5.png) and _bare for --bare."""
    stem = os.path.splitext(args.result)[0]
    for dim, index in sorted(fixed.items()):
        stem += f"_{result.axis_names[dim]}{index}"
    return stem + ("_bare" if args.bare else "") + ".png"


def main(argv=None):
    args = parse_args(argv)
    with Result(args.result) as result:
        fixed = resolve_slices(result, args.slice)
        plotted_sizes = [n for dim, n in enumerate(result.shape) if dim not in fixed]
        stride = args.stride or (1 if args.bare else max(1, math.ceil(max(plotted_sizes) / MAX_FIGURE_SAMPLES)))
        counts, outcomes, names, samples = read_map(result, fixed, stride)
        warn_if_incomplete(result)
        output = args.output or default_output(args, result, fixed)

        classes = CountClasses(counts, outcomes, args.max_classes)
        outcome_idx = outcome_classes(outcomes) if args.outcome else None
        view = View(names, samples, counts, classes, classes.classify(counts, outcomes), outcome_idx)
        if args.bare:
            write_bare(output, view.counts_rgb)
            if args.outcome:
                write_bare(os.path.splitext(output)[0] + "_outcome.png", view.outcome_rgb)
        else:
            title = title_text(result, names, fixed, stride)
            size = args.size or DEFAULT_SIZES[(len(names), args.outcome)]
            outputs = [output] + ([os.path.splitext(output)[0] + ".pdf"] if args.pdf else [])
            write_figure(view, title, size, outputs)
    print(output)
    return 0


if __name__ == "__main__":
    run_script(main)
