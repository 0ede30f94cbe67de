#!/usr/bin/python3
"""Plot one superball trajectory: the ball's centre bouncing between floor and wall.

Input is the CSV of `superball trajectory` (a file, or - for standard input), or
`--run ARGS...` to call the binary itself (from $SUPERBALL, else `superball` on
PATH) as `superball trajectory ARGS... --samples 50`.
"""

import argparse
import csv
import io
import math
import os
import sys
from typing import NamedTuple

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from superball_results import (  # noqa: E402  (needs the path above)
    ScriptError,
    format_number,
    new_figure,
    parse_size,
    pyplot,
    run_script,
    run_superball,
)

COLUMNS = ("event", "wall_bounces", "t", "x", "y", "u_in", "v_in", "omega_in", "u", "v", "omega", "contact", "beta")
# The CSV of superball before SPEC.md 1b (no contact, beta): still read.
COLUMNS_BEFORE_FRICTION = COLUMNS[:11]
EVENT_KINDS = ("launch", "wall", "floor", "land")
PATH_EVENT = "path"
# Ball radius of a physical start unless --radius says otherwise (the binary's default).
PHYSICAL_RADIUS = 0.025
# Flight samples asked of the binary with --run.
RUN_SAMPLES = 50
# Colour of the ball drawn at each kind of event.
EVENT_COLOURS = {"launch": "tab:blue", "wall": "tab:red", "floor": "tab:green", "land": "0.5"}
SURFACE_COLOUR = "0.85"
PATH_COLOUR = "0.1"
# The longest velocity arrow is this fraction of the trajectory's extent.
ARROW_FRACTION = 0.3
# Points of the centre's path computed for the animation trail (and the plot without 'path' rows).
DENSE_SAMPLES = 2000
DPI = 100
PNG_SIZE = (1000, 700)
GIF_SIZE = (640, 480)

DESCRIPTION = __doc__ + """
The figure shows the wall (x = -radius) and the floor (y = -radius) as grey
solids (coordinates are those of the centre, which touches the wall at x = 0
and the floor at y = 0), the centre's path, and the ball at every impact with a
spin marker (a radius turned by the spin accumulated since launch, the integral
of omega over time) and an arrow for its velocity after the impact.

Units: a physical start is in SI units (radius default %g m); a canonical start
is followed in dimensionless units (v0 = g = radius = 1).  Which one is read
from the gravity the trajectory shows; --radius overrides the radius drawn.

Output: a PNG (-o, default named after the input, else trajectory.png) and,
with --gif, an animation of the ball moving with its spin marker turning.
Exit status: 0 done, 2 bad input (message names it), 1 other failure.
""" % PHYSICAL_RADIUS


class Event(NamedTuple):
    """One CSV row: an impact (or launch/land, or a path sample), arriving (_in) and leaving state."""

    kind: str
    wall_bounces: int
    t: float
    x: float
    y: float
    u_in: float
    v_in: float
    omega_in: float
    u: float
    v: float
    omega: float
    contact: str = ""  # impacts: "grip" or "slide" (SPEC.md 1b)
    beta: float = math.nan  # impacts: the tangential factor


class Trajectory:
    """Events of one start, with the motion between them reconstructed exactly.

    Between events the centre flies on a parabola under gravity g, and the spin
    is constant, so position and accumulated spin angle follow at any time from
    the state leaving the previous event.  g is read from the data itself (the
    vertical speed lost per time in flight), which also tells SI from
    dimensionless output.
    """

    def __init__(self, events, path, source):
        if len(events) < 2 or events[0].kind != "launch":
            raise ScriptError(f"{source}: a trajectory needs a launch event followed by at least one more event")
        self.events = events
        self.path = path  # (k, 2) sampled centre positions from 'path' rows, or None
        self.columns = {name: np.array([getattr(e, name) for e in events]) for name in Event._fields[1:]}
        self.times = self.columns["t"]
        if np.any(np.diff(self.times) < 0):
            raise ScriptError(f"{source}: event times decrease")
        self.g = self._gravity(source)
        spin = self.columns["omega"][:-1]
        self.event_angles = np.concatenate([[0.0], np.cumsum(spin * np.diff(self.times))])

    def _gravity(self, source):
        """Median over flights of (v leaving - v arriving next) / flight time."""
        flight = np.diff(self.times)
        lost = self.columns["v"][:-1] - self.columns["v_in"][1:]
        moving = flight > 0
        g = float(np.median(lost[moving] / flight[moving])) if moving.any() else math.nan
        if not g > 0 or not math.isfinite(g):
            raise ScriptError(f"{source}: cannot infer gravity from the events (zero flight times or inconsistent data)")
        return g

    @property
    def dimensionless(self):
        """True for a canonical start (followed with v0 = g = radius = 1)."""
        return math.isclose(self.g, 1.0, rel_tol=1e-6)

    @property
    def wall_bounces(self):
        return int(self.columns["wall_bounces"].max())

    @property
    def outcome(self):
        """Outcome name (SPEC.md section 3) read from how the event list ends."""
        last, before = self.events[-1], self.events[-2]
        if last.kind != "land":
            return "capped"
        return "left" if before.kind == "floor" and before.u >= 0 else "missed"

    def _segments(self, times):
        """Clipped times and, for each, the index of the event whose leaving state governs it."""
        times = np.clip(np.asarray(times, dtype=float), self.times[0], self.times[-1])
        index = np.clip(np.searchsorted(self.times, times, side="right") - 1, 0, len(self.events) - 2)
        return times, index

    def position(self, times):
        """Centre (x, y) at the given times."""
        times, k = self._segments(times)
        tau = times - self.times[k]
        c = self.columns
        x = c["x"][k] + c["u"][k] * tau
        y = c["y"][k] + c["v"][k] * tau - 0.5 * self.g * tau**2
        return x, y

    def angle(self, times):
        """Spin angle accumulated since launch (integral of omega dt, radians, counter-clockwise)."""
        times, k = self._segments(times)
        return self.event_angles[k] + self.columns["omega"][k] * (times - self.times[k])

    def bounces_at(self, times):
        """Wall impacts so far at the given times."""
        return self.columns["wall_bounces"][self._segments(times)[1]]


