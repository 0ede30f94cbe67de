#!/usr/bin/python3
"""End-to-end tests of `superball analyse`: a 256 x 256 copy of jobs/quickstart.toml is
explored under mpirun, analysed with --json, and the report is checked against the same
quantities computed with h5py/numpy from the file (area fractions, boundary pairs,
1-uncertain points, basin entropy) and against the bounds the estimators must respect.
Also: 3-D results need --slice (and a slice reads the right plane), tiles not yet done
read as invalid, bad input exits with status 2 and a message naming the problem.

Run by ctest as `$SUPERBALL_PYTHON tests/cli/test_analyse.py -v` with
  SUPERBALL             the built binary
  MPIEXEC               mpirun (default: mpirun)
  SUPERBALL_SOURCE_DIR  the source tree (default: two levels up from this file)
"""
import json
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
import unittest

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))
from superball_testing import main as superball_testing_main  # noqa: E402
from superball_testing import interrupted_run  # noqa: E402

SUPERBALL = os.environ.get("SUPERBALL", "superball")
MPIEXEC = os.environ.get("MPIEXEC") or "mpirun"
SOURCE_DIR = os.environ.get("SUPERBALL_SOURCE_DIR", os.path.join(HERE, os.pardir, os.pardir))
OUTCOMES = ["invalid", "left", "missed", "capped"]
N = 256


