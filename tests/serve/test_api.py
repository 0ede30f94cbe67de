#!/usr/bin/env python3
"""Tests of `superball serve`'s JSON API and tiles, each against the command line on the same
input: /api/count against `superball count --json`, /api/trajectory against `superball
trajectory --format json`, /api/region against `superball explore` of the job /api/job
exports for the same grid (read with h5py), tiles against /api/region; layers from a result
and a partial file; every kind of bad request (status, message, the command line's wording
for the same mistake, and the server still serving); a slow request bounded by the time
limit without stalling the others; an abandoned request dropped; and 16 concurrent clients.

Run by ctest with SUPERBALL set to the binary (label serve).
"""

import concurrent.futures
import io
import json
import os
import random
import re
import socket
import subprocess
import sys
import tempfile
import threading
import time
import unittest
import urllib.error
import urllib.parse
import urllib.request

import h5py
import numpy as np
from PIL import Image

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from superball_testing import main as superball_testing_main  # noqa: E402
from superball_testing import Server, interrupted_run, mpi_env, read_partial, superball_binary  # noqa: E402

BINARY = superball_binary()
QUICKSTART = dict(x="xi", x_min=0, x_max=1, y="W", y_min=-3, y_max=3, U=-1, e=0.9, alpha=0.9, max_bounces=1000)
# analysis/region_map.py's outcome colours: invalid, left, missed, capped.
OUTCOME_RGB = np.array([(153, 153, 153), (31, 119, 180), (255, 127, 14), (0, 0, 0)], dtype=np.uint8)
# A launch that bounces for ever without dissipation (superball_testing.capped_job).
CAPPED = dict(x="xi", x_min=0.24, x_max=0.26, y="W", y_min=-1.27, y_max=-1.23, U=-0.5, e=1, alpha=1)
# Under AddressSanitizer (tests/all's asan stage) counting is several times slower and
# freed memory is held in quarantine: latencies are allowed this factor, memory not checked.
SANITIZED = "ASAN_OPTIONS" in os.environ
SLOWER = 10 if SANITIZED else 1


def query(**params):
    return urllib.parse.urlencode(params)


def run(*args, **kwargs):
    return subprocess.run([BINARY, *args], capture_output=True, text=True, env=mpi_env(), timeout=300, **kwargs)


def cli_message(stderr):
    """The command line's message with its flags spelt as the API's keys (--alpha-wall -> alpha_wall)."""
    message = stderr.strip().split(": ", 1)[1]
    return re.sub(r"--([A-Za-z][\w-]*)", lambda m: m.group(1).replace("-", "_"), message)


def region_from_file(path, x, y):
    """wall_bounces and outcome of a 2-D result as rows along y, and the samples of x and y."""
    with h5py.File(path, "r") as f:
        counts, outcomes = f["wall_bounces"][()], f["outcome"][()]
        first = [a for a in ("xi", "U", "W") if a in (x, y)][0]
        if first == x:  # dimensions (x, y): rows along x
            counts, outcomes = counts.T, outcomes.T
        return counts, outcomes, f[x][()], f[y][()]


class ApiTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.server = Server("--threads", "2")

    @classmethod
    def tearDownClass(cls):
        code, stderr = cls.server.stop()
        cls.tmp.cleanup()
        assert code == 0, f"superball serve exited with {code}: {stderr}"

    def path(self, name):
        return os.path.join(self.tmp.name, name)

    def test_count_equals_the_command_line(self):
        cases = [
            dict(xi=0.05, U=-1, W=-2, e=0.9, alpha=0.9),
            dict(xi=0.0123456789, U=-0.7, W=-2.5, e_wall=0.8, alpha_wall=0.95, e_floor=0.9, alpha_floor=0.7),
            dict(xi=0.25, U=-0.5, W=-1.25, e=1, alpha=1, max_bounces=777),
            dict(xi=1.5, U=-1, W=0, e=0.9, alpha=0.9),
            dict(x=0.02, u=-2, v=2, omega=-200, e=0.9, alpha=0.9),
            dict(x=0.3, u=-1, v=3, omega=10, g=1.62, radius=0.1, e=0.5, alpha=-0.3),
        ]
        for params in cases:
            with self.subTest(**params):
                status, api = self.server.json("/api/count?" + query(**params))
                self.assertEqual(status, 200, api)
                flags = [a for k, v in params.items() for a in ("--" + k.replace("_", "-"), str(v))]
                r = run("count", *flags, "--json")
                self.assertEqual(r.returncode, 0, r.stderr)
                self.assertEqual(api, json.loads(r.stdout))

    def test_trajectory_equals_the_command_line(self):
        cases = [
            dict(xi=0.05, U=-1, W=-2, e=0.9, alpha=0.9, samples=5),
            dict(x=0.02, u=-2, v=2, omega=-200, e=0.9, alpha=0.9),
            dict(xi=0.01, U=-1.1, W=-2.6, e=0.9, alpha=0.99, max_bounces=300, samples=3),
        ]
        for params in cases:
            with self.subTest(**params):
                status, _, body = self.server.get("/api/trajectory?" + query(**params))
                self.assertEqual(status, 200, body)
                flags = [a for k, v in params.items() for a in ("--" + k.replace("_", "-"), str(v))]
                r = run("trajectory", *flags, "--format", "json")
                self.assertEqual(r.returncode, 0, r.stderr)
                self.assertEqual(body.decode(), r.stdout)  # one writer for both
                self.assertGreater(len(json.loads(body)["events"]), 1)

    def test_region_equals_explore_of_the_exported_job(self):
        planes = [
            dict(QUICKSTART, nx=23, ny=17),
            # Transposed: W across, xi up (the result's dimensions are xi, W).
            dict(x="W", x_min=-3, x_max=3, nx=19, y="xi", y_min=0, y_max=0.5, ny=11, U=-1.5, e_wall=0.8,
                 alpha_wall=0.95, e_floor=0.9, alpha_floor=0.7, max_bounces=500),
            dict(x="U", x_min=-3, x_max=-0.2, nx=13, y="W", y_min=-3, y_max=3, ny=21, xi=0.1, e=0.9, alpha=0.99,
                 max_bounces=50),
            dict(x="xi", x_min=0, x_max=1, nx=16, y="U", y_min=-2, y_max=-0.1, ny=9, W=-1, e=0.7, alpha=0.5),
            # The boundary plane xi = 0 is counted as a limit (count_on_plane), as explore does.
            dict(x="W", x_min=-4, x_max=0, nx=14, y="U", y_min=-2, y_max=-0.5, ny=10, xi=0, e=0.9, alpha=0.99),
        ]
        for k, params in enumerate(planes):
            with self.subTest(plane=k):
                out = self.path(f"plane{k}.h5")
                status, _, job = self.server.get("/api/job?" + query(**params, output=out))
                self.assertEqual(status, 200, job)
                # Provenance of the export: the server, the request, the software.
                text = job.decode()
                self.assertRegex(text, r"(?m)^# history: \d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ .*superball.* serve.*\(GET /api/job\?")
                self.assertRegex(text, r"(?m)^# source: superball \d+\.\d+\.\d+ \(git ")
                self.assertRegex(text, r"(?m)^# build: ")
                job_path = self.path(f"plane{k}.toml")
                with open(job_path, "wb") as f:
                    f.write(job)
                r = run("explore", job_path, "--dry-run")
                self.assertEqual(r.returncode, 0, r.stderr)
                r = run("explore", job_path, "-q")
                self.assertEqual(r.returncode, 0, r.stderr)
                status, region = self.server.json("/api/region?" + query(**params))
                self.assertEqual(status, 200, region)
                counts, outcomes, xs, ys = region_from_file(out, params["x"], params["y"])
                self.assertEqual(region["x"], list(xs))  # the same doubles: Range::sample
                self.assertEqual(region["y"], list(ys))
                self.assertEqual(np.array(region["wall_bounces"]).shape, (params["ny"], params["nx"]))
                np.testing.assert_array_equal(np.array(region["wall_bounces"]), counts)
                np.testing.assert_array_equal(np.array(region["outcome"]), outcomes)
                self.assertEqual(region["outcome_names"], ["invalid", "left", "missed", "capped"])

    def tile(self, z, tx, ty, **params):
        status, headers, body = self.server.get(f"/tile/{z}/{tx}/{ty}.png?" + query(**params))
        self.assertEqual(status, 200, body)
        self.assertEqual(headers["Content-Type"], "image/png")
        return np.array(Image.open(io.BytesIO(body)).convert("RGBA"))

    def test_tiles_show_the_region_of_their_part_of_the_window(self):
        # Tile (2, 1, 2) is the part x in [0.25, 0.5], y in [-1.5, 0] of the window (y rows go down).
        for z, tx, ty, window in [(0, 0, 0, (0, 1, -3, 3)), (2, 1, 2, (0.25, 0.5, -1.5, 0))]:
            with self.subTest(z=z):
                rgba = self.tile(z, tx, ty, **QUICKSTART, show="outcome")
                x0, x1, y0, y1 = window
                params = dict(QUICKSTART, x_min=x0, x_max=x1, y_min=y0, y_max=y1, nx=256, ny=256)
                status, region = self.server.json("/api/region?" + query(**params))
                self.assertEqual(status, 200, region)
                outcomes = np.array(region["outcome"])[::-1]  # first image row: the top, y_max
                np.testing.assert_array_equal(rgba[:, :, :3], OUTCOME_RGB[outcomes])
                self.assertTrue((rgba[:, :, 3] == 255).all())
                self.assertGreater(len(np.unique(outcomes)), 1)
        # Counts: one colour per count, invalid grey and capped black.
        rgba = self.tile(0, 0, 0, x="xi", x_min=-0.5, x_max=1.5, y="W", y_min=-3, y_max=3, U=-1, e=1, alpha=1,
                         max_bounces=30, colours="viridis", colour_max=12)
        params = dict(x="xi", x_min=-0.5, x_max=1.5, nx=256, y="W", y_min=-3, y_max=3, ny=256, U=-1, e=1, alpha=1,
                      max_bounces=30)
        region = self.server.json("/api/region?" + query(**params))[1]
        counts, outcomes = np.array(region["wall_bounces"])[::-1], np.array(region["outcome"])[::-1]
        colours = {}
        for n, o, c in zip(counts.ravel(), outcomes.ravel(), rgba[:, :, :3].reshape(-1, 3)):
            key = "invalid" if o == 0 else "capped" if o == 3 else min(n, 12)
            colours.setdefault(key, set()).add(tuple(c))
        self.assertTrue(all(len(v) == 1 for v in colours.values()), colours)
        self.assertEqual(colours["invalid"], {(153, 153, 153)})
        self.assertEqual(colours["capped"], {(0, 0, 0)})
        self.assertGreater(len(colours), 5)
        status, legend = self.server.json("/api/legend?colours=viridis&colour_max=12")
        self.assertEqual(status, 200)
        listed = {e["label"]: tuple(int(e["colour"][i:i + 2], 16) for i in (1, 3, 5)) for e in legend["entries"]}
        for key, (colour,) in colours.items():
            label = {"invalid": "invalid", "capped": "capped (N = max_bounces)", 12: "N >= 12"}.get(key, f"N = {key}")
            self.assertEqual(listed[label], colour, label)

    def test_tiles_down_to_double_precision(self):
        # Zoom 40 of the quickstart window, then a window 1e-13 wide: still distinct samples.
        rgba = self.tile(40, 2**38, 2**39 + 5, **QUICKSTART)
        self.assertEqual(rgba.shape, (256, 256, 4))
        rgba = self.tile(3, 1, 1, **dict(QUICKSTART, x_min=0.05, x_max=0.05 + 1e-13, y_min=-2, y_max=-2 + 1e-11))
        self.assertEqual(rgba.shape, (256, 256, 4))
        status, error = self.server.json("/tile/30/0/0.png?" + query(**dict(QUICKSTART, x_min=0.05, x_max=0.05 + 1e-13)))
        self.assertEqual(status, 400)
        self.assertIn("are not distinct doubles", error["error"])

    def test_layers_show_files_where_they_have_the_samples(self):
        job = self.path("layer.toml")
        with open(job, "w") as f:
            f.write("[model]\ne = 0.9\nalpha = 0.9\n\n[grid]\nxi = { min = 0.0, max = 1.0, n = 32 }\nU = -1.0\n"
                    "W = { min = -3.0, max = 3.0, n = 24 }\n\n[run]\nmax_bounces = 1000\ntile_points = 96\n")
        result = self.path("layer.h5")
        r = run("explore", job, "-o", result, "-q")
        self.assertEqual(r.returncode, 0, r.stderr)
        partial = interrupted_run(BINARY, job, self.path("half.h5"), result, lambda t: t % 2 == 0)
        # One sample of the result changed: a tile showing it took it from the file.
        with h5py.File(result, "r+") as f:
            f["outcome"][5, 7] = 2 if f["outcome"][5, 7] == 1 else 1
            changed = int(f["outcome"][5, 7])
        bogus = self.path("bogus.h5")
        with open(bogus, "w") as f:
            f.write("not a result\n")
        with Server(result, partial, "--threads", "2") as server:
            status, info = server.json("/api/info")
            self.assertEqual(status, 200)
            self.assertEqual([layer["kind"] for layer in info["layers"]], ["result", "partial"])
            first = info["layers"][0]
            self.assertEqual(first["grid"]["xi"], {"min": 0, "max": 1, "n": 32})
            self.assertEqual(first["view"], {"x": "xi", "y": "W", "fixed": "U", "value": -1})
            # A window 8 x (64/6) times the file's: one pixel per sample, the file at the bottom left.
            window = dict(QUICKSTART, x_max=8, y_max=61, show="outcome")
            for layer, path in ((0, result), (1, partial)):
                status, _, body = server.get(f"/tile/0/0/0.png?" + query(**window, layer=layer))
                self.assertEqual(status, 200, body)
                rgba = np.array(Image.open(io.BytesIO(body)).convert("RGBA"))
                with h5py.File(path, "r") as f:
                    outcomes = f["outcome"][()]  # (xi, W)
                    tile_shape = [int(n) for n in f.attrs["tile_shape"]] if layer else None
                if layer:  # a partial file's tiles done, read independently of the server
                    _, outcomes, done = read_partial(path)
                pixels = rgba[256 - 24:, :32][::-1].transpose(1, 0, 2)  # (xi, W) like the file
                if layer == 0:
                    np.testing.assert_array_equal(pixels[:, :, :3], OUTCOME_RGB[outcomes])
                    self.assertEqual(tuple(pixels[5, 7, :3]), tuple(OUTCOME_RGB[changed]))
                    self.assertTrue((pixels[:, :, 3] == 255).all())
                else:
                    per_row = -(-24 // tile_shape[1])
                    tiles = (np.arange(32)[:, None] // tile_shape[0]) * per_row + np.arange(24)[None, :] // tile_shape[1]
                    missing = done[tiles] == 0
                    self.assertTrue(missing.any() and (~missing).any())
                    np.testing.assert_array_equal(pixels[:, :, 3] == 0, missing)
                    np.testing.assert_array_equal(pixels[~missing][:, :3], OUTCOME_RGB[outcomes[~missing]])
                # Outside the file, computed: beyond xi = 1 every launch misses the wall.
                self.assertTrue((rgba[:, 40:, :3] == OUTCOME_RGB[2]).all())
            # Zoomed in beyond the file's samples (on the changed one): computed.
            status, _, body = server.get("/tile/3/1/5.png?" + query(**dict(QUICKSTART, show="outcome"), layer=0))
            self.assertEqual(status, 200, body)
            rgba = np.array(Image.open(io.BytesIO(body)).convert("RGBA"))
            params = dict(QUICKSTART, x_min=0.125, x_max=0.25, y_min=-1.5, y_max=-0.75, nx=256, ny=256)
            outcomes = np.array(server.json("/api/region?" + query(**params))[1]["outcome"])[::-1]
            np.testing.assert_array_equal(rgba[:, :, :3], OUTCOME_RGB[outcomes])
        r = subprocess.run([BINARY, "serve", bogus], capture_output=True, text=True, timeout=60)
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertIn(bogus, r.stderr)

    def test_volume_layer_shows_the_slice_holding_the_fixed_value(self):
        job = self.path("volume.toml")
        with open(job, "w") as f:
            f.write("[model]\ne = 0.9\nalpha = 0.9\n\n[grid]\nxi = { min = 0.0, max = 1.0, n = 16 }\n"
                    "U = { min = -2.0, max = -0.5, n = 5 }\nW = { min = -3.0, max = 3.0, n = 12 }\n\n"
                    "[run]\nmax_bounces = 1000\n")
        result = self.path("volume.h5")
        r = run("explore", job, "-o", result, "-q")
        self.assertEqual(r.returncode, 0, r.stderr)
        with h5py.File(result, "r") as f:
            outcomes = f["outcome"][()]  # (xi, U, W)
        with Server(result, "--threads", "2") as server:
            layer = server.json("/api/info")[1]["layers"][0]
            self.assertEqual(layer["view"], {"x": "xi", "y": "W", "fixed": "U", "value": -1.25})
            # U = -1.2 lies in the cell of the sample -1.25, [-1.4, -1.1]; one pixel per sample.
            window = dict(QUICKSTART, U=-1.2, x_max=16, y_max=125, show="outcome")
            status, _, body = server.get("/tile/0/0/0.png?" + query(**window, layer=0))
            self.assertEqual(status, 200, body)
            rgba = np.array(Image.open(io.BytesIO(body)).convert("RGBA"))
            pixels = rgba[256 - 12:, :16][::-1].transpose(1, 0, 2)  # (xi, W)
            np.testing.assert_array_equal(pixels[:, :, :3], OUTCOME_RGB[outcomes[:, 2, :]])

    def test_bad_requests(self):
        cases = [
            ("/api/count?" + query(xi=0.05, U=-1, W=-2, e=0.9, alpah=0.9), 400,
             "unknown parameter alpah (did you mean alpha?): accepted xi, U, W"),
            ("/api/count?xi=0.05&U=-1&W=-2&e=0.9&alpha=0.9&alpha=0.8", 400, "alpha is given 2 times: accepted once"),
            ("/api/count?" + query(xi=0.05, U="abc", W=-2, e=0.9, alpha=0.9), 400,
             "U = abc is not a number: accepted a decimal number"),
            ("/api/count?" + query(xi=0.05, U=-1, W=-2, e=0.9, alpha=0.9, max_bounces=0), 400,
             "max_bounces = 0 is out of range: accepted 1 to 1000000"),
            ("/api/count?" + query(xi=0.05, U=-1, W=-2, e=0.9, alpha=0.9, max_bounces=2**32), 400,
             "max_bounces = 4294967296 is out of range"),
            ("/api/count?" + query(xi=0.05, U=-1, W=-2, e=0.9, alpha=0.9, max_bounces=2.5), 400,
             "max_bounces = 2.5 is not an integer"),
            ("/api/trajectory?" + query(xi=0.05, U=-1, W=-2, e=0.9, alpha=0.9, samples=1), 400,
             "samples = 1 is out of range: accepted 0 or 2..100000"),
            ("/api/trajectory?" + query(xi=0.25, U=-0.5, W=-1.25, e=1, alpha=1, max_bounces=20000), 413,
             "the trajectory has 20000 wall impacts: accepted at most 10000"),
            ("/api/trajectory?" + query(xi=0.05, U=-1, W=-2, e=0.9, alpha=0.9, samples=100000), 413,
             "path points: accepted at most 1000000"),
            ("/api/region?" + query(**dict(QUICKSTART, nx=4, ny=3, x="V")), 400, "x = V is not accepted: accepted xi, U or W"),
            ("/api/region?" + query(**{k: v for k, v in dict(QUICKSTART, nx=4, ny=3).items() if k != "x"}), 400,
             "x is not set: accepted xi, U or W (the axis across)"),
            ("/api/region?" + query(**dict(QUICKSTART, nx=4, ny=3, y="xi")), 400,
             "x = xi and y = xi are the same axis"),
            ("/api/region?" + query(**{k: v for k, v in dict(QUICKSTART, nx=4, ny=3).items() if k != "U"}), 400,
             "U is not set: the third coordinate needs a fixed value (x = xi, y = W)"),
            ("/api/region?" + query(**dict(QUICKSTART, nx=4, ny=3, xi=0.5)), 400, "xi is given, but it is the x axis"),
            ("/api/region?" + query(**dict(QUICKSTART, nx=4, ny=3, x_min=1, x_max=0)), 400,
             "x_min = 1 and x_max = 0: accepted x_min < x_max"),
            ("/api/region?" + query(**dict(QUICKSTART, nx=4, ny=3, y_max="inf")), 400,
             "y_max = inf is not finite: accepted a finite number"),
            ("/api/region?" + query(**dict(QUICKSTART, nx=4, ny=3, U="nan")), 400, "U = nan is not finite"),
            ("/api/region?" + query(**dict(QUICKSTART, nx=4, ny=3, x_min=-1e308, x_max=1e308)), 400,
             "x_max - x_min overflows, accepted a finite width"),
            ("/api/region?" + query(**dict(QUICKSTART, nx=0, ny=3)), 400, "nx = 0 is out of range: accepted nx >= 1"),
            ("/api/region?" + query(**dict(QUICKSTART, nx=4)), 400, "ny is not set"),
            ("/api/region?" + query(**dict(QUICKSTART, nx=2048, ny=1024)), 413,
             "nx x ny = 2048 x 1024 points: accepted at most 1048576 in one request"),
            ("/api/region?" + query(**dict(QUICKSTART, nx=4, ny=3, e=0)), 400, "e = 0 is out of range: accepted 0 < e <= 1"),
            ("/api/job?" + query(**dict(QUICKSTART, nx=4, ny=3, output="")), 400, "output = \"\" is empty"),
            ("/api/job?" + query(**dict(QUICKSTART, nx=2**21, ny=2**20)), 400, "accepted at most 1099511627776 (2^40)"),
            ("/api/legend?colours=virdis", 400, "colours = virdis is not accepted (did you mean viridis?)"),
            ("/api/legend?show=counts", 400, "show = counts is not accepted (did you mean count?): accepted count or outcome"),
            ("/api/legend?colour_max=0", 400, "colour_max = 0 is out of range"),
            ("/tile/0/0/0.png?" + query(**QUICKSTART, layer=0), 400, "started with no result files"),
            ("/tile/0/0/0.png?" + query(**QUICKSTART, nx=4), 400, "unknown parameter nx"),
            ("/tile/2000/0/0.png?" + query(**QUICKSTART), 400, "z = 2000 is out of range: accepted 0 to 1100"),
            ("/api/info?verbose=1", 400, "unknown parameter verbose: accepted no parameters"),
            ("/api/nothing", 404, "no such path \"/api/nothing\": accepted / (the page), /api/count"),
            ("/tile/0/0/0.jpg", 404, "no such path"),
        ]
        for path, status, message in cases:
            with self.subTest(path=path):
                got, body = self.server.json(path)
                self.assertEqual(got, status, body)
                self.assertIn(message, body["error"])
        # POST, and a request line too long for the server.
        try:
            urllib.request.urlopen(urllib.request.Request(self.server.url + "api/count", data=b"x=1"), timeout=10)
            self.fail("POST accepted")
        except urllib.error.HTTPError as e:
            self.assertEqual(e.code, 405)
            self.assertEqual(json.loads(e.read()), {"error": "method POST is not accepted: accepted GET"})
        status, body = self.server.json("/api/count?" + "x" * 10000)
        self.assertEqual(status, 414)
        self.assertIn("the request's URL is too long: accepted at most 8192 characters", body["error"])
        # The server still serves.
        status, body = self.server.json("/api/count?" + query(xi=0.05, U=-1, W=-2, e=0.9, alpha=0.9))
        self.assertEqual((status, body["wall_bounces"]), (200, 8))

    def test_model_and_start_errors_have_the_command_lines_wording(self):
        cases = [
            dict(xi=0.05, U=-1, W=-2, e=0.9),
            dict(xi=0.05, U=-1, W=-2, e=1.5, alpha=0.9),
            dict(xi=0.05, U=-1, W=-2, e=0.9, alpha=0.9, alpha_floor=-2),
            dict(xi=0.05, U=-1, W=-2, e="nan", alpha=0.9),
            dict(xi=-0.1, U=-1, W=-2, e=0.9, alpha=0.9),
            dict(xi=0.05, U=0.5, W=-2, e=0.9, alpha=0.9),
            dict(xi=0.05, U=-1, e=0.9, alpha=0.9),
            dict(xi=0.05, U=-1, W=-2, x=1, e=0.9, alpha=0.9),
            dict(e=0.9, alpha=0.9),
            dict(xi=0.05, U=-1, W=-2, g=2, e=0.9, alpha=0.9),
            dict(x=0.02, u=-2, v=-2, omega=0, e=0.9, alpha=0.9),
            dict(x=0.02, u=-2, v=2, omega=0, radius=0, e=0.9, alpha=0.9),
        ]
        for params in cases:
            with self.subTest(**params):
                status, body = self.server.json("/api/count?" + query(**params))
                self.assertEqual(status, 400, body)
                flags = [a for k, v in params.items() for a in ("--" + k.replace("_", "-"), str(v))]
                r = run("count", *flags)
                self.assertEqual(r.returncode, 2, r.stderr)
                self.assertEqual(body["error"], cli_message(r.stderr))


class LoadTest(unittest.TestCase):
    """Slow, abandoned and concurrent requests on a server with 2 counting threads."""

    def test_slow_request_is_bounded_and_stalls_no_one(self):
        # A limit of 3 s, so that several fast requests fit beside the slow one wherever the
        # test runs (with 1 s, the sanitized build beside other work answered 2, of up to
        # 568 ms each).
        with Server("--threads", "2", "--time-limit", "3") as server:
            slow = dict(CAPPED, nx=512, ny=512, max_bounces=1000000)  # hours of work
            result = {}

            def ask():
                started = time.monotonic()
                result["answer"] = server.json("/api/region?" + query(**slow))
                result["seconds"] = time.monotonic() - started

            thread = threading.Thread(target=ask)
            thread.start()
            time.sleep(0.2)
            fast = []
            while thread.is_alive():
                started = time.monotonic()
                status, body = server.json("/api/count?" + query(xi=0.05, U=-1, W=-2, e=0.9, alpha=0.9))
                fast.append(time.monotonic() - started)
                self.assertEqual(status, 200)
                time.sleep(0.05)
            thread.join()
            status, body = result["answer"]
            self.assertEqual(status, 503, body)
            self.assertIn("took longer than the server's time limit of 3 s", body["error"])
            self.assertLess(result["seconds"], 3 + 2 * SLOWER)
            print(f"\nfast requests beside the slow one: {len(fast)}, at most {1e3 * max(fast):.0f} ms")
            # Answered while the slow one ran, each within the bound.
            self.assertGreaterEqual(len(fast), 3)
            self.assertLess(max(fast), 0.5 * SLOWER, fast)
            self.assertEqual(server.json("/api/info")[1]["stats"]["timed_out"], 1)

    def test_abandoned_request_is_dropped(self):
        with Server("--threads", "2", "--time-limit", "600") as server:
            host, port = urllib.parse.urlsplit(server.url).netloc.split(":")
            with socket.create_connection((host, int(port))) as s:
                path = "/api/region?" + query(**CAPPED, nx=512, ny=512, max_bounces=1000000)
                s.sendall(f"GET {path} HTTP/1.1\r\nHost: {host}\r\n\r\n".encode())
                time.sleep(0.3)
            deadline = time.monotonic() + 5
            while time.monotonic() < deadline:
                stats = server.json("/api/info")[1]["stats"]
                if stats["cancelled"] == 1:
                    break
                time.sleep(0.05)
            self.assertEqual(stats["cancelled"], 1, stats)
            self.assertGreater(stats["blocks_skipped"], 0)
            started = time.monotonic()
            status, _ = server.json("/api/region?" + query(**QUICKSTART, nx=256, ny=256))
            self.assertEqual(status, 200)
            self.assertLess(time.monotonic() - started, 1.0 * SLOWER)

    def test_concurrent_clients(self):
        clients, requests = 16, 50
        with Server("--threads", "2") as server:
            def client(seed):
                rng = random.Random(seed)
                latencies = []
                for _ in range(requests):
                    # A random part of the quickstart window at a random zoom.
                    size = 2.0 ** -rng.randint(0, 12)
                    x0, y0 = rng.uniform(0, 1 - size), rng.uniform(-3, 3 - 6 * size)
                    params = dict(QUICKSTART, x_min=x0, x_max=x0 + size, y_min=y0, y_max=y0 + 6 * size, nx=64, ny=64)
                    started = time.monotonic()
                    status, body = server.json("/api/region?" + query(**params))
                    latencies.append(time.monotonic() - started)
                    assert status == 200, body
                    assert len(body["wall_bounces"]) == 64 and len(body["wall_bounces"][0]) == 64
                return latencies

            client(-1)  # warm-up: the server's threads and arenas exist
            before = server.rss_kib()[0]
            started = time.monotonic()
            with concurrent.futures.ThreadPoolExecutor(clients) as pool:
                latencies = sorted(t for ts in pool.map(client, range(clients)) for t in ts)
            wall = time.monotonic() - started
            after = server.rss_kib()[0]
            with concurrent.futures.ThreadPoolExecutor(clients) as pool:
                list(pool.map(client, range(clients, 2 * clients)))
            again = server.rss_kib()[0]
            p50, p99 = latencies[len(latencies) // 2], latencies[int(0.99 * len(latencies))]
            print(f"\n{clients} clients x {requests} regions of 64x64: {wall:.2f} s, p50 {1e3 * p50:.1f} ms, "
                  f"p99 {1e3 * p99:.1f} ms; RSS {before / 1024:.1f} -> {after / 1024:.1f} -> {again / 1024:.1f} MiB")
            self.assertEqual(len(latencies), clients * requests)
            self.assertLess(wall, 60)
            # Memory flat: a second round of the same load leaves the server where the first did.
            if not SANITIZED:
                self.assertLess(again - after, 8 * 1024, (before, after, again))
            stats = server.json("/api/info")[1]["stats"]
            self.assertEqual((stats["timed_out"], stats["refused"], stats["pending"]), (0, 0, 0))


if __name__ == "__main__":
    superball_testing_main()