def read_csv(text, source):
    """Parse `superball trajectory` CSV; every problem names the source and line."""
    if text.lstrip().startswith("{"):
        raise ScriptError(f"{source}: this is JSON; give the CSV of `superball trajectory` (--format csv)")
    rows = [(n, row) for n, row in enumerate(csv.reader(io.StringIO(text)), 1) if row and not row[0].startswith("#")]
    header = tuple(field.strip() for field in rows[0][1]) if rows else ()
    if header not in (COLUMNS, COLUMNS_BEFORE_FRICTION):
        raise ScriptError(f"{source}: not a superball trajectory CSV (expected the header {','.join(COLUMNS)})")
    events, path = [], []
    for line, row in rows[1:]:
        if len(row) != len(header):
            raise ScriptError(f"{source} line {line}: {len(row)} fields, expected {len(header)}")
        kind = row[0].strip()
        if kind not in EVENT_KINDS + (PATH_EVENT,):
            raise ScriptError(f"{source} line {line}: unknown event {kind!r} (expected {', '.join(EVENT_KINDS)}, path)")
        try:
            numbers = [float(field) for field in row[2:11]]
            contact = (row[11].strip(), float(row[12])) if len(header) == len(COLUMNS) else ()
            event = Event(kind, int(row[1]), *numbers, *contact)
        except ValueError:
            raise ScriptError(f"{source} line {line}: a field is not a number")
        if not all(math.isfinite(value) for value in numbers):
            raise ScriptError(f"{source} line {line}: a field is not finite")
        if kind == PATH_EVENT:
            path.append((event.t, event.x, event.y))
        else:
            events.append(event)
    if path:
        path = np.array(path)
        path = path[np.argsort(path[:, 0], kind="stable"), 1:]
    return Trajectory(events, path if len(path) else None, source)


def run_trajectory(arguments):
    """CSV text of `superball trajectory ARGS`, with flight samples for a smooth path."""
    if not any(arg == "--samples" or arg.startswith("--samples=") for arg in arguments):
        arguments = arguments + ["--samples", str(RUN_SAMPLES)]
    return run_superball("trajectory", arguments)


def load(args):
    """The trajectory and a name for it (for titles and the default output)."""
    if args.run is not None:
        return read_csv(run_trajectory(args.run), "superball trajectory"), None
    if args.input == "-":
        return read_csv(sys.stdin.read(), "standard input"), None
    if not os.path.isfile(args.input):
        raise ScriptError(f"trajectory file {args.input!r} does not exist")
    with open(args.input, encoding="utf-8") as stream:
        return read_csv(stream.read(), args.input), args.input


