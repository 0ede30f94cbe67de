"""Tests of the analysis scripts (analysis/region_map.py, trajectory_plot.py, summary.py).

Result files come from fixtures.make_result (SPEC.md section 5 written with h5py),
and expected values are read back from those files, so the checks do not depend
on how a file was made.  Scripts run as a user runs them, in a subprocess; a few
helpers are also imported for exact unit checks.  With $SUPERBALL naming a built
binary, trajectory_plot.py is also tried on its real output.
"""

import json
import os
import subprocess
import sys
import tempfile
import unittest

import h5py
import numpy as np
from PIL import Image

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE_DIR = os.environ.get("SUPERBALL_SOURCE_DIR") or os.path.dirname(os.path.dirname(HERE))
ANALYSIS = os.path.join(SOURCE_DIR, "analysis")
sys.path[:0] = [HERE, ANALYSIS]

import region_map  # noqa: E402
import superball_results  # noqa: E402
import trajectory_plot  # noqa: E402
from fixtures import CAPPED, INVALID, LEFT, MISSED, make_result  # noqa: E402
from superball_testing import tile_boxes  # noqa: E402

SCRIPTS = ("region_map.py", "trajectory_plot.py", "summary.py")
BINARY = os.environ.get("SUPERBALL", "")
HAVE_BINARY = os.path.isfile(BINARY) and os.access(BINARY, os.X_OK)
GRID_2D = {"xi": (0.0, 1.0, 24), "U": -1.0, "W": (-3.0, 3.0, 18)}
GRID_3D = {"xi": (0.0, 1.0, 12), "U": (-2.0, -0.5, 5), "W": (-3.0, 3.0, 10)}

# A canonical start (dimensionless) that leaves after one wall bounce, with 2 samples per flight:
# output of `superball trajectory --xi 0.3 --U -1 --W 0.3 --e 0.9 --alpha 0.9 --samples 2`.
CANONICAL_CSV = """\
event,wall_bounces,t,x,y,u_in,v_in,omega_in,u,v,omega
launch,0,0,0.6,0,-1,1,0.3,-1,1,0.3
wall,1,0.6,0,0.42,-1,0.4,0.3,0.9,0.34571428571428575,0.4357142857142858
floor,1,1.925264369858501,1.1927379328726508,0,0.9,-0.9795500841442151,0.4357142857142858,0.1748979591836735,0.8815950757297936,-1.3770408163265309
land,1,3.6884545213180884,1.5011162920156849,0,0.1748979591836735,-0.8815950757297936,-1.3770408163265309,0.1748979591836735,-0.8815950757297936,-1.3770408163265309
path,0,0,0.6,0,-1,1,0.3,-1,1,0.3
path,0,0.6,0,0.42,-1,0.4,0.3,-1,0.4,0.3
path,1,0.6,0,0.42,0.9,0.34571428571428575,0.4357142857142858,0.9,0.34571428571428575,0.4357142857142858
path,1,1.925264369858501,1.1927379328726508,-1.1102230246251565e-16,0.9,-0.9795500841442152,0.4357142857142858,0.9,-0.9795500841442152,0.4357142857142858
path,1,1.925264369858501,1.1927379328726508,0,0.1748979591836735,0.8815950757297936,-1.3770408163265309,0.1748979591836735,0.8815950757297936,-1.3770408163265309
path,1,3.6884545213180884,1.5011162920156849,0,0.1748979591836735,-0.8815950757297936,-1.3770408163265309,0.1748979591836735,-0.8815950757297936,-1.3770408163265309
"""

