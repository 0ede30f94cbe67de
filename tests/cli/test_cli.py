#!/usr/bin/env python3
"""Tests of the `superball` command line: `count`, `trajectory`, help, version and the
rejection of bad input (exit status 2, a message naming the flag).

Run by ctest as `$SUPERBALL_PYTHON tests/cli/test_cli.py -v` with
  SUPERBALL                the built binary
  SUPERBALL_REFERENCE_DIR  tests/reference (defaults to ../reference next to this file)
Standard library only.
"""

import csv
import io
import json
import math
import os
import re
import subprocess
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
SUPERBALL = os.environ.get("SUPERBALL", "")
REFERENCE_DIR = os.environ.get("SUPERBALL_REFERENCE_DIR", os.path.join(HERE, os.pardir, "reference"))

# The documented example (SPEC, `superball count --help`).
EXAMPLE = ["--xi", "0.05", "--U", "-1", "--W", "-2"]
MODEL = ["--e", "0.9", "--alpha", "0.9"]

# trajectory_example.csv: g = 9.81, a = 0.025, e = alpha = 0.9 on both surfaces.
PHYSICAL = ["--x", "0.02", "--u", "-2.0", "--v", "2.0", "--omega", "-200.0"]
EXAMPLE_G = 9.81
EXAMPLE_RADIUS = 0.025

CSV_HEADER = "event,wall_bounces,t,x,y,u_in,v_in,omega_in,u,v,omega,contact,beta"
HELP_HINT = "Run with --help for usage."
REL_TOL = 1e-12


def setUpModule():
    if not SUPERBALL or not os.access(SUPERBALL, os.X_OK):
        raise RuntimeError("set SUPERBALL to the built superball binary (got %r)" % SUPERBALL)


def run(*args, timeout=60):
    return subprocess.run([SUPERBALL, *args], capture_output=True, text=True, timeout=timeout)


def data_lines(path):
    """Lines of a reference CSV without its '#' comments."""
    with open(path, newline="") as f:
        return [line for line in f if line.strip() and not line.startswith("#")]


def count_rows():
    return list(csv.DictReader(data_lines(os.path.join(REFERENCE_DIR, "canonical_counts.csv"))))


def trajectory_rows():
    rows = list(csv.DictReader(data_lines(os.path.join(REFERENCE_DIR, "trajectory_example.csv"))))
    return [{k: float(v) for k, v in r.items()} for r in rows]


def rel_close(a, b, tol=REL_TOL):
    return abs(a - b) <= tol * max(abs(a), abs(b))


class CliTestCase(unittest.TestCase):
    def assertOk(self, r):
        self.assertEqual(r.returncode, 0, "exit status %d, stderr: %s" % (r.returncode, r.stderr))
        self.assertEqual(r.stderr, "")

    def assertRelClose(self, a, b, what, tol=REL_TOL):
        self.assertTrue(rel_close(a, b, tol), "%s: %r vs %r (relative tolerance %g)" % (what, a, b, tol))


# --------------------------------------------------------------------- help and version


class HelpAndVersion(CliTestCase):
    def test_version(self):
        r = run("--version")
        self.assertOk(r)
        self.assertRegex(r.stdout.strip(), r"^superball \d+\.\d+\.\d+")

    def test_top_level_help(self):
        r = run("--help")
        self.assertOk(r)
        for word in ("count", "trajectory", "--version", "--help", "Exit status"):
            self.assertIn(word, r.stdout)

    def test_count_help_mentions_its_flags(self):
        r = run("count", "--help")
        self.assertOk(r)
        for flag in ("--e ", "--alpha ", "--e-wall", "--alpha-wall", "--e-floor", "--alpha-floor", "--xi", "--U", "--W",
                     "--x ", "--u ", "--v ", "--omega", "--g ", "--radius", "--max-bounces", "--json"):
            self.assertIn(flag, r.stdout, "count --help does not mention " + flag)
        self.assertIn("superball count --xi 0.05 --U -1 --W -2 --e 0.9 --alpha 0.9", r.stdout)

    def test_trajectory_help_mentions_its_flags(self):
        r = run("trajectory", "--help")
        self.assertOk(r)
        for flag in ("--e ", "--alpha ", "--e-wall", "--alpha-floor", "--xi", "--U", "--W", "--x ", "--omega",
                     "--g ", "--radius", "--max-bounces", "--format", "--samples", "--output", "-o"):
            self.assertIn(flag, r.stdout, "trajectory --help does not mention " + flag)

    def test_every_listed_subcommand_has_help(self):
        top = run("--help").stdout
        section = top.split("Subcommands:", 1)[1]
        names = re.findall(r"^  (\w[\w-]*) ", section, flags=re.MULTILINE)
        self.assertIn("count", names)
        self.assertIn("trajectory", names)
        for name in names:
            with self.subTest(subcommand=name):
                r = run(name, "--help")
                self.assertOk(r)
                self.assertIn("--help", r.stdout)