class Scene:
    """Geometry shared by the still figure and the animation: radius, limits, units."""

    def __init__(self, trajectory, radius):
        self.trajectory = trajectory
        self.radius = radius if radius is not None else (1.0 if trajectory.dimensionless else PHYSICAL_RADIUS)
        times = np.union1d(np.linspace(trajectory.times[0], trajectory.times[-1], DENSE_SAMPLES), trajectory.times)
        self.dense = np.column_stack(trajectory.position(times))
        self.dense_times = times
        # Events that set the ball off (the land row only records where it came down).
        self.impacts = [e for e in trajectory.events if e.kind != "land"]
        speeds = [math.hypot(e.u, e.v) for e in self.impacts]
        points = self.dense if trajectory.path is None else np.vstack([self.dense, trajectory.path])
        extent = max(np.ptp(points[:, 0]), np.ptp(points[:, 1])) + 2 * self.radius
        self.arrow_scale = ARROW_FRACTION * extent / max(max(speeds), 1e-300)
        tips = np.array([(e.x + self.arrow_scale * e.u, e.y + self.arrow_scale * e.v) for e in self.impacts])
        low = np.minimum(np.min(points, axis=0) - self.radius, tips.min(axis=0))
        high = np.maximum(np.max(points, axis=0) + self.radius, tips.max(axis=0))
        margin = 0.1 * extent
        self.xlim = (min(low[0], -self.radius) - margin, high[0] + margin)
        self.ylim = (min(low[1], -self.radius) - margin, high[1] + margin)

    @property
    def units(self):
        """(description for the title, unit suffix for axis labels)."""
        if self.trajectory.dimensionless:
            return "dimensionless (v0 = g = radius = 1)", ""
        return f"SI (g = {self.trajectory.g:.4g} m/s^2, radius {format_number(self.radius)} m)", " [m]"

    def start_coordinates(self):
        """The launch as it was most likely given: canonical (xi, U, W) or physical (x, u, v, omega)."""
        start = self.trajectory.events[0]
        if self.trajectory.dimensionless:  # v0 = g = radius = 1 (SPEC.md section 2)
            return {"xi": start.x / (2 * abs(start.u) * start.v), "U": start.u / start.v, "W": start.omega / start.v}
        return {key: getattr(start, key) for key in ("x", "u", "v", "omega")}

    def title(self, name):
        """Outcome, start and units: what the figure shows, in two lines."""
        tr = self.trajectory
        head = f"{os.path.basename(name)}: " if name else ""
        state = ", ".join(f"{key} = {format_number(value)}" for key, value in self.start_coordinates().items())
        return f"{head}{tr.wall_bounces} wall bounces, outcome {tr.outcome}\nstart {state}; units {self.units[0]}"

    def draw_background(self, ax):
        """Wall and floor as solids at the contact distance, axes, limits, equal scale."""
        ax.axvspan(self.xlim[0], -self.radius, color=SURFACE_COLOUR, zorder=0)
        ax.axhspan(self.ylim[0], -self.radius, color=SURFACE_COLOUR, zorder=0)
        ax.axvline(-self.radius, color="0.2", linewidth=1.5)
        ax.axhline(-self.radius, color="0.2", linewidth=1.5)
        ax.set_xlim(*self.xlim)
        ax.set_ylim(*self.ylim)
        ax.set_aspect("equal", adjustable="box")
        unit = self.units[1]
        ax.set_xlabel(f"x of the centre{unit} (wall at x = -radius)")
        ax.set_ylabel(f"y of the centre{unit} (floor at y = -radius)")

    def ball(self, ax, colour, **style):
        """A ball (circle and spin marker) to be placed with place()."""
        from matplotlib.patches import Circle

        circle = Circle((0, 0), self.radius, fill=False, edgecolor=colour, zorder=3, **style)
        ax.add_patch(circle)
        (marker,) = ax.plot([], [], color=colour, zorder=3, **style)
        return circle, marker

    def place(self, ball, x, y, angle):
        """Move a ball to (x, y) with its spin marker turned by `angle` from straight up."""
        circle, marker = ball
        circle.center = (x, y)
        marker.set_data([x, x + self.radius * math.cos(math.pi / 2 + angle)],
                        [y, y + self.radius * math.sin(math.pi / 2 + angle)])


def draw_still(scene, name, size, output):
    """The whole trajectory: path, ball at each impact with spin marker and velocity arrow."""
    from matplotlib.lines import Line2D

    tr = scene.trajectory
    fig = new_figure(size, DPI)
    ax = fig.subplots()
    scene.draw_background(ax)
    path = scene.dense if tr.path is None else tr.path
    ax.plot(path[:, 0], path[:, 1], color=PATH_COLOUR, linewidth=1.2, zorder=5)
    angles = tr.event_angles
    for event, angle in zip(tr.events, angles):
        style = {"linestyle": "--"} if event.kind == "land" else {}
        ball = scene.ball(ax, EVENT_COLOURS[event.kind], linewidth=0.9, alpha=0.7, **style)
        scene.place(ball, event.x, event.y, angle)
    impacts = scene.impacts
    ax.quiver([e.x for e in impacts], [e.y for e in impacts],
              [scene.arrow_scale * e.u for e in impacts], [scene.arrow_scale * e.v for e in impacts],
              color=[EVENT_COLOURS[e.kind] for e in impacts], angles="xy", scale_units="xy", scale=1,
              width=0.004, zorder=6)
    kinds = [kind for kind in EVENT_KINDS if any(e.kind == kind for e in tr.events)]
    handles = [Line2D([], [], color=EVENT_COLOURS[k], marker="o", fillstyle="none", linestyle="", label=k)
               for k in kinds]
    handles.append(Line2D([], [], color=PATH_COLOUR, label="centre's path"))
    ax.legend(handles=handles, loc="upper right", fontsize="small", title="ball at event (arrow: velocity after)",
              title_fontsize="small")
    fig.suptitle(scene.title(name), fontsize="medium")
    fig.savefig(output, dpi=DPI)
    pyplot().close(fig)


