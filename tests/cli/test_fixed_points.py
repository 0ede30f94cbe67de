#!/usr/bin/env python3
"""Tests of `superball fixed-points`: cycles of the canonical map G found by Newton's method,
the same with and without mpirun, checked against `superball trajectory` (the physical
motion) and, for the elastic ball, against the self-retracing fixed points derived in
src/core/dynamics.hpp.

Run by ctest as `$SUPERBALL_PYTHON tests/cli/test_fixed_points.py -v` with
  SUPERBALL  the built binary
  MPIEXEC    mpirun (default: mpirun on PATH)
Standard library only.
"""

import cmath
import json
import math
import os
import subprocess
import tempfile
import unittest

SUPERBALL = os.environ.get("SUPERBALL", "")
MPIEXEC = os.environ.get("MPIEXEC") or "mpirun"

# A dissipative model with interior cycles of periods 1 and 3 and a stable corner fixed point.
DISSIPATIVE = ["--e", "0.9", "--alpha", "0.99"]
SEARCH = ["--period", "3", "--starts", "600", "--seed", "3", "--corner"]
RESIDUAL_TOLERANCE = 1e-10


def setUpModule():
    if not SUPERBALL or not os.access(SUPERBALL, os.X_OK):
        raise RuntimeError("set SUPERBALL to the built superball binary (got %r)" % SUPERBALL)