# --------------------------------------------------------------------- count


class Count(CliTestCase):
    def test_documented_example(self):
        r = run("count", *EXAMPLE, *MODEL)
        self.assertOk(r)
        self.assertEqual(r.stdout, "8 wall bounces, outcome left\n")

    def test_json(self):
        r = run("count", *EXAMPLE, *MODEL, "--json")
        self.assertOk(r)
        out = json.loads(r.stdout)
        self.assertEqual(out["wall_bounces"], 8)
        self.assertEqual(out["outcome"], "left")
        self.assertEqual((out["xi"], out["U"], out["W"]), (0.05, -1.0, -2.0))

    def test_singular_and_cap(self):
        r = run("count", *EXAMPLE, *MODEL, "--max-bounces", "1")
        self.assertOk(r)
        self.assertEqual(r.stdout, "1 wall bounce, outcome capped\n")
        r = run("count", *EXAMPLE, *MODEL, "--max-bounces", "3")
        self.assertEqual(r.stdout, "3 wall bounces, outcome capped\n")
        r = run("count", *EXAMPLE, *MODEL, "--max-bounces", "8")
        self.assertEqual(r.stdout, "8 wall bounces, outcome left\n")

    def test_beyond_the_range_misses(self):
        r = run("count", "--xi", "1.5", "--U", "-1", "--W", "0", *MODEL)
        self.assertOk(r)
        self.assertEqual(r.stdout, "0 wall bounces, outcome missed\n")

    def test_every_reference_row(self):
        rows = count_rows()
        self.assertEqual(len(rows), 40)
        for i, row in enumerate(rows):
            with self.subTest(row=i + 1, values=dict(row)):
                r = run("count", "--xi", row["xi"], "--U", row["U"], "--W", row["W"],
                        "--e-wall", row["e_wall"], "--alpha-wall", row["alpha_wall"],
                        "--e-floor", row["e_floor"], "--alpha-floor", row["alpha_floor"], "--json")
                self.assertOk(r)
                out = json.loads(r.stdout)
                self.assertEqual((out["wall_bounces"], out["outcome"]), (int(row["wall_bounces"]), row["outcome"]))
                # The start is read back exactly (shortest round-trip printing both ways).
                self.assertEqual(out["xi"], float(row["xi"]))
                self.assertEqual(out["U"], float(row["U"]))
                self.assertEqual(out["W"], float(row["W"]))

    def test_shorthand_and_overrides(self):
        # One material: --e/--alpha equal the four per-surface flags.
        rows = [r for r in count_rows() if r["e_wall"] == r["e_floor"] and r["alpha_wall"] == r["alpha_floor"]]
        self.assertGreater(len(rows), 10)
        for row in rows[:8]:
            with self.subTest(values=dict(row)):
                r = run("count", "--xi", row["xi"], "--U", row["U"], "--W", row["W"],
                        "--e", row["e_wall"], "--alpha", row["alpha_wall"])
                self.assertOk(r)
                n = int(row["wall_bounces"])
                self.assertEqual(r.stdout, "%d wall bounce%s, outcome %s\n" % (n, "" if n == 1 else "s", row["outcome"]))
        # Per-surface flags override the shared ones.
        mixed = [r for r in count_rows() if r["e_wall"] != r["e_floor"]]
        self.assertTrue(mixed)
        row = mixed[0]
        r = run("count", "--xi", row["xi"], "--U", row["U"], "--W", row["W"], "--e", "0.1", "--alpha", "-0.5",
                "--e-wall", row["e_wall"], "--alpha-wall", row["alpha_wall"],
                "--e-floor", row["e_floor"], "--alpha-floor", row["alpha_floor"], "--json")
        self.assertOk(r)
        out = json.loads(r.stdout)
        self.assertEqual((out["wall_bounces"], out["outcome"]), (int(row["wall_bounces"]), row["outcome"]))

    def test_physical_start(self):
        r = run("count", *PHYSICAL, *MODEL, "--json")
        self.assertOk(r)
        out = json.loads(r.stdout)
        self.assertEqual((out["wall_bounces"], out["outcome"]), (12, "left"))
        # xi = g x / (2 |u| v), U = u / v, W = a omega / v with the default g and radius
        self.assertRelClose(out["xi"], EXAMPLE_G * 0.02 / (2 * 2.0 * 2.0), "xi")
        self.assertRelClose(out["U"], -1.0, "U")
        self.assertRelClose(out["W"], EXAMPLE_RADIUS * -200.0 / 2.0, "W")
        r = run("count", *PHYSICAL, *MODEL, "--g", "9.81", "--radius", "0.025")
        self.assertOk(r)
        self.assertEqual(r.stdout, "12 wall bounces, outcome left\n")

    def test_physical_start_with_other_units(self):
        # The canonical example as a physical start with g = 1.62, a = 0.04, v = 3 (same launch).
        g, a, v = 1.62, 0.04, 3.0
        xi, U, W = 0.05, -1.0, -2.0
        x, u, omega = 2 * xi * abs(U) * v * v / g, U * v, W * v / a
        r = run("count", "--x", repr(x), "--u", repr(u), "--v", repr(v), "--omega", repr(omega),
                "--g", repr(g), "--radius", repr(a), *MODEL, "--json")
        self.assertOk(r)
        out = json.loads(r.stdout)
        self.assertEqual((out["wall_bounces"], out["outcome"]), (8, "left"))
        self.assertRelClose(out["xi"], xi, "xi", 1e-15)
        self.assertRelClose(out["W"], W, "W", 1e-15)