def draw_animation(scene, name, size, frames, fps, output):
    """The ball moving along the path in equal steps of time, its spin marker turning."""
    from matplotlib.animation import FuncAnimation, PillowWriter

    tr = scene.trajectory
    fig = new_figure(size, DPI)
    ax = fig.subplots()
    scene.draw_background(ax)
    ax.plot(scene.dense[:, 0], scene.dense[:, 1], color=PATH_COLOUR, linewidth=0.6, alpha=0.3)
    (trail,) = ax.plot([], [], color=PATH_COLOUR, linewidth=1.0)
    ball = scene.ball(ax, "tab:blue", linewidth=1.5)
    clock = ax.text(0.02, 0.97, "", transform=ax.transAxes, va="top", fontsize="small")
    fig.suptitle(scene.title(name), fontsize="small")
    times = np.linspace(tr.times[0], tr.times[-1], frames)
    xs, ys = tr.position(times)
    angles = tr.angle(times)
    bounces = tr.bounces_at(times)
    time_unit = "" if tr.dimensionless else " s"

    def update(i):
        shown = np.searchsorted(scene.dense_times, times[i], side="right")
        trail.set_data(np.append(scene.dense[:shown, 0], xs[i]), np.append(scene.dense[:shown, 1], ys[i]))
        scene.place(ball, xs[i], ys[i], angles[i])
        clock.set_text(f"t = {times[i]:.4g}{time_unit}, wall bounces {bounces[i]}")
        return []

    animation = FuncAnimation(fig, update, frames=frames, blit=False)
    animation.save(output, writer=PillowWriter(fps=fps), dpi=DPI)
    pyplot().close(fig)


def parse_args(argv):
    parser = argparse.ArgumentParser(description=DESCRIPTION, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("input", nargs="?", help="CSV written by `superball trajectory`, or - for standard input")
    parser.add_argument("-o", "--output", help="output PNG (default: INPUT.png, or trajectory.png)")
    parser.add_argument("--radius", type=float, help=f"ball radius drawn (default {PHYSICAL_RADIUS} m for SI data, "
                        "1 for dimensionless data)")
    parser.add_argument("--size", type=parse_size, default=PNG_SIZE, metavar="WxH",
                        help="PNG size in pixels (default %dx%d)" % PNG_SIZE)
    parser.add_argument("--gif", metavar="OUT.gif", help="also write an animation (GIF) of the ball in flight")
    parser.add_argument("--frames", type=int, default=100, help="frames of the animation (default 100)")
    parser.add_argument("--fps", type=float, default=20, help="frames per second of the animation (default 20)")
    parser.add_argument("--gif-size", type=parse_size, default=GIF_SIZE, metavar="WxH",
                        help="animation size in pixels (default %dx%d)" % GIF_SIZE)
    parser.add_argument("--run", nargs=argparse.REMAINDER, metavar="ARGS",
                        help="run `superball trajectory ARGS` (adding --samples %d) instead of reading a CSV; "
                        "must come last" % RUN_SAMPLES)
    args = parser.parse_args(argv)
    if (args.input is None) == (args.run is None):
        parser.error("give either a CSV file (or -) or --run ARGS...")
    if args.radius is not None and not (args.radius > 0 and math.isfinite(args.radius)):
        parser.error(f"--radius {args.radius} is out of range: accepted > 0")
    if args.frames < 2:
        parser.error(f"--frames {args.frames} is out of range: accepted >= 2")
    if not args.fps > 0:
        parser.error(f"--fps {args.fps} is out of range: accepted > 0")
    return args


def main(argv=None):
    args = parse_args(argv)
    trajectory, name = load(args)
    scene = Scene(trajectory, args.radius)
    output = args.output or (os.path.splitext(name)[0] + ".png" if name else "trajectory.png")
    draw_still(scene, name, args.size, output)
    print(output)
    if args.gif:
        draw_animation(scene, name, args.gif_size, args.frames, args.fps, args.gif)
        print(args.gif)
    return 0


if __name__ == "__main__":
    run_script(main)