# A physical start (SI) stopped after 3 wall bounces, events only: output of `superball trajectory
# --x 0.02 --u -2 --v 2 --omega -200 --e 0.9 --alpha 0.9 --max-bounces 3`, with a comment line.
PHYSICAL_CSV = """\
# written by hand from superball trajectory output
event,wall_bounces,t,x,y,u_in,v_in,omega_in,u,v,omega
launch,0,0,0.02,0,-2,2,-200,-2,2,-200
wall,1,0.01,0,0.0195095,-2,1.9019,-200,1.8,-1.844845714285714,174.67457142857143
floor,1,0.020293431012417318,0.01852817582235117,0,1.8,-1.9458242725175279,174.67457142857143,-1.5477263265306118,1.7512418452657752,-160.09806122448978
wall,2,0.03226465325290475,0,0.02026156898224565,-1.5477263265306118,1.6338041550865936,-160.09806122448978,1.3929536938775506,-1.4258775028642041,145.87010457059
floor,2,0.04584054187925948,0.018910584209751048,0,1.3929536938775506,-1.559056970288744,145.87010457059,-1.3428868733996981,1.4031512732598697,-127.7139521571349
wall,3,0.059922580049664984,0,0.018786549654642888,-1.3428868733996981,1.2650064788081916,-127.7139521571349,1.2085981860597284,-1.1549721032488,114.28390604856429
floor,3,0.07519749466382185,0.01846123409488723,0,1.2085981860597284,-1.304819015613679,114.28390604856429,-0.9984938398889253,1.1743371140523111,-106.42529654630107
"""


def image_size(path):
    with Image.open(path) as image:
        return image.size


def image_array(path):
    with Image.open(path) as image:
        return np.asarray(image.convert("RGB"))


def colours(pixels):
    """Distinct RGB colours of an image array."""
    return {tuple(int(c) for c in rgb) for rgb in pixels.reshape(-1, 3)}


def read_back(path, index=()):
    """Counts and outcomes as stored in a result file (optionally a slice)."""
    with h5py.File(path, "r") as f:
        return f["wall_bounces"][index].astype(np.int64), f["outcome"][index].astype(np.int64)


def colour_keys(counts, outcomes):
    """What decides a point's colour: its count, or its outcome if invalid or capped."""
    keys = counts.astype(object)
    keys[outcomes == INVALID] = "invalid"
    keys[outcomes == CAPPED] = "capped"
    return keys


class ScriptTestCase(unittest.TestCase):
    """Runs scripts in a fresh temporary directory."""

    def setUp(self):
        self._tmp = tempfile.TemporaryDirectory(prefix="superball-analysis-")
        self.tmp = self._tmp.name

    def tearDown(self):
        self._tmp.cleanup()

    def path(self, name):
        return os.path.join(self.tmp, name)

    def run_script(self, script, *args, stdin=None, env=None, status=0):
        """Run an analysis script with this Python, checking its exit status."""
        command = [sys.executable, os.path.join(ANALYSIS, script), *map(str, args)]
        process = subprocess.run(command, capture_output=True, text=True, input=stdin, cwd=self.tmp,
                                 env=None if env is None else {**os.environ, **env}, timeout=300)
        self.assertEqual(process.returncode, status, f"{' '.join(command)}\nstdout: {process.stdout}\n"
                         f"stderr: {process.stderr}")
        return process

    def result(self, name, grid=GRID_2D, **options):
        return make_result(self.path(name), grid, **options)


class CommonTest(ScriptTestCase):
    def test_scripts_are_executable_with_debian_python(self):
        for script in SCRIPTS:
            path = os.path.join(ANALYSIS, script)
            with open(path, encoding="utf-8") as f:
                self.assertEqual(f.readline().strip(), "#!/usr/bin/python3", script)
            self.assertTrue(os.access(path, os.X_OK), f"{script} is not executable")

    def test_help_describes_inputs_and_outputs(self):
        for script in SCRIPTS:
            process = self.run_script(script, "--help")
            self.assertIn("Output", process.stdout, script)
            self.assertIn("Exit status", process.stdout, script)
        # Run directly too: the shebang must find numpy/h5py/matplotlib.
        process = subprocess.run([os.path.join(ANALYSIS, "summary.py"), "--help"], capture_output=True, text=True)
        self.assertEqual(process.returncode, 0, process.stderr)


