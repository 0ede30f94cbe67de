#!/usr/bin/python3
"""End-to-end tests of `superball explore` under mpirun: results identical for every
rank count and tile size and to `superball count` per point, the SPEC.md section 5
layout read back with h5py, resume after SIGKILL, and refusal of bad jobs."""
import json
import os
import random
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import unittest
import xml.etree.ElementTree as ET

import h5py
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from superball_testing import main as superball_testing_main  # noqa: E402
from superball_testing import (ExploreCase, descendants, killable_job, mpi_env, running_journal,  # noqa: E402
                               wall_impacts_per_second)

SUPERBALL = os.environ.get("SUPERBALL", "superball")
MPIEXEC = os.environ.get("MPIEXEC") or "mpirun"


def text(value):
    """An HDF5 text attribute as str (h5py gives fixed-length ones as bytes)."""
    return value.decode("ascii") if isinstance(value, bytes) else str(value)


def job_text(grid, model="e = 0.9\nalpha = 0.9", run="max_bounces = 1000"):
    return f"[model]\n{model}\n\n[grid]\n{grid}\n\n[run]\n{run}\n"


CANONICAL_2D = 'xi = { min = 0.0, max = 1.0, n = 61 }\nU = -1.0\nW = { min = -3.0, max = 3.0, n = 47 }'


