#!/usr/bin/env python3
"""Tests of `superball continue`: branches of cycles of the canonical map followed in one
coefficient, checked against references computed here: the map G written out from
SPEC.md section 1 (the physical map, then canonical coordinates) for the residuals, its
finite-difference Jacobian for the eigenvalues, `superball fixed-points` at parameters the
branch crosses, and the elastic ball's self-retracing fixed points; CSV against JSON, the
same output under mpirun -n 1 and -n 2, and bad input.

Run by ctest as `$SUPERBALL_PYTHON tests/cli/test_continue.py -v` with
  SUPERBALL  the built binary (default: a build of this repository, tests/superball_testing.py)
  MPIEXEC    mpirun (default: mpirun on PATH)
Needs numpy (eigenvalues).
"""

import concurrent.futures
import csv
import io
import json
import math
import os
import subprocess
import sys
import unittest

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from superball_testing import main as superball_testing_main  # noqa: E402
from superball_testing import mpi_env, superball_binary  # noqa: E402

MPIEXEC = os.environ.get("MPIEXEC") or "mpirun"

# e = 0.9, alpha = 0.99: the interior fixed point and the corner fixed point, continued in alpha.
PERIOD1 = ["--e", "0.9", "--alpha", "0.99", "--param", "alpha", "--min", "0.95", "--max", "1", "--corner",
           "--starts", "100"]
# A period-3 cycle of the same model (from `fixed-points --period 3`): folds, a period doubling.
PERIOD3 = ["--e", "0.9", "--alpha", "0.99", "--param", "alpha", "--min", "0.98", "--max", "1", "--period", "3",
           "--start", "0.0125,-0.658,-0.54"]
# The same, with every event followed as a curve in (alpha, e).
CURVES = ["--e", "0.9", "--alpha", "0.99", "--param", "alpha", "--min", "0.5", "--max", "1", "--corner", "--starts",
          "100", "--curve", "e", "--curve-min", "0.5", "--curve-max", "0.99"]
CURVE_COLUMNS = ["curve", "branch", "event", "period", "corner", "alpha", "e", "xi", "U", "W", "lambda", "ev1_re",
                 "ev1_im", "ev2_re", "ev2_im", "ev3_re", "ev3_im", "stability", "note"]
COLUMNS = ["branch", "period", "corner", "alpha", "xi", "U", "W", "lambda", "ev1_re", "ev1_im", "ev2_re", "ev2_im",
           "ev3_re", "ev3_im", "stability", "event", "note", "residual", "arclength", "bracket"]
EVENTS = {"", "fold", "period_doubling", "neimark_sacker", "branch_point", "boundary", "end"}


def run(*args, ranks=0, timeout=120):
    """`superball ARGS`, under `mpirun -n RANKS --oversubscribe` if ranks > 0."""
    prefix = [MPIEXEC, "-n", str(ranks), "--oversubscribe"] if ranks else []
    return subprocess.run([*prefix, superball_binary(), *args], capture_output=True, text=True, env=mpi_env(),
                          timeout=timeout)


def continued(*args, ranks=0, fmt="json"):
    r = run("continue", *args, "--format", fmt, ranks=ranks)
    if r.returncode != 0:
        raise AssertionError("continue %s failed (%d): %s" % (args, r.returncode, r.stderr))
    return json.loads(r.stdout) if fmt == "json" else r.stdout


def without_run(text):
    """The CSV without the provenance lines that name the run itself (its time, command
    line and ranks), which two runs never share."""
    return "\n".join(l for l in text.splitlines() if not l.startswith(("# history: ", "# date_created: ")))