class RegionMapTest(ScriptTestCase):
    def bare(self, result, *args):
        """The --bare image of a result as an RGB array."""
        output = self.path("bare.png")
        self.run_script("region_map.py", result, "--bare", "-o", output, *args)
        return image_array(output)

    def assert_one_colour_per_key(self, pixels, keys):
        """Cell (i, j) is pixel (x = i, y = up from the bottom), and colours and keys match one to one."""
        self.assertEqual(pixels.shape[:2], (keys.shape[1], keys.shape[0]))
        cells = np.flipud(pixels).swapaxes(0, 1)  # back to [first axis, second axis]
        colour_of = {}
        for index in np.ndindex(keys.shape):
            colour = tuple(int(c) for c in cells[index])
            self.assertEqual(colour_of.setdefault(keys[index], colour), colour, f"key {keys[index]} at {index}")
        self.assertEqual(len(set(colour_of.values())), len(colour_of), f"two keys share a colour: {colour_of}")
        return colour_of

    def test_figure_size_and_pdf(self):
        result = self.result("map.h5")
        self.run_script("region_map.py", result, "-o", self.path("map.png"), "--pdf")
        self.assertEqual(image_size(self.path("map.png")), region_map.DEFAULT_SIZES[(2, False)])
        with open(self.path("map.pdf"), "rb") as f:
            self.assertEqual(f.read(4), b"%PDF")
        self.run_script("region_map.py", result, "--outcome", "--size", "800x500")
        self.assertEqual(image_size(self.path("map.png")), (800, 500))  # default name: next to the result

    def test_exactly_k_colours_for_k_counts(self):
        shape = (GRID_2D["xi"][2], GRID_2D["W"][2])
        counts = np.indices(shape).sum(axis=0) // 7  # 6 distinct counts in bands
        result = self.result("k.h5", data=(counts, np.full(shape, LEFT)))
        stored_counts, outcomes = read_back(result)
        k = len(np.unique(stored_counts))
        pixels = self.bare(result)
        self.assertEqual(len(colours(pixels)), k)
        self.assert_one_colour_per_key(pixels, colour_keys(stored_counts, outcomes))
        # The figure draws the same colours (no interpolation blends them).
        self.run_script("region_map.py", result, "-o", self.path("k.png"))
        self.assertLessEqual(colours(pixels), colours(image_array(self.path("k.png"))))

    def test_invalid_grey_capped_black_and_orientation(self):
        result = self.result("banded.h5")
        counts, outcomes = read_back(result)
        self.assertTrue((outcomes == INVALID).any() and (outcomes == CAPPED).any())
        colour_of = self.assert_one_colour_per_key(self.bare(result), colour_keys(counts, outcomes))
        self.assertEqual(colour_of["invalid"], region_map.INVALID_COLOUR)
        self.assertEqual(colour_of["capped"], region_map.CAPPED_COLOUR)
        regular = np.unique(counts[(outcomes == LEFT) | (outcomes == MISSED)])
        self.assertEqual(len(colour_of), len(regular) + 2)

    def test_many_counts_grouped_into_bins(self):
        shape = (40, 30)
        counts = np.indices(shape).sum(axis=0)  # 69 distinct counts
        result = self.result("many.h5", grid={"xi": (0.0, 1.0, 40), "U": -1.0, "W": (-3.0, 3.0, 30)},
                             data=(counts, np.full(shape, LEFT)))
        pixels = self.bare(result)
        self.assertEqual(len(colours(pixels)), region_map.MAX_COUNT_CLASSES)
        cells = np.flipud(pixels).swapaxes(0, 1)
        # Each colour holds one run of consecutive counts, in count order.
        runs = {}
        for index in np.ndindex(shape):
            runs.setdefault(tuple(cells[index]), set()).add(int(counts[index]))
        spans = sorted((min(v), max(v), len(v)) for v in runs.values())
        self.assertTrue(all(high - low + 1 == n for low, high, n in spans), spans)
        self.assertTrue(all(a[1] + 1 == b[0] for a, b in zip(spans, spans[1:])), spans)

    def test_bin_labels_are_honest(self):
        bins = region_map.count_bins(np.arange(100), 15)
        self.assertEqual(len(bins), 15)
        self.assertEqual(bins[0], (0, 0))
        self.assertEqual(bins[-1][1], 99)
        self.assertEqual(region_map.bin_label(*bins[-1], last=True), f"N >= {bins[-1][0]} (max 99)")
        self.assertEqual(region_map.count_bins([0, 3, 7], 15), [(0, 0), (3, 3), (7, 7)])
        classes = region_map.CountClasses(np.array([1, 2, 5, 1000]), np.array([LEFT, MISSED, INVALID, CAPPED]), 15)
        self.assertEqual(classes.labels, ["N = 1", "N = 2", "invalid", "capped (N = max_bounces)"])

    def test_slice_of_3d_by_index_and_by_value(self):
        result = self.result("cube.h5", grid=GRID_3D)
        counts, outcomes = read_back(result, (slice(None), 2, slice(None)))
        by_index = self.bare(result, "--slice", "U=2")
        self.assert_one_colour_per_key(by_index, colour_keys(counts, outcomes))
        with h5py.File(result, "r") as f:
            value = f["U"][2] + 0.01
        np.testing.assert_array_equal(self.bare(result, "--slice", f"U={value!r}"), by_index)
        self.assertEqual(self.bare(result, "--slice", "xi=3").shape[:2], (GRID_3D["W"][2], GRID_3D["U"][2]))
        self.run_script("region_map.py", result, "--slice", "U=2", "--outcome")
        self.assertEqual(image_size(self.path("cube_U2.png")), region_map.DEFAULT_SIZES[(2, True)])

    def test_slice_reads_only_the_slice(self):
        """read_map asks h5py for a hyperslab, never the whole dataset."""
        result = superball_results.Result(self.result("cube.h5", grid=GRID_3D))
        requested = []

        class Recorder:
            def __init__(self, dataset):
                self.dataset = dataset

            def __getitem__(self, index):
                requested.append(index)
                return self.dataset[index]

            def __getattr__(self, name):
                return getattr(self.dataset, name)

        with result:
            result.counts, result.outcomes = Recorder(result.counts), Recorder(result.outcomes)
            counts, _, names, samples = region_map.read_map(result, {1: 3}, 2)
        self.assertEqual(requested, [(slice(1, None, 2), 3, slice(1, None, 2))] * 2)
        self.assertEqual(names, ["xi", "W"])
        self.assertEqual(counts.shape, (6, 5))
        self.assertEqual([len(s) for s in samples], [6, 5])

    def test_line_plot_of_1d_data(self):
        result = self.result("line.h5", grid={"xi": (0.0, 1.0, 50), "U": -1.0, "W": 0.5})
        self.run_script("region_map.py", result, "-o", self.path("line.png"), "--outcome")
        self.assertEqual(image_size(self.path("line.png")), region_map.DEFAULT_SIZES[(1, True)])
        self.assertEqual(self.bare(result).shape[:2], (1, 50))
        cube = self.result("cube.h5", grid=GRID_3D)
        self.run_script("region_map.py", cube, "--slice", "U=1", "--slice", "W=4", "-o", self.path("l2.png"))
        self.assertEqual(image_size(self.path("l2.png")), region_map.DEFAULT_SIZES[(1, False)])

    def test_physical_grid_and_stride(self):
        grid = {"x": (0.0, 0.05, 40), "u": -2.0, "v": 2.0, "omega": (-300.0, 300.0, 30)}
        result = self.result("phys.h5", grid=grid, coordinates="physical")
        self.run_script("region_map.py", result, "-o", self.path("phys.png"))
        self.assertEqual(self.bare(result, "--stride", "2").shape[:2], (15, 20))

    def test_incomplete_result_is_plotted_with_a_warning(self):
        result = self.result("part.h5", complete=False)
        process = self.run_script("region_map.py", result)
        self.assertIn("warning", process.stderr)
        self.assertIn("incomplete", process.stderr)
        self.assertTrue(os.path.isfile(self.path("part.png")))

    def test_bad_inputs_exit_2_naming_the_problem(self):
        result = self.result("map.h5")
        cube = self.result("cube.h5", grid=GRID_3D)
        cases = [
            ((self.path("missing.h5"),), "missing.h5"),
            ((result, "--slice", "Q=1"), "Q"),
            ((result, "--slice", "U=1"), "U is fixed"),
            ((result, "--slice", "W=18"), "out of range"),
            ((result, "--slice", "W=7.5"), "outside the axis range"),
            ((result, "--slice", "W"), "AXIS=INDEX"),
            ((cube,), "--slice"),
            ((cube, "--slice", "U=1", "--slice", "U=2"), "twice"),
        ]
        with open(self.path("junk.h5"), "w") as f:
            f.write("not HDF5")
        cases.append(((self.path("junk.h5"),), "junk.h5"))
        for args, expected in cases:
            with self.subTest(args=args):
                process = self.run_script("region_map.py", *args, status=2)
                self.assertIn(expected, process.stderr)


