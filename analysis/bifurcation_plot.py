#!/usr/bin/python3
"""Draw a bifurcation diagram: the branches of cycles `superball continue` followed in one
coefficient, or (with its --curve) the curves of their events in the plane of two.

Input is the CSV of `superball continue` (a file, or - for standard input), or `--run
ARGS...` to call the binary itself (from $SUPERBALL, else `superball` on PATH) as
`superball continue ARGS... --format csv`.
"""

import argparse
import csv
import io
import math
import os
import sys
import textwrap
from typing import NamedTuple

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from superball_results import (  # noqa: E402  (needs the path above)
    AXIS_LABELS,
    ScriptError,
    new_figure,
    parse_size,
    pyplot,
    run_script,
    run_superball,
)

# Columns after the parameter's, in the order `superball continue` writes them.
FIXED_COLUMNS = ("branch", "period", "corner")
VALUE_COLUMNS = ("xi", "U", "W", "lambda", "ev1_re", "ev1_im", "ev2_re", "ev2_im", "ev3_re", "ev3_im")
TEXT_COLUMNS = ("stability", "event", "note")
TAIL_COLUMNS = ("residual", "arclength", "bracket")
PARAMETERS = ("e", "alpha", "e_wall", "alpha_wall", "e_floor", "alpha_floor", "mu", "mu_wall", "mu_floor", "inertia")
STABILITIES = ("stable", "unstable", "saddle", "marginal")
# Marker of each event: (matplotlib marker, colour, label).
EVENT_STYLE = {
    "fold": ("v", "tab:red", "fold"),
    "period_doubling": ("s", "tab:purple", "period doubling"),
    "neimark_sacker": ("D", "tab:green", "Neimark-Sacker"),
    "branch_point": ("o", "tab:orange", "branch point"),
    # SPEC.md 1b: an impact of the cycle passes from gripping to sliding.
    "grip_slide": ("P", "tab:brown", "grip/slide (an impact starts or stops sliding)"),
    "boundary": ("X", "black", "boundary (branch leaves the region)"),
    "end": ("|", "0.4", "end"),
}
# Quantities that can be drawn against the parameter.
QUANTITIES = {
    "xi": AXIS_LABELS["xi"],
    "U": AXIS_LABELS["U"],
    "W": AXIS_LABELS["W"],
    "lambda": "lambda (scale factor per period)",
    "modulus": "largest |eigenvalue| of D(G^k)",
    "moduli": "|eigenvalues| of D(G^k)",
}
# Events drawn, in a panel of eigenvalue moduli, at the modulus that crosses 1 there.
CROSSING_EVENTS = ("fold", "period_doubling", "neimark_sacker", "branch_point")
DEFAULT_QUANTITIES = "U,modulus"
DPI = 100
# Characters per line of the title (the comment line of the CSV), wrapped to fit.
TITLE_WIDTH = 100
PNG_SIZE = (1000, 800)

DESCRIPTION = __doc__ + """
Branches: one panel per quantity (--y, default %s: U of the cycle's point with the
smallest xi, and the largest modulus of the eigenvalues of D(G^k)), against the
parameter. Each branch has its colour; a stretch where the cycle is stable is drawn
solid, one where it is not (unstable, saddle, marginal) dashed. Events are marked:
fold, period doubling, Neimark-Sacker, branch point, boundary, end.

Event curves (`superball continue --curve Q`): the curves in the plane of the two
coefficients, coloured by the kind of event, each labelled with the branch it came from.

Output: a PNG (-o, default named after the input, else bifurcation.png) and a PDF of
the same figure next to it (same name, .pdf).
Exit status: 0 done, 2 bad input (message names it), 1 other failure.
""" % DEFAULT_QUANTITIES


class Point(NamedTuple):
    """One CSV row."""

    branch: int
    period: int
    corner: bool
    parameter: float
    values: dict  # VALUE_COLUMNS -> float
    stability: str
    event: str
    note: str


class Diagram(NamedTuple):
    parameter: str
    title: str  # from the comment lines
    branches: dict  # branch number -> list of Point, in order along the branch


class CurvePoint(NamedTuple):
    """One row of the event-curve CSV."""

    curve: int
    branch: int
    event: str
    period: int
    corner: bool
    first: float
    second: float


class Curves(NamedTuple):
    parameters: tuple  # (first, second)
    title: str
    curves: dict  # curve number -> list of CurvePoint, in order along the curve