def canonical_map(xi, U, W, model):
    """G from SPEC.md section 1 (seed equations), for the representative v = 1, g = 1."""
    ew, aw, ef, af = model["e_wall"], model["alpha_wall"], model["e_floor"], model["alpha_floor"]
    x, u, v, g = 2.0 * xi * abs(U), U, 1.0, 1.0
    y = -(x / u) * (v + g * x / (2.0 * u))
    v_w = v + g * x / u
    u_plus = -ew * u
    v_plus = (2.0 / 7.0) * (1.0 + aw) * W + (1.0 / 7.0) * (5.0 - 2.0 * aw) * v_w
    W_plus = (5.0 / 7.0) * (1.0 + aw) * v_w + (1.0 / 7.0) * (2.0 - 5.0 * aw) * W
    v_f = -math.sqrt(v_plus * v_plus + 2.0 * g * y)
    x1 = u_plus * (v_plus - v_f) / g
    u1 = (1.0 / 7.0) * (5.0 - 2.0 * af) * u_plus - (2.0 / 7.0) * (1.0 + af) * W_plus
    W1 = -(5.0 / 7.0) * (1.0 + af) * u_plus + (1.0 / 7.0) * (2.0 - 5.0 * af) * W_plus
    v1 = -ef * v_f
    return np.array([g * x1 / (2.0 * abs(u1) * v1), u1 / v1, W1 / v1])


def iterate(s, model, k):
    for _ in range(k):
        s = canonical_map(*s, model)
    return s


def model_at(data, value):
    """The run's model with the parameter set to `value`."""
    model = dict(data["model"])
    p = data["parameter"]
    for key in ([p] if p in model else [p + "_wall", p + "_floor"]):
        model[key] = value
    return model


def eigenvalues(point):
    return np.array([complex(z["re"], z["im"]) for z in point["eigenvalues"]])


class Cached:
    """Runs shared by the tests."""

    runs = {}

    @classmethod
    def get(cls, key, *args, **kw):
        if key not in cls.runs:
            cls.runs[key] = continued(*args, **kw)
        return cls.runs[key]


def period1():
    return Cached.get("period1", *PERIOD1)


def period3():
    return Cached.get("period3", *PERIOD3)


def events(branch):
    return [p for p in branch["points"] if p["event"]]