class Explore(ExploreCase):
    prefix = "superball-explore-"

    @staticmethod
    def datasets(path):
        with h5py.File(path, "r") as f:
            return f["wall_bounces"][()], f["outcome"][()]

    def assert_same_results(self, a, b):
        wa, oa = self.datasets(a)
        wb, ob = self.datasets(b)
        np.testing.assert_array_equal(wa, wb)
        np.testing.assert_array_equal(oa, ob)

    def test_identical_for_rank_counts_and_tile_sizes(self):
        outputs = []
        for ranks, tile in [(1, 64), (2, 64), (3, 64), (4, 64), (2, 7), (3, 1000), (1, 100000)]:
            job = self.write_job(job_text(CANONICAL_2D, run=f"max_bounces = 1000\ntile_points = {tile}"),
                                 f"job-{ranks}-{tile}.toml")
            out = self.path(f"r{ranks}-t{tile}.h5")
            self.explore(job, out, ranks)
            outputs.append(out)
            with h5py.File(out, "r") as f:
                self.assertEqual(f.attrs["complete"], 1)
                self.assertEqual(f.attrs["superball_file"], "result")
                self.assertEqual(f.attrs["mpi_ranks"], ranks)
                self.assertNotIn("progress", f)  # the journal stays with the partial file
            self.assertFalse(os.path.exists(out + ".partial"))
        for out in outputs[1:]:
            self.assert_same_results(outputs[0], out)

    def test_equals_count_per_point(self):
        """Every grid point equals `superball count` at the same coordinates (sampled)."""
        job = self.write_job(job_text(CANONICAL_2D, model="e_wall = 0.8\nalpha_wall = 0.6\ne_floor = 0.85\nalpha_floor = 0.7"))
        out = self.path("r.h5")
        self.explore(job, out, 2)
        wb, oc = self.datasets(out)
        names = ["invalid", "left", "missed", "capped"]
        rng = random.Random(7)
        with h5py.File(out, "r") as f:
            xi, W = f["xi"][()], f["W"][()]
        for _ in range(60):
            i, k = rng.randrange(len(xi)), rng.randrange(len(W))
            r = subprocess.run([SUPERBALL, "count", "--json", "--e-wall", "0.8", "--alpha-wall", "0.6", "--e-floor", "0.85",
                                "--alpha-floor", "0.7", "--xi", repr(float(xi[i])), "--U", "-1", "--W", repr(float(W[k]))],
                               capture_output=True, text=True, check=True)
            got = json.loads(r.stdout)
            self.assertEqual((got["wall_bounces"], got["outcome"]), (int(wb[i, k]), names[oc[i, k]]), (xi[i], W[k]))

    def test_layout(self):
        """SPEC.md section 5 as issue 13 amends it: netCDF-4/CF conventions, compressed."""
        job = self.write_job(job_text(CANONICAL_2D))
        out = self.path("r.h5")
        self.explore(job, out, 2)
        with h5py.File(out, "r") as f:
            counts, outcome = f["wall_bounces"], f["outcome"]
            self.assertEqual(counts.dtype, np.uint16)
            self.assertEqual(outcome.dtype, np.uint8)
            self.assertEqual(counts.shape, (61, 47))
            self.assertEqual(outcome.shape, (61, 47))
            self.assertEqual((counts.compression, counts.shuffle), ("gzip", True))
            self.assertEqual((outcome.compression, outcome.shuffle), ("gzip", True))
            # Coordinate variables at the root, attached as dimension scales.
            self.assertEqual(sorted(f), ["U", "W", "outcome", "wall_bounces", "xi"])
            for d in (counts, outcome):
                self.assertEqual([dim[0].name for dim in d.dims], ["/xi", "/W"])
                self.assertEqual(text(d.attrs["coordinates"]), "U")
            self.assertTrue(h5py.h5ds.is_scale(f["xi"].id))
            # Cell centres, computed as SPEC.md section 4 says.
            expect = np.array([0.0 + (i + 0.5) * (1.0 - 0.0) / 61 for i in range(61)])
            np.testing.assert_array_equal(f["xi"][()], expect)
            self.assertEqual(f["W"].dtype, np.float64)
            self.assertEqual(f["U"][()], -1.0)
            for name in ("xi", "U", "W"):
                self.assertEqual(text(f[name].attrs["units"]), "1")
                self.assertIn(name, text(f[name].attrs["long_name"]))
            self.assertEqual(text(counts.attrs["units"]), "1")
            self.assertTrue(text(counts.attrs["long_name"]))
            self.assertEqual(list(outcome.attrs["flag_values"]), [0, 1, 2, 3])
            self.assertEqual(outcome.attrs["flag_values"].dtype, np.uint8)
            self.assertEqual(text(outcome.attrs["flag_meanings"]), "invalid left missed capped")
            # netCDF text (fixed-length ASCII), not NC_STRING, which some netCDF tools drop.
            self.assertFalse(h5py.check_string_dtype(outcome.attrs.get_id("flag_meanings").dtype).length is None)
            a = f.attrs
            self.assertEqual(text(a["Conventions"]), "CF-1.8")
            self.assertEqual(a["coordinate_system"], "canonical")
            self.assertNotIn("coordinates", a)  # CF's keyword for auxiliary coordinates: xarray would take it
            self.assertEqual(list(a["axis_names"]), ["xi", "W"])
            for key in ["e_wall", "alpha_wall", "e_floor", "alpha_floor"]:
                self.assertEqual(a[key], 0.9)
            self.assertEqual(a["fixed_U"], -1.0)
            self.assertEqual(a["max_bounces"], 1000)
            self.assertIn("[grid]", a["job_toml"])
            self.assertEqual(a["mpi_ranks"], 2)
            self.assertGreater(a["wall_seconds"], 0)
            self.assertEqual(a["complete"], 1)
            self.assertTrue(a["software_version"])
            self.assertNotIn("g", a)  # canonical grids have no g/radius
            outcomes = set(np.unique(outcome[()]))
            self.assertTrue(outcomes <= {1, 2, 3})
        # The sidecar: a 3-D mesh one sample thick at U = -1.
        xmf = ET.parse(self.path("r.xmf")).getroot()
        topology = xmf.find(".//Topology")
        self.assertEqual(topology.get("TopologyType"), "3DRectMesh")
        self.assertEqual(topology.get("Dimensions"), "61 1 47")
        h5dump = shutil.which("h5dump")
        if h5dump:
            r = subprocess.run([h5dump, "-H", out], capture_output=True, text=True)
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertIn('DATASET "wall_bounces"', r.stdout)

    def test_large_grids_get_large_chunks(self):
        """The result's chunks are the run's tiles: on large grids, by default, of at least
        256 KiB of counts (for readers and the compressor)."""
        job = self.write_job(job_text('xi = { min = 0.0, max = 1.0, n = 2048 }\nU = -1.0\nW = { min = -3.0, max = 3.0, n = 2048 }'))
        out = self.path("big.h5")
        self.explore(job, out, 2)
        with h5py.File(out, "r") as f:
            chunks = f["wall_bounces"].chunks
            self.assertGreaterEqual(np.prod(chunks) * 2, 256 * 1024, chunks)
        self.assertLess(os.path.getsize(out), 0.02 * 2048 * 2048 * 3)
        # Tiles set by the job are the chunks too.
        small = self.write_job(job_text('xi = { min = 0.0, max = 1.0, n = 256 }\nU = -1.0\nW = { min = -3.0, max = 3.0, n = 192 }',
                                        run="max_bounces = 1000\ntile_points = 1024"), "small.toml")
        self.explore(small, self.path("small.h5"), 2)
        with h5py.File(self.path("small.h5"), "r") as f:
            self.assertTrue(512 < np.prod(f["wall_bounces"].chunks) <= 1024, f["wall_bounces"].chunks)

    def test_ten_billion_points_are_not_filled(self):
        """Creating the file of a 10^10-point job writes none of its data: compressed (the
        default), nothing is allocated for them until tiles are done (the file holds the
        metadata and the journal, 33 bytes a tile); uncompressed, 30 GB of chunks are
        allocated but not written. Reading it reads the tiles done, not 30 GB of nothing."""
        grid = 'xi = { min = 0.0, max = 1.0, n = 100000 }\nU = -1.0\nW = { min = -3.0, max = 3.0, n = 100000 }'
        for compression in (4, 0):
            with self.subTest(compression=compression):
                job = self.write_job(job_text(grid, run=f"max_bounces = 1000\ncompression = {compression}"),
                                     f"huge{compression}.toml")
                out = self.path(f"huge{compression}.h5")
                start = time.time()
                r = self.explore(job, out, 1, ["--stop-after", "0"], expect=1)
                self.assertIn("--resume", r.stderr)
                st = os.stat(out + ".partial")
                if compression:
                    self.assertLess(st.st_size, 64 * 2**20, st)
                else:
                    self.assertGreaterEqual(st.st_size, 3 * 10**10)        # every chunk allocated...
                self.assertLess(st.st_blocks * 512, 64 * 2**20, st)     # ...and none written
                self.assertLess(time.time() - start, 60)
                info = subprocess.run([SUPERBALL, "info", out], capture_output=True, text=True, timeout=30)
                self.assertEqual(info.returncode, 0, info.stderr)
                self.assertRegex(info.stdout, r"complete: +no \(0 of \d+ tiles done\)")

    def test_provenance(self):
        """history (UTC time, the command line, the software, ranks and hosts), source with the
        commit, date_created and build are in the result; superball info prints them."""
        job = self.write_job(job_text(CANONICAL_2D), "prov.toml")
        out = self.path("prov.h5")
        self.explore(job, out, 2)
        with h5py.File(out, "r") as f:
            attrs = {k: (v.decode() if isinstance(v, bytes) else v) for k, v in f.attrs.items()}
        self.assertRegex(attrs["date_created"], r"^\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ$")
        self.assertRegex(attrs["source"], r"^superball \d+\.\d+\.\d+ \(git ([0-9a-f]{12}|unknown)(, dirty)?\)$")
        self.assertIn("(kernels: ", attrs["build"])
        self.assertIn("; counting kernel ", attrs["build"])
        history = attrs["history"]
        self.assertEqual(history.count("\n"), 0, history)  # one run, one line
        self.assertTrue(history.startswith(attrs["date_created"] + " "), history)
        self.assertIn(f"superball explore {job} -o {out}", history)
        self.assertIn(attrs["source"] + "; 2 MPI ranks on 1 host, 1 thread each; kernel ", history)
        self.assertEqual((attrs["mpi_ranks"], attrs["mpi_hosts"], attrs["threads"]), (2, 1, 1))
        info = subprocess.run([SUPERBALL, "info", out], capture_output=True, text=True, timeout=30)
        self.assertEqual(info.returncode, 0, info.stderr)
        self.assertIn("source:      " + attrs["source"], info.stdout)
        self.assertIn("created:     " + attrs["date_created"], info.stdout)
        self.assertIn("build:       " + attrs["build"], info.stdout)
        self.assertIn("history:\n  " + history + "\n", info.stdout)

    def test_uncompressed(self):
        job = self.write_job(job_text(CANONICAL_2D, run="max_bounces = 1000\ncompression = 0"))
        out = self.path("raw.h5")
        self.explore(job, out, 2)
        with h5py.File(out, "r") as f:
            self.assertIsNone(f["wall_bounces"].compression)
        reference = self.path("compressed.h5")
        self.explore(self.write_job(job_text(CANONICAL_2D), "c.toml"), reference, 1)
        self.assert_same_results(out, reference)

    def test_three_dimensional_grid(self):
        grid = ('xi = { min = 0.0, max = 1.0, n = 13 }\nU = { min = -2.0, max = -0.1, n = 9 }\n'
                'W = { min = -3.0, max = 3.0, n = 11 }')
        job = self.write_job(job_text(grid, run="max_bounces = 1000\ntile_points = 50"))
        one, three = self.path("one.h5"), self.path("three.h5")
        self.explore(job, one, 1)
        self.explore(job, three, 3)
        self.assert_same_results(one, three)
        with h5py.File(one, "r") as f:
            self.assertEqual(f["wall_bounces"].shape, (13, 9, 11))
            self.assertEqual(list(f.attrs["axis_names"]), ["xi", "U", "W"])
        self.assertEqual(ET.parse(self.path("one.xmf")).getroot().find(".//Topology").get("TopologyType"), "3DRectMesh")

    def test_physical_grid(self):
        grid = ('coordinates = "physical"\nx = { min = 0.0, max = 0.2, n = 30 }\nu = { min = -3.0, max = 1.0, n = 20 }\n'
                'v = 2.0\nomega = -200.0')
        job = self.write_job(job_text(grid, model="e = 0.9\nalpha = 0.9\ng = 9.81\nradius = 0.025"))
        out = self.path("phys.h5")
        self.explore(job, out, 2)
        with h5py.File(out, "r") as f:
            wb, oc = f["wall_bounces"][()], f["outcome"][()]
            u = f["u"][()]
            self.assertEqual(f.attrs["coordinate_system"], "physical")
            self.assertEqual([text(f[n].attrs["units"]) for n in ("x", "u", "v", "omega")], ["m", "m/s", "m/s", "rad/s"])
            self.assertEqual(f.attrs["g"], 9.81)
            self.assertEqual(f.attrs["radius"], 0.025)
            self.assertEqual(f.attrs["fixed_v"], 2.0)
            self.assertEqual(f.attrs["fixed_omega"], -200.0)
        # u >= 0 is not a launch toward the wall: invalid, zero bounces.
        self.assertTrue((oc[:, u >= 0] == 0).all())
        self.assertTrue((wb[:, u >= 0] == 0).all())
        self.assertTrue((oc[:, u < 0] != 0).all())
        # The reference launch x = 0.02, u = -2, v = 2, omega = -200 gives 12 bounces, left;
        # spot-check a grid point against `superball count` with the physical flags.
        i, k = 3, int(np.argmin(abs(u + 2)))
        with h5py.File(out, "r") as f:
            x = f["x"][i]
        r = subprocess.run([SUPERBALL, "count", "--json", "--e", "0.9", "--alpha", "0.9", "--x", repr(float(x)), "--u",
                            repr(float(u[k])), "--v", "2", "--omega", "-200"], capture_output=True, text=True, check=True)
        self.assertEqual(json.loads(r.stdout)["wall_bounces"], int(wb[i, k]))

    def test_one_axis_grid_and_wide_counts(self):
        job = self.write_job(job_text('xi = { min = 0.0, max = 1.0, n = 100 }\nU = -1.0\nW = -2.0',
                                      model="e = 1.0\nalpha = 1.0", run="max_bounces = 70000"))
        out = self.path("line.h5")
        self.explore(job, out, 2)
        with h5py.File(out, "r") as f:
            self.assertEqual(f["wall_bounces"].shape, (100,))
            self.assertEqual(f["wall_bounces"].dtype, np.uint32)  # max_bounces > 65535
        # A line: the mesh is 3-D, one sample thick along U and W.
        topology = ET.parse(self.path("line.xmf")).getroot().find(".//Topology")
        self.assertEqual(topology.get("Dimensions"), "100 1 1")

    def test_swept_coefficient(self):
        """alpha as a range axis (before the coordinates): each slice equals a run at that
        alpha, and the layout says which axis sets which coefficient."""
        grid = 'xi = { min = 0.0, max = 1.0, n = 40 }\nU = -1.0\nW = { min = -3.0, max = 3.0, n = 30 }'
        job = self.write_job(job_text(grid, model="e = 0.9\nalpha = { min = 0.5, max = 1.0, n = 5 }\ne_floor = 0.8"))
        out = self.path("sweep.h5")
        self.explore(job, out, 3)
        with h5py.File(out, "r") as f:
            self.assertEqual(f["wall_bounces"].shape, (5, 40, 30))
            self.assertEqual(list(f.attrs["axis_names"]), ["alpha", "xi", "W"])
            self.assertEqual(list(f.attrs["swept"]), ["alpha"])
            self.assertEqual(f.attrs["alpha_wall"], "axis:alpha")
            self.assertEqual(f.attrs["alpha_floor"], "axis:alpha")
            self.assertEqual(f.attrs["e_wall"], 0.9)
            self.assertEqual(f.attrs["e_floor"], 0.8)
            alphas = f["alpha"][()]
            self.assertEqual([dim[0].name for dim in f["wall_bounces"].dims], ["/alpha", "/xi", "/W"])
            wb, oc = f["wall_bounces"][()], f["outcome"][()]
        np.testing.assert_array_equal(alphas, [0.5 + (i + 0.5) * 0.5 / 5 for i in range(5)])
        # The sweep plots: a 2-D slice at one alpha.
        png = self.path("sweep.png")
        r = subprocess.run([sys.executable, os.path.join(os.path.dirname(__file__), "..", "..", "analysis", "region_map.py"),
                            out, "--slice", "alpha=2", "-o", png], capture_output=True, text=True)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertGreater(os.path.getsize(png), 10000)
        for i, alpha in enumerate(alphas):
            single = self.write_job(job_text(grid, model=f"e = 0.9\nalpha = {alpha!r}\ne_floor = 0.8"), f"a{i}.toml")
            self.explore(single, self.path(f"a{i}.h5"), 1)
            w1, o1 = self.datasets(self.path(f"a{i}.h5"))
            np.testing.assert_array_equal(wb[i], w1)
            np.testing.assert_array_equal(oc[i], o1)
        # Only coefficients as axes: e x alpha at one start point.
        job = self.write_job(job_text("xi = 0.05\nU = -1.0\nW = -2.0",
                                      model="e = { min = 0.5, max = 1.0, n = 7 }\nalpha = { min = 0.0, max = 1.0, n = 9 }"),
                             "ea.toml")
        self.explore(job, self.path("ea.h5"), 2)
        with h5py.File(self.path("ea.h5"), "r") as f:
            e, a, w = f["e"][()], f["alpha"][()], f["wall_bounces"][()]
        for i, k in [(0, 0), (3, 8), (6, 4)]:
            r = subprocess.run([SUPERBALL, "count", "--json", "--e", repr(float(e[i])), "--alpha", repr(float(a[k])),
                                "--xi", "0.05", "--U", "-1", "--W", "-2"], capture_output=True, text=True, check=True)
            self.assertEqual(json.loads(r.stdout)["wall_bounces"], int(w[i, k]))

    def test_boundary_plane(self):
        """A fixed xi of exactly 0 is the plane xi -> 0+: counted as the limit (no invalid
        points), like launches a hair from the wall; the swept alpha slice plots."""
        grid = 'xi = 0.0\nU = { min = -3.0, max = -0.01, n = 30 }\nW = { min = -6.0, max = 3.0, n = 40 }'
        near = grid.replace("xi = 0.0", "xi = 1e-13")
        self.explore(self.write_job(job_text(grid), "plane.toml"), self.path("plane.h5"), 2)
        self.explore(self.write_job(job_text(near), "near.toml"), self.path("near.h5"), 2)
        wp, op = self.datasets(self.path("plane.h5"))
        wn, on = self.datasets(self.path("near.h5"))
        self.assertTrue((op != 0).all())
        self.assertGreater(((wp == wn) & (op == on)).mean(), 0.97)
        self.assertGreater(wp.max(), 10)

    def test_refine(self):
        """Adaptive refinement: the same file for any rank count, close to the full
        computation, exact where the grid is uniform, and recorded in the file."""
        grid = 'xi = { min = 0.0, max = 1.0, n = 150 }\nU = -1.0\nW = { min = -3.0, max = 3.0, n = 130 }'
        full_job = self.write_job(job_text(grid), "full.toml")
        refined_job = self.write_job(job_text(grid, run="max_bounces = 1000\nrefine = 8"), "refined.toml")
        full, one, three = self.path("full.h5"), self.path("one.h5"), self.path("three.h5")
        self.explore(full_job, full, 1)
        r = self.explore(refined_job, one, 1)
        self.assertRegex(r.stderr, r"refinement: \d+ of 19500 points counted")
        counted = int(r.stderr.split("refinement: ")[1].split()[0])
        self.assertLess(counted, 19500 // 2)
        self.explore(refined_job, three, 3)
        self.assert_same_results(one, three)
        wf, of = self.datasets(full)
        wr, orr = self.datasets(one)
        mismatch = ((wf != wr) | (of != orr)).mean()
        self.assertLess(mismatch, 0.01)
        # W > -0.8 is all one bounce, left: refinement must reproduce it exactly.
        with h5py.File(full, "r") as f:
            calm = f["W"][()] > -0.8
            self.assertEqual(f.attrs["refine"], 0)
        np.testing.assert_array_equal(wr[:, calm], wf[:, calm])
        with h5py.File(one, "r") as f:
            self.assertEqual(f.attrs["refine"], 8)
        r = self.explore(refined_job, full, 1, ["--resume"], expect=2)  # a full result is another job
        self.assertIn("different job", r.stderr)

    def test_refuses_to_overwrite(self):
        job = self.write_job(job_text(CANONICAL_2D))
        out = self.path("r.h5")
        self.explore(job, out, 1)
        with open(out, "rb") as f:
            before = f.read()
        r = self.explore(job, out, 1, expect=2)
        self.assertIn("--overwrite", r.stderr)
        with open(out, "rb") as f:
            self.assertEqual(f.read(), before)
        self.explore(job, out, 1, ["--overwrite"])
        r = self.explore(job, out, 1, ["--resume"])  # complete: nothing to do
        other = self.write_job(job_text(CANONICAL_2D.replace("n = 47", "n = 48")), "other.toml")
        r = self.explore(other, out, 1, ["--resume"], expect=2)
        self.assertIn("different job", r.stderr)

    def test_resume_after_sigkill(self):
        """A run killed with SIGKILL mid-way, then --resume, equals an uninterrupted run; the
        interrupted run never sits under the result's name."""
        # Sized by the speed of the binary under test (a release build or a sanitized
        # one) to last about 2.5 s on two ranks, long enough to be killed part-way.
        job = self.write_job(killable_job(wall_impacts_per_second(SUPERBALL, self.dir), 2.5))
        out = self.path("killed.h5")
        partial = out + ".partial"
        proc = subprocess.Popen([MPIEXEC, "-n", "2", "--oversubscribe", SUPERBALL, "explore", job, "-o", out, "-q"],
                                env=mpi_env(), start_new_session=True, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        done, total = 0, 1
        deadline = time.time() + 120
        while time.time() < deadline and proc.poll() is None:
            time.sleep(0.02)
            journal = running_journal(partial)
            if journal is None:
                continue
            done, total = int(journal.sum()), journal.size
            if done >= total // 5:
                break
        self.assertIsNone(proc.poll(), "the run finished before it could be killed: make the grid larger")
        for pid in descendants(proc.pid) + [proc.pid]:
            try:
                os.kill(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
        proc.wait()
        proc.stderr.close()
        self.assertGreater(done, 0)
        self.assertFalse(os.path.exists(out))
        self.assertFalse(os.path.exists(self.path("killed.xmf")))
        with h5py.File(partial, "r") as f:
            self.assertEqual(f.attrs["complete"], 0)
            self.assertEqual(f.attrs["superball_file"], "partial")
            marked = int(f["progress/tile_done"][()].sum())
            self.assertLess(marked, f["progress/tile_done"].size)
        r = self.explore(job, out, 1, expect=2)  # an interrupted run is not overwritten either
        self.assertIn("--resume", r.stderr)
        self.explore(job, out, 2, ["--resume"])
        self.assertFalse(os.path.exists(partial))
        reference = self.path("straight.h5")
        self.explore(job, reference, 2)
        self.assert_same_results(out, reference)
        with h5py.File(out, "r") as f:
            self.assertEqual(f.attrs["complete"], 1)


class BadJobs(unittest.TestCase):
    """Each class of job-file error: exit status 2, a message naming the key, no file."""

    CASES = [
        ("unknown key", job_text(CANONICAL_2D + "\nxii = 1.0"), "xii"),
        ("missing coordinate", job_text('xi = { min = 0.0, max = 1.0, n = 4 }\nU = -1.0'), "W"),
        ("wrong type", job_text(CANONICAL_2D.replace("U = -1.0", 'U = "minus one"')), "U"),
        ("nan", job_text(CANONICAL_2D.replace("U = -1.0", "U = nan")), "U"),
        ("min >= max", job_text(CANONICAL_2D.replace("max = 1.0", "max = 0.0")), "xi"),
        ("n < 1", job_text(CANONICAL_2D.replace("n = 61", "n = 0")), "xi"),
        ("e out of range", job_text(CANONICAL_2D, model="e = 1.5\nalpha = 0.9"), "e"),
        ("alpha out of range", job_text(CANONICAL_2D, model="e = 0.9\nalpha = -2"), "alpha"),
        ("syntax", "[model\ne = 0.9", "bad.toml:1:"),
    ]

    def test_bad_jobs(self):
        d = tempfile.mkdtemp(prefix="superball-badjob-")
        try:
            for what, text, key in self.CASES:
                with self.subTest(what):
                    job = os.path.join(d, "bad.toml")
                    with open(job, "w") as f:
                        f.write(text)
                    out = os.path.join(d, "out.h5")
                    r = subprocess.run([SUPERBALL, "explore", job, "-o", out], capture_output=True, text=True,
                                       env=mpi_env(), timeout=60)
                    self.assertEqual(r.returncode, 2, r.stderr)
                    self.assertIn(key, r.stderr)
                    self.assertFalse(os.path.exists(out))
            # Under mpirun with several ranks: still status 2, and one message, not one per rank.
            r = subprocess.run([MPIEXEC, "-n", "3", "--oversubscribe", SUPERBALL, "explore", job, "-o", out],
                               capture_output=True, text=True, env=mpi_env(), timeout=60)
            self.assertEqual(r.returncode, 2, r.stderr)
            self.assertEqual(r.stderr.count("superball explore:"), 1, r.stderr)
            r = subprocess.run([SUPERBALL, "explore", os.path.join(d, "missing.toml")], capture_output=True, text=True,
                               env=mpi_env())
            self.assertEqual(r.returncode, 2)
            self.assertIn("missing.toml", r.stderr)
        finally:
            shutil.rmtree(d, ignore_errors=True)


if __name__ == "__main__":
    superball_testing_main()