CURVE_COLUMNS = ("curve", "branch", "event", "period", "corner")
CURVE_TAIL = VALUE_COLUMNS + ("stability", "note")


def split_rows(text, source):
    """(comment lines, [(line number, fields)]) of a CSV with # comments."""
    if text.lstrip().startswith("{"):
        raise ScriptError(f"{source}: this is JSON; give the CSV of `superball continue` (--format csv)")
    comments = []
    rows = []
    for n, row in enumerate(csv.reader(io.StringIO(text)), 1):
        if not row:
            continue
        if row[0].startswith("#"):
            comments.append(",".join(row).lstrip("#").strip())
            continue
        rows.append((n, row))
    return comments, rows


def read_curves(comments, rows, source):
    """The event curves of `superball continue --curve` (rows[0] is the header)."""
    header = [field.strip() for field in rows[0][1]]
    expected = ",".join(CURVE_COLUMNS) + ",P,Q," + ",".join(CURVE_TAIL)
    if (len(header) != len(CURVE_COLUMNS) + 2 + len(CURVE_TAIL) or tuple(header[:5]) != CURVE_COLUMNS
            or header[5] not in PARAMETERS or header[6] not in PARAMETERS or tuple(header[7:]) != CURVE_TAIL):
        raise ScriptError(f"{source}: not a superball continue --curve CSV (expected the header {expected}, "
                          f"P and Q among {', '.join(PARAMETERS)})")
    curves = {}
    for line, row in rows[1:]:
        if len(row) != len(header):
            raise ScriptError(f"{source} line {line}: {len(row)} fields, expected {len(header)}")
        try:
            point = CurvePoint(int(row[0]), int(row[1]), row[2], int(row[3]), bool(int(row[4])), float(row[5]),
                               float(row[6]))
        except ValueError:
            raise ScriptError(f"{source} line {line}: a field is not a number")
        if point.event not in EVENT_STYLE:
            raise ScriptError(f"{source} line {line}: unknown event {point.event!r} (expected {', '.join(EVENT_STYLE)})")
        if not (math.isfinite(point.first) and math.isfinite(point.second)):
            raise ScriptError(f"{source} line {line}: {header[5]} or {header[6]} is not finite")
        curves.setdefault(point.curve, []).append(point)
    if not curves:
        raise ScriptError(f"{source}: the CSV has a header but no points")
    title = comments[0] if comments else f"superball continue: event curves in ({header[5]}, {header[6]})"
    return Curves((header[5], header[6]), title, curves)


def read_csv(text, source):
    """Parse `superball continue` CSV (branches, or event curves); every problem names the source
    and line."""
    comments, rows = split_rows(text, source)
    if rows and rows[0][1] and rows[0][1][0].strip() == "curve":
        return read_curves(comments, rows, source)
    expected = "branch,period,corner,PARAMETER," + ",".join(VALUE_COLUMNS + TEXT_COLUMNS + TAIL_COLUMNS)
    if not rows:
        raise ScriptError(f"{source}: no data (expected the header {expected})")
    header = [field.strip() for field in rows[0][1]]
    if (len(header) != len(FIXED_COLUMNS) + 1 + len(VALUE_COLUMNS) + len(TEXT_COLUMNS) + len(TAIL_COLUMNS)
            or tuple(header[:3]) != FIXED_COLUMNS or header[3] not in PARAMETERS
            or tuple(header[4:]) != VALUE_COLUMNS + TEXT_COLUMNS + TAIL_COLUMNS):
        raise ScriptError(f"{source}: not a superball continue CSV (expected the header {expected}, "
                          f"PARAMETER one of {', '.join(PARAMETERS)})")
    parameter = header[3]
    branches = {}
    for line, row in rows[1:]:
        if len(row) != len(header):
            raise ScriptError(f"{source} line {line}: {len(row)} fields, expected {len(header)}")
        try:
            branch, period, corner = int(row[0]), int(row[1]), int(row[2])
            numbers = [float(field) for field in row[3:14]]
        except ValueError:
            raise ScriptError(f"{source} line {line}: a field is not a number")
        if not all(math.isfinite(x) for x in numbers[:5]):
            raise ScriptError(f"{source} line {line}: {parameter}, xi, U, W or lambda is not finite")
        stability, event, note = row[14], row[15], row[16]
        if stability not in STABILITIES:
            raise ScriptError(f"{source} line {line}: unknown stability {stability!r} "
                              f"(expected {', '.join(STABILITIES)})")
        if event and event not in EVENT_STYLE:
            raise ScriptError(f"{source} line {line}: unknown event {event!r} (expected {', '.join(EVENT_STYLE)})")
        branches.setdefault(branch, []).append(
            Point(branch, period, bool(corner), numbers[0], dict(zip(VALUE_COLUMNS, numbers[1:])), stability,
                  event, note))
    if not branches:
        raise ScriptError(f"{source}: the CSV has a header but no points")
    title = comments[0] if comments else f"superball continue in {parameter}"
    return Diagram(parameter, title, branches)