class SummaryTest(ScriptTestCase):
    def random_result(self, name, **options):
        def data(shape, max_bounces):
            rng = np.random.default_rng(7)
            counts = np.minimum(rng.geometric(0.1, size=shape) - 1, max_bounces)
            outcome = np.where(counts == max_bounces, CAPPED, rng.choice([INVALID, LEFT, MISSED], size=shape))
            return np.where(outcome == INVALID, 0, counts), outcome  # an invalid launch has no bounce

        return self.result(name, grid=GRID_3D, data=data, max_bounces=40, **options)

    def test_fractions_equal_direct_computation(self):
        result = self.random_result("r.h5", complete=False, tiles=8, tiles_done=3)
        counts, outcomes = read_back(result)
        for block in ("7", "1000000"):  # many odd blocks, and one
            summary = json.loads(self.run_script("summary.py", result, "--json", "--block", block).stdout)
            self.assertEqual(summary["shape"], list(counts.shape))
            self.assertEqual(summary["axis_names"], ["xi", "U", "W"])
            self.assertEqual(summary["points"], counts.size)
            expected = {n: c / counts.size for n, c in enumerate(np.bincount(counts.ravel())) if c}
            self.assertEqual({r["wall_bounces"]: r["fraction"] for r in summary["wall_bounces"]}, expected)
            fractions = np.bincount(outcomes.ravel(), minlength=4) / counts.size
            self.assertEqual([r["fraction"] for r in summary["outcome"]], list(fractions))
            self.assertEqual([r["outcome"] for r in summary["outcome"]], ["invalid", "left", "missed", "capped"])
            self.assertIs(summary["complete"], False)
            self.assertEqual(summary["tile_fraction"], 3 / 8)
            self.assertEqual(summary["model"]["e_wall"], 0.9)
            self.assertEqual(summary["max_bounces"], 40)

    def test_text_report(self):
        result = self.random_result("r.h5", complete=False)
        report = self.run_script("summary.py", result).stdout
        for expected in ("12 x 5 x 10 (xi x U x W) = 600 points", "incomplete", "e_wall=0.9", "capped",
                         "wall bounces"):
            self.assertIn(expected, report)
        report = self.run_script("summary.py", self.result("map.h5")).stdout
        self.assertIn("U = -1", report)

    def test_blocks_cover_every_point_once(self):
        for shape in [(7,), (5, 3), (4, 5, 6), (1, 1, 9)]:
            for limit in (1, 4, 5, 7, 30, 120, 10**6):
                hits = np.zeros(shape, dtype=int)
                for index in superball_results.iter_blocks(shape, limit):
                    self.assertLessEqual(hits[index].size, limit, (shape, limit, index))
                    hits[index] += 1
                self.assertTrue((hits == 1).all(), (shape, limit))

    def test_other_attribute_spellings_and_wide_counts(self):
        result = self.result("wide.h5", max_bounces=70000)
        with h5py.File(result, "a") as f:
            self.assertEqual(f["wall_bounces"].dtype, np.uint32)
            f.attrs["coordinates"] = np.bytes_(b"canonical")  # an attribute the layout does not use: ignored
        summary = json.loads(self.run_script("summary.py", result, "--json").stdout)
        self.assertEqual(summary["axis_names"], ["xi", "W"])
        self.assertIn(70000, [r["wall_bounces"] for r in summary["wall_bounces"]])
        # The layout has one spelling of axis_names, a list: a comma-separated text is refused.
        with h5py.File(result, "a") as f:
            f.attrs["axis_names"] = "xi,W"
        process = self.run_script("summary.py", result, "--json", status=2)
        self.assertIn("attribute axis_names is a text, not a list of texts", process.stderr)

    def test_missing_file(self):
        process = self.run_script("summary.py", self.path("nothing.h5"), status=2)
        self.assertIn("nothing.h5", process.stderr)