class ContinueTest(unittest.TestCase):
    def test_help_explains_the_events_and_columns(self):
        r = run("continue", "--help")
        self.assertEqual(r.returncode, 0, r.stderr)
        for word in ("--param", "--min", "--max", "--start", "fold", "period_doubling", "neimark_sacker",
                     "branch_point", "boundary", "end", "csv", "json", "mpirun"):
            self.assertIn(word, r.stdout)

    def test_csv_columns_and_rows_match_json(self):
        data = period1()
        text = continued(*PERIOD1, fmt="csv")
        lines = [l for l in text.splitlines() if not l.startswith("#")]
        rows = list(csv.reader(io.StringIO("\n".join(lines))))
        self.assertEqual(rows[0], COLUMNS)
        rows = rows[1:]
        points = [(b, p) for b in data["branches"] for p in b["points"]]
        self.assertEqual(len(rows), len(points))
        for row, (b, p) in zip(rows, points):
            self.assertEqual(int(row[0]), b["branch"])
            self.assertEqual(int(row[1]), b["period"])
            self.assertEqual(row[2], "1" if b["corner"] else "0")
            values = [float(x) for x in row[3:14]]
            ev = eigenvalues(p)
            want = [p["alpha"], p["xi"], p["U"], p["W"], p["lambda"]] + [c for z in ev for c in (z.real, z.imag)]
            self.assertEqual(values, want)  # shortest round-trip text in both
            self.assertEqual(row[14:17], [p["stability"], p["event"], p["note"]])
        self.assertTrue(any(r[15] for r in rows))

    def test_json_fields(self):
        data = period1()
        self.assertEqual(data["parameter"], "alpha")
        self.assertEqual((data["min"], data["max"], data["ranks"]), (0.95, 1, 1))
        self.assertEqual(data["model"], {"e_wall": 0.9, "alpha_wall": 0.99, "e_floor": 0.9, "alpha_floor": 0.99})
        self.assertEqual(data["search"], {"max_period": 1, "starts": 100, "seed": 1, "corner": True})
        self.assertEqual([b["corner"] for b in data["branches"]], [False, True])
        for b in data["branches"]:
            self.assertTrue(b["continued"])
            start = b["points"][b["start_index"]]
            self.assertEqual(start["alpha"], 0.99)
            # The search's cycle, refined again in the continuation's own variables.
            for key in ("xi", "U", "W"):
                self.assertAlmostEqual(start[key], b["start_cycle"][key], delta=1e-12)
            for p in b["points"]:
                self.assertIn(p["event"], EVENTS)
                self.assertTrue(0.95 - 1e-12 <= p["alpha"] <= 1 + 1e-12)
                self.assertEqual(len(p["eigenvalues"]), 3)
                moduli = [abs(z) for z in eigenvalues(p)]
                self.assertEqual(moduli, sorted(moduli, reverse=True))

    def test_every_point_is_a_cycle_of_the_spec_map(self):
        """|G^k(s) - s| <= 1e-10 with G written out here from SPEC.md, at every point."""
        for data in (period1(), period3()):
            for b in data["branches"]:
                for p in b["points"]:
                    s = np.array([p["point"]["xi"], p["point"]["U"], p["point"]["W"]])
                    if b["corner"]:
                        self.assertEqual(s[0], 0.0)
                        continue  # the SPEC map's x/u is 0/u there: checked through the corner's own tests
                    image = iterate(s, model_at(data, p["alpha"]), b["period"])
                    self.assertLessEqual(np.max(np.abs(image - s)), 1e-10, p)
                    self.assertLessEqual(p["residual"], 1e-10)

    def test_eigenvalues_agree_with_finite_differences(self):
        """Eigenvalues of a central-difference Jacobian of the SPEC map's G^k."""
        checked = 0
        for data in (period1(), period3()):
            for b in data["branches"]:
                if b["corner"]:
                    continue
                for p in b["points"][::4]:
                    if p["event"] or p["xi"] < 1e-3:
                        continue
                    s = np.array([p["xi"], p["U"], p["W"]])
                    model = model_at(data, p["alpha"])
                    J = np.empty((3, 3))
                    for j in range(3):
                        h = 1e-6 * max(1.0, abs(s[j])) if j else 1e-6 * s[0]
                        d = np.zeros(3)
                        d[j] = h
                        J[:, j] = (iterate(s + d, model, b["period"]) - iterate(s - d, model, b["period"])) / (2 * h)
                    fd = np.linalg.eigvals(J)
                    scale = max(1.0, max(abs(fd)))
                    for z in eigenvalues(p):
                        self.assertLess(min(abs(fd - z)), 1e-5 * scale, (p, fd))
                    checked += 1
        self.assertGreater(checked, 10)

    def test_branch_passes_through_fixed_points_results(self):
        """At an alpha the interior branch crosses, fixed-points finds the branch's cycle."""
        data = period1()
        points = [p for p in data["branches"][0]["points"] if not p["event"]]
        p = points[len(points) // 4]
        r = run("fixed-points", "--e", "0.9", "--alpha", repr(p["alpha"]), "--starts", "300", "--format", "json")
        self.assertEqual(r.returncode, 0, r.stderr)
        cycles = json.loads(r.stdout)["cycles"]
        nearest = min(cycles, key=lambda c: math.dist((c["xi"], c["U"], c["W"]), (p["xi"], p["U"], p["W"])))
        self.assertLess(math.dist((nearest["xi"], nearest["U"], nearest["W"]), (p["xi"], p["U"], p["W"])), 1e-8)
        self.assertEqual(nearest["stability"], p["stability"])
        for a, b in zip(eigenvalues(nearest), eigenvalues(p)):
            self.assertLess(abs(a - b), 1e-7)

    def test_period1_events(self):
        """The interior branch: two Neimark-Sacker points, then the corner plane where the corner
        branch has its branch point (kappa = 1); both branches end at the bounds."""
        interior, corner = period1()["branches"]
        self.assertEqual([p["event"] for p in events(interior)], ["boundary", "neimark_sacker", "neimark_sacker", "end"])
        self.assertEqual([p["event"] for p in events(corner)], ["end", "neimark_sacker", "branch_point", "end"])
        meet = events(interior)[0]
        self.assertEqual(meet["note"], "xi -> 0")
        bp = events(corner)[2]
        self.assertIn("kappa = 1", bp["note"])
        self.assertAlmostEqual(meet["alpha"], bp["alpha"], delta=1e-9)
        self.assertAlmostEqual(meet["U"], bp["U"], delta=1e-7)
        self.assertEqual((events(interior)[-1]["alpha"], events(corner)[0]["alpha"]), (1, 0.95))
        for b in (interior, corner):
            for e in events(b):
                self.assertLessEqual(e["bracket"], 1e-8)

    def test_events_bracket_a_sign_change(self):
        """Around each event the neighbouring points lie on either side of it: the parameter
        turns at a fold, a real eigenvalue crosses -1 at a period doubling and 1 at a branch
        point, the complex pair the unit circle at a Neimark-Sacker point."""
        seen = set()
        for data in (period1(), period3()):
            for b in data["branches"]:
                pts = b["points"]
                for i in range(1, len(pts) - 1):
                    e, before, after = pts[i], pts[i - 1], pts[i + 1]
                    if e["event"] in ("", "end", "boundary") or before["event"] or after["event"]:
                        continue
                    seen.add(e["event"])
                    if e["event"] == "fold":
                        self.assertLess((e["alpha"] - before["alpha"]) * (after["alpha"] - e["alpha"]), 0)
                    elif e["event"] == "period_doubling":
                        # det(D(G^k) + I): changes sign when a real eigenvalue passes -1.
                        def det_plus_one(p):
                            return np.prod(1 + eigenvalues(p)).real

                        self.assertLess(det_plus_one(before) * det_plus_one(after), 0)
                        self.assertAlmostEqual(min(abs(eigenvalues(e) + 1)), 0, delta=1e-7)
                    elif e["event"] == "branch_point":
                        # det(D(G^k) - I): a real eigenvalue passes 1 (not at a fold: alpha goes on).
                        def det_minus_one(p):
                            return np.prod(1 - eigenvalues(p)).real

                        self.assertLess(det_minus_one(before) * det_minus_one(after), 0)
                        self.assertGreater((e["alpha"] - before["alpha"]) * (after["alpha"] - e["alpha"]), 0)
                    elif e["event"] == "neimark_sacker":
                        def pair(p):
                            ev = eigenvalues(p)
                            return abs(ev[np.argmax(ev.imag)]) - 1

                        self.assertLess(pair(before) * pair(after), 0)
                        self.assertAlmostEqual(pair(e), 0, delta=1e-7)
        self.assertEqual(seen, {"fold", "period_doubling", "neimark_sacker", "branch_point"})

    def test_same_output_under_mpirun(self):
        """Branches are shared among ranks; the output does not depend on how many."""
        one = continued(*PERIOD1, "--period", "3", ranks=1)
        two = continued(*PERIOD1, "--period", "3", ranks=2)
        self.assertEqual((one.pop("ranks"), two.pop("ranks")), (1, 2))
        self.assertEqual(one, two)
        self.assertGreaterEqual(len(one["branches"]), 3)
        # The two period-3 cycles of the search lie on one branch (joined through folds).
        self.assertTrue(any(b["same_as"] is not None for b in one["branches"]))
        two_csv = continued(*PERIOD1, "--period", "3", fmt="csv", ranks=2)
        self.assertIn("2 MPI ranks on 1 host", two_csv)  # provenance (history) in the header
        self.assertEqual(without_run(two_csv.replace("2 ranks", "1 rank")),
                         without_run(continued(*PERIOD1, "--period", "3", fmt="csv")))

    def test_elastic_family_has_no_false_events(self):
        """e = alpha = 1: the branch is the family xi = (1+U)/2, W = 5U/2, lambda = 1 at alpha = 1,
        ending at the corner point U = -1 and at U -> 0, with no event in between."""
        data = continued("--e", "1", "--alpha", "1", "--param", "alpha", "--min", "0.5", "--max", "1",
                         "--start", "0.25,-0.5,-1.25")
        (b,) = data["branches"]
        self.assertEqual([p["event"] for p in events(b)], ["boundary", "boundary"])
        self.assertGreater(len(b["points"]), 30)
        for p in b["points"]:
            self.assertAlmostEqual(p["alpha"], 1.0, delta=1e-12)
            self.assertAlmostEqual(p["lambda"], 1.0, delta=1e-10)
            self.assertAlmostEqual(p["xi"], (1 + p["U"]) / 2, delta=1e-9)
            self.assertAlmostEqual(p["W"], 2.5 * p["U"], delta=1e-9)
        self.assertAlmostEqual(b["points"][0]["U"], -1.0, delta=1e-9)

    def test_output_file(self):
        data = period3()
        out = os.path.join(os.environ.get("TMPDIR", "/tmp"), "superball_test_continue_%d.json" % os.getpid())
        try:
            r = run("continue", *PERIOD3, "--format", "json", "-o", out)
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertEqual(r.stdout, "")
            with open(out) as f:
                self.assertEqual(json.load(f), data)
        finally:
            if os.path.exists(out):
                os.remove(out)

    def test_event_curves(self):
        """Every event of the branches followed in (alpha, e): the corner fixed point's
        Neimark-Sacker and branch-point (kappa = 1) curves, the interior one's two Neimark-Sacker
        curves. Along them the eigenvalues stay on the unit circle (at 1 for the branch point)."""
        data = Cached.get("curves", *CURVES)
        self.assertEqual((data["curve_parameter"], data["curve_min"], data["curve_max"]), ("e", 0.5, 0.99))
        kinds = sorted((c["event"], data["branches"][c["branch"]]["corner"]) for c in data["curves"])
        self.assertEqual(kinds, [("branch_point", True), ("neimark_sacker", False), ("neimark_sacker", False),
                                 ("neimark_sacker", True)])
        for c in data["curves"]:
            branch = data["branches"][c["branch"]]
            event = branch["points"][c["event_index"]]
            start = c["points"][c["start_index"]]
            self.assertEqual((start["alpha"], start["e"]), (event["alpha"], 0.9))
            self.assertGreater(len(c["points"]), 15)
            self.assertTrue(all(0.5 <= p["e"] <= 0.99 and 0.5 <= p["alpha"] <= 1 for p in c["points"]))
            for p in c["points"]:
                ev = eigenvalues(p)
                if c["event"] == "neimark_sacker":
                    self.assertAlmostEqual(abs(ev[np.argmax(ev.imag)]), 1.0, delta=1e-7)
                else:
                    self.assertAlmostEqual(min(abs(ev - 1)), 0.0, delta=1e-7)
        # Independently, at a point halfway along the corner Neimark-Sacker curve: fixed-points
        # finds the corner cycle's pair inside the unit circle on one side and outside on the other.
        (ns,) = [c for c in data["curves"] if c["event"] == "neimark_sacker" and data["branches"][c["branch"]]["corner"]]
        p = ns["points"][len(ns["points"]) // 2]
        moduli = []
        for alpha in (p["alpha"] - 1e-6, p["alpha"] + 1e-6):
            r = run("fixed-points", "--e", repr(p["e"]), "--alpha", repr(alpha), "--corner", "--starts", "200",
                    "--format", "json")
            self.assertEqual(r.returncode, 0, r.stderr)
            (corner,) = [c for c in json.loads(r.stdout)["cycles"] if c["corner"]]
            self.assertAlmostEqual(corner["U"], p["U"], delta=1e-4)
            ev = eigenvalues(corner)
            moduli.append(abs(ev[np.argmax(ev.imag)]) - 1)
        self.assertLess(moduli[0] * moduli[1], 0)

    def test_event_curves_csv_and_mpirun(self):
        data = Cached.get("curves", *CURVES)
        text = continued(*CURVES, fmt="csv", ranks=2)
        self.assertIn("on 2 ranks", text)
        self.assertEqual(without_run(text.replace("on 2 ranks", "on 1 rank")), without_run(continued(*CURVES, fmt="csv")))
        lines = [l for l in text.splitlines() if not l.startswith("#")]
        rows = list(csv.reader(io.StringIO("\n".join(lines))))
        self.assertEqual(rows[0], CURVE_COLUMNS)
        self.assertEqual(len(rows) - 1, sum(len(c["points"]) for c in data["curves"]))
        self.assertEqual(sum(l.startswith("# curve ") for l in text.splitlines()), len(data["curves"]))

    def test_bad_input_names_the_flag(self):
        base = ["--e", "0.9", "--alpha", "0.99"]
        rng = ["--param", "alpha", "--min", "0.95", "--max", "1"]
        cases = [
            (base + ["--min", "0.9", "--max", "1"], "--param"),
            (base + ["--param", "beta", "--min", "0.9", "--max", "1"], "--param"),
            (base + ["--param", "alpha", "--max", "1"], "--min"),
            (base + ["--param", "alpha", "--min", "-2", "--max", "1"], "--min"),
            (base + ["--param", "alpha", "--min", "0.95", "--max", "1.5"], "--max"),
            (base + ["--param", "alpha", "--min", "1", "--max", "0.95"], "--min"),
            (base + ["--param", "alpha", "--min", "0.995", "--max", "1"], "outside --min"),
            (["--e", "0.9", "--e-wall", "0.8", "--alpha", "0.99", "--param", "e", "--min", "0.5", "--max", "1"],
             "--param"),
            (base + rng + ["--start", "0.2,-0.5"], "--start"),
            (base + rng + ["--start", "0.2,x,-1"], "--start"),
            (base + rng + ["--start", "0.2,0.5,-1"], "--start"),
            (base + rng + ["--start", "0.9,-50,30"], "--start"),
            (base + rng + ["--period", "0"], "--period"),
            (base + rng + ["--period", "9"], "--period"),
            (base + rng + ["--format", "xml"], "--format"),
            (base + rng + ["--step", "0"], "--step"),
            (base + rng + ["--step", "0.1", "--max-step", "0.05"], "--step"),
            (base + rng + ["--max-step", "-1"], "--max-step"),
            (base + rng + ["--max-points", "0"], "--max-points"),
            (base + rng + ["--starts", "0"], "--starts"),
            (["--e", "0.9"] + rng, "--alpha"),
            (base + rng + ["--curve", "beta", "--curve-min", "0.5", "--curve-max", "1"], "--curve"),
            (base + rng + ["--curve", "alpha", "--curve-min", "0.5", "--curve-max", "1"], "--curve"),
            (base + rng + ["--curve", "alpha_wall", "--curve-min", "0.5", "--curve-max", "1"], "--curve"),
            (base + rng + ["--curve", "e", "--curve-max", "1"], "--curve-min"),
            (base + rng + ["--curve", "e", "--curve-min", "0.5", "--curve-max", "1.5"], "--curve-max"),
            (base + rng + ["--curve", "e", "--curve-min", "0.95", "--curve-max", "0.5"], "--curve-min"),
            (base + rng + ["--curve", "e", "--curve-min", "0.95", "--curve-max", "1"], "outside --curve-min"),
            (base + rng + ["--curve", "e", "--curve-min", "0.5", "--curve-max", "1", "--curve-step", "0"],
             "--curve-step"),
        ]
        # Concurrently: each run waits mostly for MPI's start-up.
        with concurrent.futures.ThreadPoolExecutor(max_workers=8) as pool:
            results = list(pool.map(lambda case: run("continue", *case[0]), cases))
        for (args, flag), r in zip(cases, results):
            with self.subTest(args=args):
                self.assertEqual(r.returncode, 2, r.stderr)
                self.assertIn(flag, r.stderr)
                self.assertEqual(r.stdout, "")
        # Under mpirun: status 2 and one message, not one per rank.
        r = run("continue", *base, "--param", "beta", "--min", "0", "--max", "1", ranks=2)
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertEqual(r.stderr.count("--param"), 1, r.stderr)


if __name__ == "__main__":
    superball_testing_main()