def mpi_env():
    env = dict(os.environ)
    env.setdefault("OMPI_ALLOW_RUN_AS_ROOT", "1")
    env.setdefault("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
    env.setdefault("OMPI_MCA_rmaps_base_oversubscribe", "1")
    return env


def run(*args, ranks=0, timeout=120):
    """`superball ARGS`, under `mpirun -n RANKS` if ranks > 0."""
    prefix = [MPIEXEC, "-n", str(ranks), "--oversubscribe"] if ranks else []
    return subprocess.run([*prefix, SUPERBALL, *args], capture_output=True, text=True, env=mpi_env(), timeout=timeout)


def fixed_points(*args, ranks=0):
    r = run("fixed-points", *args, "--format", "json", ranks=ranks)
    if r.returncode != 0:
        raise AssertionError("fixed-points %s failed (%d): %s" % (args, r.returncode, r.stderr))
    return json.loads(r.stdout)


def eigenvalues(cycle):
    return [complex(z["re"], z["im"]) for z in cycle["eigenvalues"]]


def self_retracing_eigenvalues(U):
    """1 and the roots of 49 U mu^2 + (122 U + 40) mu + 49 U = 0 (dynamics.hpp)."""
    b = (122.0 * U + 40.0) / (49.0 * U)
    root = cmath.sqrt(b * b - 4.0)
    return [1.0, (-b + root) / 2.0, (-b - root) / 2.0]


class Cached:
    """Runs of the dissipative search, shared by the tests."""

    serial = None
    parallel = None

    @classmethod
    def get(cls):
        if cls.serial is None:
            cls.serial = fixed_points(*DISSIPATIVE, *SEARCH)
            cls.parallel = fixed_points(*DISSIPATIVE, *SEARCH, ranks=2)
        return cls.serial, cls.parallel


class FixedPointsTest(unittest.TestCase):
    def test_same_cycles_with_and_without_mpirun(self):
        serial, parallel = Cached.get()
        self.assertEqual(serial["ranks"], 1)
        self.assertEqual(parallel["ranks"], 2)
        # Every start is examined in the same order whatever the ranks: identical to the bit.
        self.assertEqual(serial["cycles"], parallel["cycles"])
        periods = sorted((c["period"], c["corner"]) for c in serial["cycles"])
        self.assertIn((1, False), periods)
        self.assertIn((3, False), periods)
        self.assertIn((1, True), periods)

    def test_fields_are_consistent(self):
        serial, _ = Cached.get()
        self.assertEqual(serial["model"], {"e_wall": 0.9, "alpha_wall": 0.99, "e_floor": 0.9, "alpha_floor": 0.99})
        self.assertEqual((serial["max_period"], serial["starts"], serial["seed"]), (3, 600, 3))
        for c in serial["cycles"]:
            with self.subTest(cycle=c):
                points = c["points"]
                self.assertEqual(len(points), c["period"])
                self.assertEqual((c["xi"], c["U"], c["W"]), (points[0]["xi"], points[0]["U"], points[0]["W"]))
                # Representative: the point with the smallest xi.
                self.assertEqual(points[0]["xi"], min(p["xi"] for p in points))
                for p in points:
                    self.assertLess(p["U"], 0.0)
                    if c["corner"]:
                        self.assertEqual(p["xi"], 0.0)
                    else:
                        self.assertTrue(0.0 < p["xi"] < 1.0)
                self.assertLessEqual(c["residual"], RESIDUAL_TOLERANCE)
                self.assertTrue(0.0 < c["lambda"] < 1.0)  # dissipative: the motion shrinks
                ev = eigenvalues(c)
                self.assertEqual(len(ev), 3)
                # Real matrix: complex eigenvalues in conjugate pairs; sorted by modulus.
                self.assertAlmostEqual(sum(z.imag for z in ev), 0.0, places=12)
                moduli = [abs(z) for z in ev]
                self.assertEqual(moduli, sorted(moduli, reverse=True))
                tol = serial["marginal_tolerance"]
                inside = sum(m < 1 - tol for m in moduli)
                outside = sum(m > 1 + tol for m in moduli)
                expected = ("stable" if inside == 3 else "unstable" if outside == 3 else
                            "saddle" if inside and outside else "marginal")
                self.assertEqual(c["stability"], expected)
                self.assertFalse(c["family"])

    def test_cycles_are_cycles_of_the_physical_motion(self):
        """`superball trajectory` follows the physical motion (a different code path): after
        `period` wall impacts the launch is the cycle's start again, scaled by lambda."""
        serial, _ = Cached.get()
        interior = [c for c in serial["cycles"] if not c["corner"]]
        self.assertTrue(interior)
        for c in interior:
            with self.subTest(cycle=c):
                start = ["--xi", repr(c["xi"]), "--U", repr(c["U"]), "--W", repr(c["W"])]
                r = run("trajectory", *DISSIPATIVE, *start, "--max-bounces", str(c["period"]), "--format", "json")
                self.assertEqual(r.returncode, 0, r.stderr)
                tr = json.loads(r.stdout)
                floors = [e for e in tr["events"] if e["event"] == "floor"]
                self.assertEqual(len(floors), c["period"])
                for i, e in enumerate(floors):
                    # Dimensionless units: v0 = g = radius = 1, so omega = W.
                    got = (e["x"] / (2 * abs(e["u"]) * e["v"]), e["u"] / e["v"], e["omega"] / e["v"])
                    want = c["points"][(i + 1) % c["period"]]
                    self.assertLess(abs(got[0] / want["xi"] - 1), 1e-8)
                    scale = math.hypot(want["U"], want["W"])
                    self.assertLess(math.hypot(got[1] - want["U"], got[2] - want["W"]) / scale, 1e-8)
                self.assertLess(abs(floors[-1]["v"] / c["lambda"] - 1), 1e-12)

    def test_elastic_ball_self_retracing_family(self):
        """e = alpha = 1: the fixed points are the self-retracing motions xi = (1 + U)/2,
        W = 5U/2 with lambda = 1, and the eigenvalues of the closed form."""
        data = fixed_points("--e", "1", "--alpha", "1", "--starts", "300", "--seed", "5")
        cycles = data["cycles"]
        self.assertGreater(len(cycles), 10)
        for c in cycles:
            with self.subTest(cycle=c):
                U = c["U"]
                self.assertEqual(c["period"], 1)
                self.assertAlmostEqual(c["xi"], (1 + U) / 2, delta=1e-9)
                self.assertAlmostEqual(c["W"], 2.5 * U, delta=1e-9)
                self.assertAlmostEqual(c["lambda"], 1.0, delta=1e-10)
                self.assertTrue(c["family"])
                if abs(U + 2 / 11) > 1e-3:  # eigenvalues are ill-conditioned at the transition
                    got = eigenvalues(c)
                    for want in self_retracing_eigenvalues(U):
                        nearest = min(got, key=lambda z: abs(z - want))
                        self.assertLess(abs(nearest - want), 1e-7)
                        got.remove(nearest)
                    self.assertEqual(c["stability"], "marginal" if U < -2 / 11 else "saddle")
        self.assertTrue(any(c["stability"] == "marginal" for c in cycles))
        self.assertTrue(any(c["stability"] == "saddle" for c in cycles))

    def test_dissipative_uniform_model(self):
        """e = alpha = 0.9: whatever is found has lambda < 1 and a tiny residual; on the corner
        plane, the analytic fixed point (U, W) = (-1, -5/2), lambda = e^2, kappa = e^-4."""
        data = fixed_points("--e", "0.9", "--alpha", "0.9", "--period", "2", "--starts", "500", "--corner")
        corner = [c for c in data["cycles"] if c["corner"]]
        self.assertEqual(len(corner), 1)
        c = corner[0]
        self.assertAlmostEqual(c["U"], -1.0, delta=1e-12)
        self.assertAlmostEqual(c["W"], -2.5, delta=1e-12)
        self.assertAlmostEqual(c["lambda"], 0.81, delta=1e-12)
        self.assertAlmostEqual(eigenvalues(c)[0].real, 0.9 ** -4, delta=1e-10)
        for c in data["cycles"]:
            self.assertLessEqual(c["residual"], RESIDUAL_TOLERANCE)
            self.assertLess(c["lambda"], 1.0)

    def test_table_has_one_line_per_cycle(self):
        serial, _ = Cached.get()
        r = run("fixed-points", *DISSIPATIVE, *SEARCH)
        self.assertEqual(r.returncode, 0, r.stderr)
        lines = [l for l in r.stdout.splitlines() if l and not l.startswith("#")]
        self.assertEqual(lines[0].split(), ["period", "xi", "U", "W", "lambda", "eig1", "eig2", "eig3", "stability",
                                            "family", "corner"])
        rows = [l.split() for l in lines[1:]]
        self.assertEqual(len(rows), len(serial["cycles"]))
        for row, c in zip(rows, serial["cycles"]):
            self.assertEqual(len(row), 11)
            self.assertEqual(int(row[0]), c["period"])
            self.assertAlmostEqual(float(row[1]), c["xi"], delta=1e-14)
            self.assertAlmostEqual(float(row[2]), c["U"], delta=1e-14)
            self.assertEqual(row[8], c["stability"])

    def test_output_file(self):
        serial, _ = Cached.get()
        with tempfile.TemporaryDirectory() as d:
            out = os.path.join(d, "cycles.json")
            r = run("fixed-points", *DISSIPATIVE, *SEARCH, "--format", "json", "-o", out)
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertEqual(r.stdout, "")
            with open(out) as f:
                self.assertEqual(json.load(f), serial)

    def test_bad_input_names_the_flag(self):
        cases = [
            (["--period", "0"], "--period"),
            (["--period", "9"], "--period"),
            (["--starts", "0"], "--starts"),
            (["--format", "xml"], "--format"),
            (["--e", "1.5", "--alpha", "1"], "--e"),
            (["--alpha", "1"], "--e"),
            (["--starts", "many"], "--starts"),
        ]
        for extra, flag in cases:
            with self.subTest(args=extra):
                args = extra if "--alpha" in extra else ["--e", "0.9", "--alpha", "1", *extra]
                r = run("fixed-points", *args)
                self.assertEqual(r.returncode, 2, r.stderr)
                self.assertIn(flag, r.stderr)
                self.assertEqual(r.stdout, "")
        # Under mpirun: still status 2, and one message, not one per rank.
        r = run("fixed-points", "--e", "0.9", "--alpha", "1", "--period", "9", ranks=2)
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertEqual(r.stderr.count("--period"), 1, r.stderr)


if __name__ == "__main__":
    import sys
    sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    from superball_testing import main

    main()