class FileLayoutTest(ScriptTestCase):
    """The fixtures are laid out as superball writes its files, and the scripts read that
    layout as the binary does: partial files with their tiles not done masked, values
    checked, the 0.1 layout refused with the binary's message."""

    def kinds(self):
        """One fixture of every kind make_result writes."""
        return {
            "2-D result": self.result("r2.h5"),
            "3-D result": self.result("r3.h5", grid=GRID_3D),
            "1-D result": self.result("r1.h5", grid={"xi": (0.0, 1.0, 50), "U": -1.0, "W": 0.5}),
            "physical result": self.result("phys.h5", coordinates="physical",
                                           grid={"x": (0.0, 0.05, 40), "u": -2.0, "v": 2.0, "omega": (-300.0, 300.0, 30)}),
            "32-bit counts": self.result("wide.h5", max_bounces=70000),
            "2-D partial": self.result("p2.h5", complete=False, tiles=4, tiles_done=1),
            "3-D partial": self.result("p3.h5", grid=GRID_3D, complete=False, tiles=8, tiles_done=3),
            "partial, no tile done": self.result("p0.h5", complete=False, tiles=6, tiles_done=0),
        }

    @unittest.skipUnless(HAVE_BINARY, "SUPERBALL does not name a built binary")
    def test_superball_info_accepts_every_fixture_kind(self):
        for kind, path in self.kinds().items():
            with self.subTest(kind):
                process = subprocess.run([BINARY, "info", path], capture_output=True, text=True, timeout=60)
                self.assertEqual(process.returncode, 0, process.stderr)
                partial = kind.endswith("partial") or "partial" in kind
                self.assertIn("kind:        partial" if partial else "kind:        result", process.stdout)
                with h5py.File(path, "r") as f:
                    done = int(f["progress/tile_done"][()].sum()) if partial else None
                    tiles = f["progress/tile_done"].size if partial else None
                if partial:
                    self.assertIn(f"complete:    no ({done} of {tiles} tiles done)", process.stdout)
                self.run_script("summary.py", path, "--json")

    def test_partial_file_reads_tiles_not_done_as_invalid(self):
        result = self.result("part.h5", complete=False, tiles=4, tiles_done=1)
        with h5py.File(result, "r+") as f:
            # Tiles not done hold whatever the disk held: nonsense, never read.
            tiles = tile_boxes(f["outcome"].shape, [int(t) for t in f.attrs["tile_shape"]])
            for box in tiles[1:]:
                f["outcome"][box] = 9
                f["wall_bounces"][box] = 12345
            done_points = f["outcome"][tiles[0]].size
            stored = f["outcome"][tiles[0]]
        process = self.run_script("summary.py", result, "--json")
        summary = json.loads(process.stdout)
        self.assertIn("warning", process.stderr)
        self.assertIn("1 of 4 tiles done", process.stderr)
        self.assertIs(summary["complete"], False)
        invalid = summary["outcome"][INVALID]["points"]
        self.assertEqual(invalid, summary["points"] - done_points + int((stored == INVALID).sum()))
        self.assertNotIn(12345, [r["wall_bounces"] for r in summary["wall_bounces"]])
        with superball_results.Result(result) as r:
            counts, outcomes = r.read((slice(None), slice(None)))
        self.assertTrue((outcomes[tiles[1]] == INVALID).all() and (counts[tiles[1]] == 0).all())

    def test_values_are_checked_naming_the_object_and_the_point(self):
        cases = [
            ("outcome", (3, 4), 200, "/outcome holds 200 at (3, 4): outcome codes are 0 to 3"),
            ("wall_bounces", (0, 2), 5, "/wall_bounces holds 5 at (0, 2) with outcome 0 (invalid), which allows 0"),
            ("wall_bounces", (7, 9), 1001, "/wall_bounces holds 1001 at (7, 9) with outcome"),
        ]
        for dataset, at, value, message in cases:
            with self.subTest(dataset=dataset, at=at):
                result = self.result("bad.h5")
                with h5py.File(result, "r+") as f:
                    f[dataset][at] = value
                for script in ("summary.py", "region_map.py"):
                    process = self.run_script(script, result, status=2)
                    self.assertIn(f"bad.h5: {message}", process.stderr)
                    self.assertEqual(len(process.stderr.strip().splitlines()), 1, process.stderr)
                if HAVE_BINARY:
                    process = subprocess.run([BINARY, "info", result], capture_output=True, text=True, timeout=60)
                    self.assertEqual(process.returncode, 2)
                    self.assertIn(message, process.stderr)

    def test_layout_of_superball_0_1_is_refused_as_the_binary_refuses_it(self):
        path = self.path("old.h5")
        with h5py.File(path, "w") as f:
            f.create_dataset("wall_bounces", data=np.zeros((4, 3), np.uint16))
            f.create_dataset("outcome", data=np.zeros((4, 3), np.uint8))
            f.create_dataset("axes/xi", data=np.arange(4.0))
            f.create_dataset("axes/W", data=np.arange(3.0))
            f.create_dataset("progress/tile_done", data=np.ones(1, np.uint8))
            f.attrs.update({"coordinates": "canonical", "axis_names": ["xi", "W"], "job_toml": "[model]\n",
                            "software_version": "0.1.0", "complete": np.uint8(1), "max_bounces": np.uint32(10)})
        message = (f"{path}: written by superball 0.1.0 in the layout before netCDF conventions, which this version "
                   "does not read; run the job again with this version")
        for script in ("summary.py", "region_map.py"):
            self.assertIn(message, self.run_script(script, path, status=2).stderr)
        if HAVE_BINARY:
            process = subprocess.run([BINARY, "info", path], capture_output=True, text=True, timeout=60)
            self.assertEqual(process.returncode, 2)
            self.assertEqual(process.stderr.strip(), "superball info: " + message)