def moduli(point):
    v = point.values
    return [math.hypot(v[f"ev{i}_re"], v[f"ev{i}_im"]) for i in (1, 2, 3)]


def quantity(point, name):
    """The values of a quantity (see QUANTITIES) at a point: one, or three for moduli."""
    if name == "modulus":
        return [max(moduli(point))]
    if name == "moduli":
        return moduli(point)
    return [point.values[name]]


def marker_value(point, name):
    """Where an event's marker goes: at an eigenvalue crossing, the modulus nearest 1."""
    values = quantity(point, name)
    if name == "moduli" and point.event in CROSSING_EVENTS:
        return min(values, key=lambda m: abs(m - 1.0))
    return max(values)


def stretches(points):
    """The branch cut into runs drawn alike: (stable, points). A segment is stable when both
    ends are, an event point (where the stability changes) taking the other end's status;
    consecutive runs share their end point so the line is unbroken."""
    def stable(a, b):
        ends = [p.stability == "stable" for p in (a, b) if not p.event] or [a.stability == "stable"]
        return all(ends)

    runs = []
    for i in range(len(points) - 1):
        style = stable(points[i], points[i + 1])
        if runs and runs[-1][0] == style:
            runs[-1][1].append(points[i + 1])
        else:
            runs.append((style, [points[i], points[i + 1]]))
    if not runs and points:
        runs.append((points[0].stability == "stable", points[:1]))
    return runs


def branch_label(points):
    first = points[0]
    where = " corner" if first.corner else ""
    return f"branch {first.branch}: period {first.period}{where}"


def draw(diagram, names, size, png, pdf):
    """One panel per quantity against the parameter; returns the number of lines drawn."""
    from matplotlib.lines import Line2D

    fig = new_figure(size, DPI)
    axes = fig.subplots(len(names), 1, sharex=True, squeeze=False)[:, 0]
    colours = pyplot().rcParams["axes.prop_cycle"].by_key()["color"]
    seen_events = set()
    lines = 0
    for ax, name in zip(axes, names):
        for n, (number, points) in enumerate(sorted(diagram.branches.items())):
            colour = colours[n % len(colours)]
            for stable, run in stretches(points):
                values = np.array([quantity(p, name) for p in run])
                for column in values.T:
                    ax.plot([p.parameter for p in run], column, color=colour, linestyle="-" if stable else "--",
                            linewidth=1.6 if stable else 1.2)
                    lines += 1
            for p in points:
                if p.event:
                    marker, ec, _ = EVENT_STYLE[p.event]
                    ax.plot([p.parameter], [marker_value(p, name)], linestyle="", marker=marker, markersize=8,
                            markerfacecolor="none" if p.event != "end" else ec, markeredgecolor=ec,
                            markeredgewidth=1.5, zorder=5)
                    seen_events.add(p.event)
        ax.set_ylabel(QUANTITIES[name])
        if name in ("modulus", "moduli"):
            ax.axhline(1.0, color="0.6", linewidth=0.8, zorder=0)
            low, high = ax.get_ylim()
            if low > 0 and high / low > 100:
                ax.set_yscale("log")
        ax.grid(True, linewidth=0.3, alpha=0.5)
    axes[-1].set_xlabel(diagram.parameter)
    handles = [Line2D([], [], color=colours[n % len(colours)], label=branch_label(points))
               for n, (_, points) in enumerate(sorted(diagram.branches.items()))]
    handles += [Line2D([], [], color="0.3", linestyle="-", label="stable"),
                Line2D([], [], color="0.3", linestyle="--", label="not stable (unstable, saddle, marginal)")]
    handles += [Line2D([], [], linestyle="", marker=EVENT_STYLE[e][0], markeredgecolor=EVENT_STYLE[e][1],
                       markerfacecolor="none" if e != "end" else EVENT_STYLE[e][1], markersize=8, label=EVENT_STYLE[e][2])
                for e in EVENT_STYLE if e in seen_events]
    axes[0].legend(handles=handles, fontsize="small", loc="best")
    fig.suptitle("\n".join(textwrap.wrap(diagram.title, TITLE_WIDTH)), fontsize="medium")
    fig.savefig(png, dpi=DPI)
    fig.savefig(pdf)
    pyplot().close(fig)
    return lines