# --------------------------------------------------------------------- trajectory


def parse_csv(text):
    lines = text.splitlines()
    header = lines[0]
    rows = list(csv.DictReader(io.StringIO(text)))
    for row in rows:
        for key in row:
            if key not in ("event", "contact"):
                row[key] = float(row[key])
        # SPEC.md 1b: every impact says whether it gripped or slid, nothing else does.
        assert (row["contact"] in ("grip", "slide")) == (row["event"] in ("wall", "floor")), row
        assert math.isnan(row["beta"]) == (row["contact"] == ""), row
    return header, rows


class Trajectory(CliTestCase):
    def check_against_reference(self, events):
        """events: dicts with event, wall_bounces, x, y, u, v, omega (physical start)."""
        ref = trajectory_rows()
        self.assertEqual(len(ref), 13)
        kinds = [e["event"] for e in events]
        self.assertEqual(kinds, ["launch"] + ["wall", "floor"] * 12 + ["land"])
        for n in range(1, 13):
            wall, floor = events[2 * n - 1], events[2 * n]
            self.assertEqual(int(wall["wall_bounces"]), n)
            self.assertEqual(int(floor["wall_bounces"]), n)
            self.assertEqual(wall["x"], 0.0)
            self.assertEqual(floor["y"], 0.0)
            self.assertRelClose(wall["y"], ref[n - 1]["y_n"], "y_%d" % (n - 1))
            self.assertRelClose(floor["x"], ref[n]["x_n"], "x_%d" % n)
            self.assertRelClose(floor["u"], ref[n]["u_n"], "u_%d" % n)
            self.assertRelClose(floor["v"], ref[n]["v_n"], "v_%d" % n)
            self.assertRelClose(floor["omega"], ref[n]["omega_n"], "omega_%d" % n)
        self.assertGreaterEqual(events[24]["u"], 0.0)
        times = [e["t"] for e in events]
        self.assertEqual(times, sorted(times))
        self.assertEqual(len(set(times)), len(times))

    def test_csv_matches_reference(self):
        r = run("trajectory", *PHYSICAL, *MODEL)
        self.assertOk(r)
        header, rows = parse_csv(r.stdout)
        self.assertEqual(header, CSV_HEADER)
        self.check_against_reference(rows)
        launch = rows[0]
        self.assertEqual((launch["t"], launch["x"], launch["y"], launch["u"], launch["v"], launch["omega"]),
                         (0.0, 0.02, 0.0, -2.0, 2.0, -200.0))

    def test_json_matches_reference(self):
        r = run("trajectory", *PHYSICAL, *MODEL, "--format", "json")
        self.assertOk(r)
        out = json.loads(r.stdout)
        self.assertEqual((out["wall_bounces"], out["outcome"]), (12, "left"))
        self.assertEqual(out["units"], "SI")
        self.assertEqual((out["g"], out["radius"]), (EXAMPLE_G, EXAMPLE_RADIUS))
        self.assertEqual(out["model"], {"e_wall": 0.9, "alpha_wall": 0.9, "e_floor": 0.9, "alpha_floor": 0.9})
        self.assertRelClose(out["start"]["xi"], EXAMPLE_G * 0.02 / 8.0, "start xi")
        self.assertEqual(out["path"], [])
        self.check_against_reference(out["events"])
        # Same numbers as the CSV.
        _, rows = parse_csv(run("trajectory", *PHYSICAL, *MODEL).stdout)
        self.assertEqual(len(rows), len(out["events"]))
        for row, event in zip(rows, out["events"]):
            for key in ("t", "x", "y", "u_in", "v_in", "omega_in", "u", "v", "omega"):
                self.assertEqual(row[key], event[key], key)

    def test_canonical_start_is_dimensionless(self):
        r = run("trajectory", *EXAMPLE, *MODEL, "--format", "json")
        self.assertOk(r)
        out = json.loads(r.stdout)
        self.assertEqual((out["wall_bounces"], out["outcome"]), (8, "left"))
        self.assertEqual((out["g"], out["radius"]), (1, 1))
        launch = out["events"][0]
        # v0 = g = a = 1: x = 2 xi |U|, omega = W
        self.assertEqual((launch["x"], launch["u"], launch["v"], launch["omega"]), (0.1, -1.0, 1.0, -2.0))
        wall = out["events"][1]
        self.assertRelClose(wall["t"], 0.1, "t at the wall")        # x / |u|
        self.assertRelClose(wall["y"], 0.095, "y at the wall")      # 2 xi (1 - xi)
        self.assertEqual(out["events"][-1]["event"], "land")

    def test_samples_lie_on_the_parabolas(self):
        K = 7
        r = run("trajectory", *PHYSICAL, *MODEL, "--samples", str(K))
        self.assertOk(r)
        _, rows = parse_csv(r.stdout)
        events = [row for row in rows if row["event"] != "path"]
        path = [row for row in rows if row["event"] == "path"]
        self.assertEqual(len(events), 26)
        self.assertEqual(len(path), K * (len(events) - 1))
        g = EXAMPLE_G
        for j in range(len(events) - 1):
            start, end = events[j], events[j + 1]
            seg = path[j * K:(j + 1) * K]
            x0, y0, u0, v0 = start["x"], start["y"], start["u"], start["v"]
            for p in seg:
                self.assertEqual(p["u"], u0)
                dx = p["x"] - x0
                y = y0 + v0 / u0 * dx - g * dx * dx / (2 * u0 * u0)
                self.assertLessEqual(abs(p["y"] - y), 1e-12, "flight %d" % j)
                self.assertGreaterEqual(p["y"], -1e-15)
            self.assertEqual((seg[0]["t"], seg[0]["x"], seg[0]["y"]), (start["t"], start["x"], start["y"]))
            for key in ("t", "x", "y"):
                self.assertLessEqual(abs(seg[-1][key] - end[key]), 1e-12, "end of flight %d, %s" % (j, key))
        # JSON: the same samples with their segment index.
        out = json.loads(run("trajectory", *PHYSICAL, *MODEL, "--samples", str(K), "--format", "json").stdout)
        self.assertEqual(len(out["path"]), len(path))
        self.assertEqual([p["segment"] for p in out["path"]], [j for j in range(25) for _ in range(K)])
        for a, b in zip(out["path"], path):
            self.assertEqual((a["t"], a["x"], a["y"]), (b["t"], b["x"], b["y"]))

    def test_output_file(self):
        expected_csv = run("trajectory", *EXAMPLE, *MODEL).stdout
        expected_json = run("trajectory", *EXAMPLE, *MODEL, "--format", "json").stdout
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "t.csv")
            r = run("trajectory", *EXAMPLE, *MODEL, "-o", path)
            self.assertOk(r)
            self.assertEqual(r.stdout, "")
            with open(path) as f:
                self.assertEqual(f.read(), expected_csv)
            path = os.path.join(tmp, "t.json")
            r = run("trajectory", *EXAMPLE, *MODEL, "--format", "json", "--output", path)
            self.assertOk(r)
            self.assertEqual(r.stdout, "")
            with open(path) as f:
                self.assertEqual(f.read(), expected_json)
            # A file that cannot be written is an I/O failure: exit status 1.
            r = run("trajectory", *EXAMPLE, *MODEL, "-o", os.path.join(tmp, "missing", "t.csv"))
            self.assertEqual(r.returncode, 1, r.stderr)
            self.assertIn("missing", r.stderr)