class TrajectoryPlotTest(ScriptTestCase):
    def check_outputs(self, png, gif, frames):
        self.assertEqual(image_size(png), trajectory_plot.PNG_SIZE)
        with Image.open(gif) as image:
            self.assertEqual(image.size, trajectory_plot.GIF_SIZE)
            self.assertEqual(image.n_frames, frames)

    def test_handmade_csv_file_and_stdin(self):
        with open(self.path("canonical.csv"), "w") as f:
            f.write(CANONICAL_CSV)
        self.run_script("trajectory_plot.py", self.path("canonical.csv"), "--gif", self.path("c.gif"), "--frames", 5)
        self.check_outputs(self.path("canonical.png"), self.path("c.gif"), 5)
        self.run_script("trajectory_plot.py", "-", "-o", self.path("p.png"), "--gif", self.path("p.gif"),
                        "--frames", 4, "--fps", 10, stdin=PHYSICAL_CSV)
        self.check_outputs(self.path("p.png"), self.path("p.gif"), 4)

    def test_reconstruction_and_units(self):
        canonical = trajectory_plot.read_csv(CANONICAL_CSV, "canonical")
        self.assertAlmostEqual(canonical.g, 1.0, places=12)
        self.assertTrue(canonical.dimensionless)
        self.assertEqual((canonical.wall_bounces, canonical.outcome), (1, "left"))
        self.assertEqual(trajectory_plot.Scene(canonical, None).radius, 1.0)
        physical = trajectory_plot.read_csv(PHYSICAL_CSV, "physical")
        self.assertAlmostEqual(physical.g, 9.81, places=9)
        self.assertFalse(physical.dimensionless)
        self.assertEqual((physical.wall_bounces, physical.outcome), (3, "capped"))
        self.assertEqual(trajectory_plot.Scene(physical, None).radius, trajectory_plot.PHYSICAL_RADIUS)
        self.assertIsNone(physical.path)
        for tr in (canonical, physical):
            # The flights rebuilt from each event land exactly on the next one.
            x, y = tr.position(tr.times)
            np.testing.assert_allclose(x, [e.x for e in tr.events], atol=1e-12)
            np.testing.assert_allclose(y, [e.y for e in tr.events], atol=1e-12)
            spin = sum(a.omega * (b.t - a.t) for a, b in zip(tr.events, tr.events[1:]))
            self.assertAlmostEqual(float(tr.angle([tr.times[-1]])[0]), spin, places=9)

    @unittest.skipUnless(HAVE_BINARY, "SUPERBALL does not name a built binary")
    def test_real_superball_output(self):
        start = ["--x", "0.02", "--u", "-2", "--v", "2", "--omega", "-200", "--e", "0.9", "--alpha", "0.9"]
        csv_path = self.path("real.csv")
        subprocess.run([BINARY, "trajectory", *start, "--samples", "20", "-o", csv_path], check=True)
        self.run_script("trajectory_plot.py", csv_path, "--gif", self.path("real.gif"), "--frames", 6)
        self.check_outputs(self.path("real.png"), self.path("real.gif"), 6)
        self.run_script("trajectory_plot.py", "-o", self.path("run.png"), "--gif", self.path("run.gif"),
                        "--frames", 3, "--run", *start)
        self.check_outputs(self.path("run.png"), self.path("run.gif"), 3)
        process = self.run_script("trajectory_plot.py", "--run", "--x", "0.02", status=2)
        self.assertIn("superball", process.stderr)

    def test_bad_inputs(self):
        process = self.run_script("trajectory_plot.py", self.path("absent.csv"), status=2)
        self.assertIn("absent.csv", process.stderr)
        process = self.run_script("trajectory_plot.py", "-", stdin="a,b,c\n1,2,3\n", status=2)
        self.assertIn("header", process.stderr)
        bad_row = CANONICAL_CSV.replace("wall,1,0.6", "wall,1,zero", 1)
        process = self.run_script("trajectory_plot.py", "-", stdin=bad_row, status=2)
        self.assertIn("line 3", process.stderr)
        self.run_script("trajectory_plot.py", status=2)  # neither a file nor --run
        process = self.run_script("trajectory_plot.py", "--run", "--xi", "0.3",
                                  env={"SUPERBALL": self.path("no-such-binary")}, status=1)
        self.assertIn("no-such-binary", process.stderr)


if __name__ == "__main__":
    unittest.main()