def draw_curves(diagram, size, png, pdf):
    """The event curves in the plane of the two coefficients; returns the number of lines drawn."""
    fig = new_figure(size, DPI)
    ax = fig.subplots()
    styles = ("-", "--", "-.", ":")
    lines = 0
    for n, (number, points) in enumerate(sorted(diagram.curves.items())):
        first = points[0]
        _, colour, label = EVENT_STYLE[first.event]
        where = ", corner" if first.corner else ""
        ax.plot([p.first for p in points], [p.second for p in points], color=colour, linestyle=styles[n % len(styles)],
                linewidth=1.6, label=f"curve {number}: {label} of branch {first.branch} (period {first.period}{where})")
        lines += 1
    ax.set_xlabel(diagram.parameters[0])
    ax.set_ylabel(diagram.parameters[1])
    ax.grid(True, linewidth=0.3, alpha=0.5)
    ax.legend(fontsize="small", loc="best")
    fig.suptitle("\n".join(textwrap.wrap(diagram.title, TITLE_WIDTH)), fontsize="medium")
    fig.savefig(png, dpi=DPI)
    fig.savefig(pdf)
    pyplot().close(fig)
    return lines


def load(args):
    """The diagram and a name for it (for the default output)."""
    if args.run is not None:
        return read_csv(run_superball("continue", args.run + ["--format", "csv"]), "superball continue"), None
    if args.input == "-":
        return read_csv(sys.stdin.read(), "standard input"), None
    if not os.path.isfile(args.input):
        raise ScriptError(f"continuation file {args.input!r} does not exist")
    with open(args.input, encoding="utf-8") as stream:
        return read_csv(stream.read(), args.input), args.input


def parse_quantities(text):
    """--y: comma-separated quantities (an argparse type)."""
    names = [n.strip() for n in text.split(",") if n.strip()]
    unknown = [n for n in names if n not in QUANTITIES]
    if not names or unknown:
        raise argparse.ArgumentTypeError(f"{text!r}: accepted a comma-separated list of {', '.join(QUANTITIES)}")
    return names


def parse_args(argv):
    parser = argparse.ArgumentParser(description=DESCRIPTION, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("input", nargs="?", help="CSV written by `superball continue`, or - for standard input")
    parser.add_argument("-o", "--output", help="output PNG (default: INPUT.png, or bifurcation.png); the PDF "
                        "goes next to it")
    parser.add_argument("--y", type=parse_quantities, default=parse_quantities(DEFAULT_QUANTITIES),
                        metavar="Q[,Q...]", help="quantities, one panel each: %s (default %s)"
                        % (", ".join(QUANTITIES), DEFAULT_QUANTITIES))
    parser.add_argument("--size", type=parse_size, default=PNG_SIZE, metavar="WxH",
                        help="PNG size in pixels (default %dx%d)" % PNG_SIZE)
    parser.add_argument("--run", nargs=argparse.REMAINDER, metavar="ARGS",
                        help="run `superball continue ARGS --format csv` instead of reading a CSV; must come last")
    args = parser.parse_args(argv)
    if (args.input is None) == (args.run is None):
        parser.error("give either a CSV file (or -) or --run ARGS...")
    if args.output and not args.output.lower().endswith(".png"):
        parser.error(f"--output {args.output!r}: accepted a name ending in .png (the PDF goes next to it)")
    return args


def main(argv=None):
    args = parse_args(argv)
    diagram, name = load(args)
    png = args.output or (os.path.splitext(name)[0] + ".png" if name else "bifurcation.png")
    pdf = os.path.splitext(png)[0] + ".pdf"
    if isinstance(diagram, Curves):
        draw_curves(diagram, args.size, png, pdf)
    else:
        draw(diagram, args.y, args.size, png, pdf)
    print(png)
    print(pdf)
    return 0


if __name__ == "__main__":
    run_script(main)