# --------------------------------------------------------------------- bad input

CANONICAL = EXAMPLE
PHYS = ["--x", "0.1", "--u", "-1", "--v", "1", "--omega", "0"]

# (description, arguments, text the message must contain)
BAD_INPUT = [
    ("e above 1", ["count", *CANONICAL, "--e", "1.5", "--alpha", "0.9"], "--e"),
    ("e zero", ["count", *CANONICAL, "--e", "0", "--alpha", "0.9"], "--e"),
    ("e negative", ["count", *CANONICAL, "--e=-0.5", "--alpha", "0.9"], "--e"),
    ("e_wall out of range", ["count", *CANONICAL, *MODEL, "--e-wall", "1.01"], "--e-wall"),
    ("e_floor out of range", ["trajectory", *CANONICAL, *MODEL, "--e-floor", "0"], "--e-floor"),
    ("alpha above 1", ["count", *CANONICAL, "--e", "0.9", "--alpha", "1.5"], "--alpha"),
    ("alpha below -1", ["count", *CANONICAL, "--e", "0.9", "--alpha=-1.5"], "--alpha"),
    ("alpha_wall out of range", ["count", *CANONICAL, *MODEL, "--alpha-wall", "2"], "--alpha-wall"),
    ("alpha_floor out of range", ["trajectory", *CANONICAL, *MODEL, "--alpha-floor=-1.01"], "--alpha-floor"),
    ("e NaN", ["count", *CANONICAL, "--e", "nan", "--alpha", "0.9"], "--e"),
    ("alpha NaN", ["count", *CANONICAL, "--e", "0.9", "--alpha", "nan"], "--alpha"),
    ("xi NaN", ["count", "--xi", "nan", "--U", "-1", "--W", "-2", *MODEL], "--xi"),
    ("W NaN", ["count", "--xi", "0.05", "--U", "-1", "--W", "nan", *MODEL], "--W"),
    ("omega NaN", ["trajectory", "--x", "0.1", "--u", "-1", "--v", "1", "--omega", "nan", *MODEL], "--omega"),
    ("U infinite", ["count", "--xi", "0.05", "--U=-inf", "--W", "-2", *MODEL], "--U"),
    ("xi infinite", ["count", "--xi", "inf", "--U", "-1", "--W", "-2", *MODEL], "--xi"),
    ("e not a number", ["count", *CANONICAL, "--e", "abc", "--alpha", "0.9"], "--e"),
    ("xi not a number", ["count", "--xi", "0.1x", "--U", "-1", "--W", "-2", *MODEL], "--xi"),
    ("max-bounces not a number", ["count", *CANONICAL, *MODEL, "--max-bounces", "many"], "--max-bounces"),
    ("alpha missing", ["count", *CANONICAL, "--e", "0.9"], "--alpha"),
    ("e missing", ["count", *CANONICAL, "--alpha", "0.9"], "--e"),
    ("e_floor missing", ["count", *CANONICAL, "--e-wall", "0.9", "--alpha", "0.9"], "--e-floor"),
    ("W missing", ["count", "--xi", "0.05", "--U", "-1", *MODEL], "--W"),
    ("xi missing", ["trajectory", "--U", "-1", "--W", "-2", *MODEL], "--xi"),
    ("omega missing", ["count", "--x", "0.1", "--u", "-1", "--v", "1", *MODEL], "--omega"),
    ("v missing", ["count", "--x", "0.1", "--u", "-1", "--omega", "1", *MODEL], "--v"),
    ("no start", ["count", *MODEL], "--xi"),
    ("canonical and physical", ["count", *CANONICAL, "--x", "0.1", *MODEL], "--x"),
    ("canonical and physical (trajectory)", ["trajectory", "--xi", "0.1", "--U", "-1", "--omega", "3", *MODEL],
     "--omega"),
    ("U zero", ["count", "--xi", "0.05", "--U", "0", "--W", "-2", *MODEL], "--U"),
    ("U negative zero", ["count", "--xi", "0.05", "--U=-0.0", "--W", "-2", *MODEL], "--U"),
    ("U positive", ["trajectory", "--xi", "0.05", "--U", "0.5", "--W", "-2", *MODEL], "--U"),
    ("xi zero", ["count", "--xi", "0", "--U", "-1", "--W", "-2", *MODEL], "--xi"),
    ("xi negative", ["count", "--xi=-0.1", "--U", "-1", "--W", "-2", *MODEL], "--xi"),
    ("x zero", ["count", "--x", "0", "--u", "-1", "--v", "1", "--omega", "0", *MODEL], "--x"),
    ("x negative", ["trajectory", "--x=-0.1", "--u", "-1", "--v", "1", "--omega", "0", *MODEL], "--x"),
    ("u zero", ["count", "--x", "0.1", "--u", "0", "--v", "1", "--omega", "0", *MODEL], "--u"),
    ("v zero", ["count", "--x", "0.1", "--u", "-1", "--v", "0", "--omega", "0", *MODEL], "--v"),
    ("v negative", ["count", "--x", "0.1", "--u", "-1", "--v=-1", "--omega", "0", *MODEL], "--v"),
    ("g with a canonical start", ["count", *CANONICAL, *MODEL, "--g", "9.81"], "--g"),
    ("radius with a canonical start", ["trajectory", *CANONICAL, *MODEL, "--radius", "0.03"], "--radius"),
    ("negative radius", ["count", *PHYS, *MODEL, "--radius=-0.025"], "--radius"),
    ("zero radius", ["count", *PHYS, *MODEL, "--radius", "0"], "--radius"),
    ("zero g", ["count", *PHYS, *MODEL, "--g", "0"], "--g"),
    ("max-bounces 0", ["count", *CANONICAL, *MODEL, "--max-bounces", "0"], "--max-bounces"),
    ("max-bounces 0 (trajectory)", ["trajectory", *CANONICAL, *MODEL, "--max-bounces", "0"], "--max-bounces"),
    ("samples 1", ["trajectory", *CANONICAL, *MODEL, "--samples", "1"], "--samples"),
    ("samples negative", ["trajectory", *CANONICAL, *MODEL, "--samples=-2"], "--samples"),
    ("unknown format", ["trajectory", *CANONICAL, *MODEL, "--format", "xml"], "--format"),
    ("unknown flag", ["count", *CANONICAL, *MODEL, "--bogus"], "--bogus"),
    ("unknown flag (trajectory)", ["trajectory", *CANONICAL, *MODEL, "--frobnicate", "3"], "--frobnicate"),
    ("flag given twice", ["count", *CANONICAL, *MODEL, "--xi", "0.2"], "--xi"),
    ("no subcommand", [], "subcommand"),
    # Typos get a suggestion; an unknown flag with none names the command's --help.
    ("misspelt flag", ["count", *CANONICAL, *MODEL, "--max-bounce", "5"], "did you mean --max-bounces?"),
    ("misspelt flag with =", ["trajectory", *CANONICAL, *MODEL, "--sampels=3"], "did you mean --samples?"),
    ("unknown flag, no suggestion", ["count", *CANONICAL, *MODEL, "--verbose"], "see superball count --help"),
    ("misspelt command", ["explor", "job.toml"], "did you mean explore?"),
    ("unknown command", ["plot", "job.toml"], "commands: explore, count"),
    # explore (the job file itself: tests/explore/test_job.cpp and test_explore.py)
    ("explore without a job", ["explore"], "job"),
    ("explore unknown kernel", ["explore", "job.toml", "--kernel", "avx"], "--kernel"),
    ("explore misspelt flag", ["explore", "job.toml", "--kernl", "simd"], "did you mean --kernel?"),
    ("explore resume and overwrite", ["explore", "job.toml", "--resume", "--overwrite"], "--resume"),
    ("explore output without a value", ["explore", "job.toml", "-o"], "--output"),
    ("explore nodes of no rank", ["explore", "job.toml", "--node-ranks", "0"], "--node-ranks"),
    ("explore nodes of text", ["explore", "job.toml", "--node-ranks", "many"], "--node-ranks"),
    ("explore missing job file", ["explore", "/nonexistent/job.toml"], "/nonexistent/job.toml"),
    # info and analyse
    ("info without a file", ["info"], "file"),
    ("info of a missing file", ["info", "/nonexistent/r.h5"], "/nonexistent/r.h5"),
    ("info of a file that is not a result", ["info", os.path.abspath(__file__)], "not a superball result"),
    ("analyse of a missing file", ["analyse", "/nonexistent/r.h5"], "/nonexistent/r.h5"),
    ("analyse box zero", ["analyse", "/nonexistent/r.h5", "--box", "0"], "--box"),
    ("analyse box too large", ["analyse", "/nonexistent/r.h5", "--box", "5000"], "--box"),
    ("analyse eps-max negative", ["analyse", "/nonexistent/r.h5", "--eps-max=-1"], "--eps-max"),
    ("analyse box-max NaN", ["analyse", "/nonexistent/r.h5", "--box-max", "nan"], "--box-max"),
    ("analyse top not a number", ["analyse", "/nonexistent/r.h5", "--top", "x"], "--top"),
    # fixed-points (its ranges: tests/cli/test_fixed_points.py)
    ("fixed-points misspelt flag", ["fixed-points", *MODEL, "--perod", "3"], "did you mean --period?"),
    ("fixed-points seed not a number", ["fixed-points", *MODEL, "--seed", "abc"], "--seed"),
]


class BadInput(CliTestCase):
    def test_table(self):
        for what, args, needle in BAD_INPUT:
            with self.subTest(what, args=" ".join(args)):
                r = run(*args)
                self.assertEqual(r.returncode, 2, "stdout: %r stderr: %r" % (r.stdout, r.stderr))
                self.assertEqual(r.stdout, "", "nothing is printed on standard output")
                lines = r.stderr.splitlines()
                self.assertTrue(lines, "no message on standard error")
                # One line naming the flag; command-line parse errors add the usage hint.
                self.assertIn(needle, lines[0])
                self.assertTrue(len(lines) == 1 or (len(lines) == 2 and lines[1] == HELP_HINT),
                                "message is not one line: %r" % r.stderr)
                self.assertTrue(lines[0].startswith("superball"), lines[0])

    def test_nothing_written_on_bad_input(self):
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "t.csv")
            r = run("trajectory", *CANONICAL, "--e", "2", "--alpha", "0.9", "-o", path)
            self.assertEqual(r.returncode, 2)
            self.assertFalse(os.path.exists(path))


if __name__ == "__main__":
    import sys
    sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    from superball_testing import main

    main()