def mpi_env():
    env = dict(os.environ)
    if os.geteuid() == 0:  # Open MPI refuses root unless told
        env.update(OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    return env


def explore(job, out):
    r = subprocess.run([MPIEXEC, "-n", "2", "--oversubscribe", SUPERBALL, "explore", job, "-o", out, "-q"],
                       capture_output=True, text=True, env=mpi_env(), timeout=300)
    if r.returncode != 0:
        raise RuntimeError("explore %s failed (%d): %s" % (job, r.returncode, r.stderr))


def analyse(*args):
    return subprocess.run([SUPERBALL, "analyse", *args], capture_output=True, text=True, timeout=120)


def analyse_json(*args):
    r = analyse(*args, "--json")
    if r.returncode != 0:
        raise AssertionError("analyse %s: exit %d: %s" % (args, r.returncode, r.stderr))
    return json.loads(r.stdout)


def read_plane(path, index=None):
    """(wall_bounces, outcome) of a 2-D result, or of the plane index (a tuple of slices)."""
    with h5py.File(path, "r") as f:
        sel = index if index is not None else ()
        return f["wall_bounces"][sel].astype(np.int64), f["outcome"][sel].astype(np.int64)


def differ(a, b, valid_a, valid_b):
    return (a != b) & valid_a & valid_b


class Quickstart(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.dir = tempfile.mkdtemp(prefix="superball-analyse-")
        with open(os.path.join(SOURCE_DIR, "jobs", "quickstart.toml")) as f:
            text = f.read()
        text = re.sub(r"n = 1024", "n = %d" % N, text)
        cls.job = os.path.join(cls.dir, "quickstart.toml")
        with open(cls.job, "w") as f:
            f.write(text)
        cls.result = os.path.join(cls.dir, "quickstart.h5")
        explore(cls.job, cls.result)
        cls.report = analyse_json(cls.result)
        cls.wb, cls.outcome = read_plane(cls.result)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.dir, ignore_errors=True)

    def test_shape_and_axes(self):
        r = self.report
        self.assertEqual((r["rows"], r["cols"]), (N, N))
        self.assertEqual((r["row_axis"], r["col_axis"]), ("xi", "W"))
        self.assertIsNone(r["slice"])
        self.assertAlmostEqual(r["cell"]["row"], 1.0 / N, places=12)
        self.assertAlmostEqual(r["cell"]["col"], 6.0 / N, places=12)

    def test_fractions_sum_to_one_and_match_h5py(self):
        area = self.report["area"]
        self.assertEqual(area["points"], N * N)
        outcome_fractions = [area["by_outcome"][name]["fraction"] for name in OUTCOMES]
        self.assertAlmostEqual(sum(outcome_fractions), 1.0, places=12)
        for code, name in enumerate(OUTCOMES):
            self.assertEqual(area["by_outcome"][name]["points"], int(np.sum(self.outcome == code)), name)
        valid = self.outcome != 0
        self.assertEqual(area["valid"], int(valid.sum()))
        counts, points = np.unique(self.wb[valid], return_counts=True)
        self.assertEqual([c["wall_bounces"] for c in area["by_count"]], counts.tolist())
        self.assertEqual([c["points"] for c in area["by_count"]], points.tolist())
        fractions = [c["fraction"] for c in area["by_count"]]
        self.assertAlmostEqual(sum(fractions), 1.0, places=12)
        np.testing.assert_allclose(fractions, points / valid.sum(), rtol=1e-14)

    def test_boundary_pairs_match_numpy(self):
        wb, valid = self.wb, self.outcome != 0
        row_pairs = differ(wb[:, 1:], wb[:, :-1], valid[:, 1:], valid[:, :-1]).sum()
        col_pairs = differ(wb[1:, :], wb[:-1, :], valid[1:, :], valid[:-1, :]).sum()
        b = self.report["boundary"]
        self.assertEqual((b["row_pairs"], b["col_pairs"]), (int(row_pairs), int(col_pairs)))
        cell = self.report["cell"]
        self.assertAlmostEqual(b["length"], row_pairs * cell["row"] + col_pairs * cell["col"], places=9)
        self.assertGreater(b["class_pairs"], 1)
        self.assertLessEqual(len(b["top"]), 5)

    def test_uncertainty(self):
        u = self.report["uncertainty"]
        self.assertEqual(u["eps"], [1, 2, 4])  # default: N/64
        fractions = u["fraction"]
        self.assertEqual(fractions, sorted(fractions))  # more points are uncertain at larger e
        # f(1): a point of another class among the 4 adjacent points.
        wb, valid = self.wb, self.outcome != 0
        uncertain = np.zeros_like(valid)
        uncertain[:, 1:] |= differ(wb[:, 1:], wb[:, :-1], valid[:, 1:], valid[:, :-1])
        uncertain[:, :-1] |= differ(wb[:, :-1], wb[:, 1:], valid[:, :-1], valid[:, 1:])
        uncertain[1:, :] |= differ(wb[1:, :], wb[:-1, :], valid[1:, :], valid[:-1, :])
        uncertain[:-1, :] |= differ(wb[:-1, :], wb[1:, :], valid[:-1, :], valid[1:, :])
        self.assertEqual(u["uncertain"][0], int(uncertain.sum()))
        alpha = u["exponent"]
        self.assertGreater(alpha, 0.0)
        self.assertLessEqual(alpha, 1.0)
        self.assertAlmostEqual(u["dimension"], 2.0 - alpha, places=12)
        x, y = np.log(u["eps"]), np.log(fractions)
        self.assertAlmostEqual(alpha, np.polyfit(x, y, 1)[0], places=9)

    def test_box_counting(self):
        c = self.report["box_counting"]
        self.assertEqual(c["sizes"], [1, 2, 4, 8, 16])  # default: N/16
        self.assertEqual(c["boxes"], sorted(c["boxes"], reverse=True))
        self.assertGreaterEqual(c["dimension"], 1.0)
        self.assertLessEqual(c["dimension"], 2.0)

    def test_basin_entropy(self):
        e = self.report["basin_entropy"]
        self.assertEqual(e["box"], 5)
        self.assertEqual(e["boxes"], (N // 5) ** 2)
        classes = len(self.report["area"]["by_count"])
        self.assertGreaterEqual(e["S_b"], 0.0)
        self.assertLessEqual(e["S_b"], math.log(classes))
        self.assertLessEqual(e["S_bb"], math.log(min(classes, 25)))
        self.assertLessEqual(e["S_b"], e["S_bb"])
        self.assertEqual(e["fractal_by_log2_criterion"], e["S_bb"] > math.log(2))
        # The same tiling with numpy (every point is valid in this job).
        self.assertTrue((self.outcome != 0).all())
        m = (N // 5) * 5
        boxes = self.wb[:m, :m].reshape(N // 5, 5, N // 5, 5).transpose(0, 2, 1, 3).reshape(-1, 25)
        entropies, mixed = [], 0
        for box in boxes:
            _, n = np.unique(box, return_counts=True)
            p = n / 25.0
            entropies.append(-(p * np.log(p)).sum())
            mixed += len(n) > 1
        self.assertEqual(e["boundary_boxes"], mixed)
        self.assertAlmostEqual(e["S_b"], float(np.mean(entropies)), places=12)

    def test_text_report(self):
        r = analyse(self.result, "--box", "4", "--eps-max", "8")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("uncertainty exponent alpha", r.stdout)
        self.assertIn("box-counting dimension", r.stdout)
        self.assertIn("boxes of 4 x 4", r.stdout)
        self.assertRegex(r.stdout, r"\n\s+8\s+\d+\s+[0-9.e-]+\n")  # the e = 8 row

    def test_with_outcome_separates_left_from_missed(self):
        r = analyse_json(self.result, "--with-outcome")
        self.assertEqual(r["classes"], "count_and_outcome")
        self.assertGreaterEqual(r["boundary"]["row_pairs"], self.report["boundary"]["row_pairs"])

    def test_missing_tiles_read_as_invalid(self):
        """The partial file of an interrupted run: points of tiles not done read as
        invalid, and the report says how many tiles are missing."""
        out = os.path.join(self.dir, "interrupted.h5")
        # Tiles 0, 3 and the last copied from the complete result, each recorded with its
        # checksum as the run records it (the readers check them).
        probe = interrupted_run(SUPERBALL, self.job, out, self.result, lambda t: False)
        with h5py.File(probe, "r") as f:
            th, tw = (int(t) for t in f.attrs["tile_shape"])
            last = f["progress/tile_done"].size - 1
        os.remove(probe)
        partial = interrupted_run(SUPERBALL, self.job, out, self.result, lambda t: t in (0, 3, last))
        tiles_per_row = -(-N // tw)
        with h5py.File(partial, "r") as f:
            done = f["progress/tile_done"][...]
        points = 0
        for t in np.flatnonzero(done == 0):
            i0, j0 = (t // tiles_per_row) * th, (t % tiles_per_row) * tw
            points += (min(i0 + th, N) - i0) * (min(j0 + tw, N) - j0)
        r = analyse_json(partial)
        self.assertEqual(r["tiles_missing"], int((done == 0).sum()))
        self.assertEqual(r["area"]["by_outcome"]["invalid"]["points"], points)
        self.assertEqual(r["area"]["valid"], N * N - points)

    def test_bad_input(self):
        for args, message in [
            ((os.path.join(self.dir, "nothing.h5"),), "no such file"),
            ((self.job,), "not a superball result"),
            ((self.result, "--slice", "U=0"), "3-D results only"),
            ((self.result, "--eps-max", "256"), "--eps-max"),
            ((self.result, "--box", "0"), "--box"),
        ]:
            r = analyse(*args)
            self.assertEqual(r.returncode, 2, "%s: %s" % (args, r.stderr))
            self.assertIn(message, r.stderr, args)


class OtherShapes(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.dir = tempfile.mkdtemp(prefix="superball-analyse-shapes-")
        model = "[model]\ne = 0.9\nalpha = 0.9\n"
        grids = {
            "line": 'xi = { min = 0.0, max = 1.0, n = 40 }\nU = -1.0\nW = 1.0',
            "cube": 'xi = { min = 0.0, max = 1.0, n = 24 }\nU = { min = -2.0, max = -0.5, n = 6 }\n'
                    'W = { min = -3.0, max = 3.0, n = 32 }',
        }
        cls.results = {}
        for name, grid in grids.items():
            job = os.path.join(cls.dir, name + ".toml")
            with open(job, "w") as f:
                f.write(model + "[grid]\n" + grid + "\n[run]\nmax_bounces = 100\n")
            cls.results[name] = os.path.join(cls.dir, name + ".h5")
            explore(job, cls.results[name])

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.dir, ignore_errors=True)

    def test_3d_result_needs_slice(self):
        r = analyse(self.results["cube"])
        self.assertEqual(r.returncode, 2)
        self.assertIn("--slice", r.stderr)
        self.assertIn("3-D", r.stderr)
        for bad in ["V=1", "U=6", "U", "U=-1"]:
            r = analyse(self.results["cube"], "--slice", bad)
            self.assertEqual(r.returncode, 2, bad)
            self.assertIn("--slice", r.stderr, bad)

    def test_slice_reads_its_plane(self):
        for spec, index, plane in [("U=3", (slice(None), 3, slice(None)), ("xi", "W")),
                                   ("0=5", (5, slice(None), slice(None)), ("U", "W")),
                                   ("W=31", (slice(None), slice(None), 31), ("xi", "U"))]:
            r = analyse_json(self.results["cube"], "--slice", spec)
            wb, outcome = read_plane(self.results["cube"], index)
            self.assertEqual((r["rows"], r["cols"]), wb.shape, spec)
            self.assertEqual((r["row_axis"], r["col_axis"]), plane, spec)
            valid = outcome != 0
            counts, points = np.unique(wb[valid], return_counts=True)
            self.assertEqual([c["wall_bounces"] for c in r["area"]["by_count"]], counts.tolist(), spec)
            self.assertEqual([c["points"] for c in r["area"]["by_count"]], points.tolist(), spec)
            row_pairs = differ(wb[:, 1:], wb[:, :-1], valid[:, 1:], valid[:, :-1]).sum()
            self.assertEqual(r["boundary"]["row_pairs"], int(row_pairs), spec)

    def test_1d_result_is_refused(self):
        r = analyse(self.results["line"])
        self.assertEqual(r.returncode, 2)
        self.assertIn("1-D", r.stderr)


if __name__ == "__main__":
    superball_testing_main()
