"""Tests of the analysis scripts (analysis/region_map.py, trajectory_plot.py, summary.py,
bifurcation_plot.py).

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

import bifurcation_plot  # noqa: E402
import region_map  # noqa: E402
import superball_results  # noqa: E402
import trajectory_plot  # noqa: E402
from fixtures import CAPPED, INVALID, LEFT, MISSED, banded_data, make_result  # noqa: E402
from superball_testing import main as superball_testing_main  # noqa: E402
from superball_testing import tile_boxes  # noqa: E402

SCRIPTS = ("region_map.py", "trajectory_plot.py", "summary.py", "bifurcation_plot.py")
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

# Two branches of `superball continue --e 0.9 --alpha 0.99 --param alpha --min 0.98 --max 1
# --step 0.1 --max-step 0.1`, from --start 0.2488,-0.5569,-1.3567 (every fourth point and the
# events, renumbered) and from --start 0,-1.077,-2.595 (the corner fixed point, stable above the
# branch point).
CONTINUE_CSV = """\
# superball continue: alpha from 0.98 to 1; model at the start: e_wall 0.9 alpha_wall 0.99 e_floor 0.9 alpha_floor 0.99
branch,period,corner,alpha,xi,U,W,lambda,ev1_re,ev1_im,ev2_re,ev2_im,ev3_re,ev3_im,stability,event,note,residual,arclength,bracket
0,1,0,0.9850624493840585,4.719953996578687e-17,-1.072765982895144,-2.5893604216282156,0.932169751786158,0.9999999999999989,0,-0.8242268196716229,0.5394424704456636,-0.8242268196716229,-0.5394424704456636,marginal,boundary,xi -> 0,1.3322676295501878e-15,-1.3591828393366794,6.730727086790012e-16
0,1,0,0.9853504329652042,0.04723385690145166,-0.9743954547177792,-2.3542692428043144,0.9311109770641414,1.0014884673778663,0,-0.7862074825193194,0.598317181055649,-0.7862074825193194,-0.598317181055649,saddle,,,2.220446049250313e-16,-1.0999999999999999,0
0,1,0,0.9861503567035416,0.1202877649126898,-0.8225797823246254,-1.9914821604809902,0.9291801173497727,1.006018187738903,0,-0.7082580279862966,0.6955989206977438,-0.7082580279862966,-0.6955989206977438,saddle,,,1.1102230246251565e-16,-0.7,0
0,1,0,0.9877495439492799,0.19359515933278001,-0.6707659721333673,-1.628748161395593,0.9267702731685569,1.0152847000012204,0,-0.5926111371240597,0.8024078569417185,-0.5926111371240597,-0.8024078569417185,saddle,,,2.220446049250313e-16,-0.30000000000000004,0
0,1,0,0.9894059631714429,0.2370130686595007,-0.5811841003866155,-1.4147377873166365,0.9250452317003581,1.0250410824745144,0,-0.4945481439307589,0.86915023634274,-0.4945481439307589,-0.86915023634274,marginal,neimark_sacker,angle 2.088111198904507 rad (0.33233321903119617 turns),2.7755575615628914e-17,-0.06396354079124487,8.049116928532385e-15
0,1,0,0.99,0.24880413569366772,-0.5569088577658803,-1.3567492839376505,0.9245297028936871,1.0286131731668695,0,-0.4623356200999169,0.8873064566996816,-0.4623356200999169,-0.8873064566996816,unstable,,,2.220446049250313e-16,0,0
0,1,0,0.9953141061911223,0.31519987306796854,-0.4207372410393435,-1.0315117466524024,0.9211592909060832,1.0638537661359515,0,-0.21106721728120348,0.9774715493502464,-0.21106721728120348,-0.9774715493502464,marginal,neimark_sacker,angle 1.783462972261166 rad (0.28384694785672837 turns),1.6653345369377348e-16,0.3588312774551568,1.0956513474269514e-14
0,1,0,1,0.347498927545322,-0.3548918114874911,-0.8742804049186215,0.9191645948690614,1.1032276671784238,0,-0.021281218354537182,0.9928253020385485,-0.021281218354537182,-0.9928253020385485,saddle,end,alpha = max,3.3306690738754696e-16,0.5323895606334854,0
1,1,1,0.98,0,-1.0684745541764151,-2.583918838235274,0.9247266770672165,1.0243417148321636,0,-0.8298713272704241,0.5432231245991268,-0.8298713272704241,-0.5432231245991268,saddle,end,alpha = min,6.661338147750939e-16,-0.016959644222803574,0
1,1,1,0.9850624493840583,0,-1.0727659828951444,-2.5893604216282156,0.9321697517861575,1.0000000000000004,0,-0.8242268196716247,0.5394424704456634,-0.8242268196716247,-0.5394424704456634,marginal,branch_point,kappa = 1: an interior branch meets the plane,8.881784197001252e-16,-0.008377385172426035,2.393918396847994e-16
1,1,1,0.99,0,-1.0769470767324476,-2.5946820448040584,0.9394501549268768,-0.8187872100578475,0.5357960052265307,-0.8187872100578475,-0.5357960052265307,0.9769307770339986,0,stable,,,8.881784197001252e-16,0,0
1,1,1,1,0,-1.0854017419508706,-2.605502682752226,0.9542585225582874,-0.8079642927710479,0.5285319332161582,-0.8079642927710479,-0.5285319332161582,0.9321523028222304,0,stable,end,alpha = max,4.440892098500626e-16,0.016987255933436647,0
"""

# Event curves of `superball continue --e 0.9 --alpha 0.99 --param alpha --min 0.5 --max 1 --start
# 0,-1.077,-2.595 --curve e --curve-min 0.8 --curve-max 0.99 --curve-step 0.02 --curve-max-step 0.05`,
# every other point.
CURVES_CSV = """\
# superball continue: event curves in (alpha, e), alpha from 0.5 to 1, e from 0.8 to 0.99; model at the start: e_wall 0.9 alpha_wall 0.99 e_floor 0.9 alpha_floor 0.99
curve,branch,event,period,corner,alpha,e,xi,U,W,lambda,ev1_re,ev1_im,ev2_re,ev2_im,ev3_re,ev3_im,stability,note
0,0,neimark_sacker,1,1,0.9550499482603967,0.8318585612457468,0,-1.1133773142987877,-2.6362896466064036,0.8577954086139193,1.0963464866853239,0,-0.8364465602814364,0.5480484940161369,-0.8364465602814364,-0.5480484940161369,marginal,angle 2.5615632948844778 rad (0.40768546042362697 turns)
0,0,neimark_sacker,1,1,0.9685571706327674,0.88,0,-1.0774239837044628,-2.5942033194613368,0.8989563860483383,1.0659810358691508,0,-0.8365957478284982,0.5478207322795247,-0.8365957478284982,-0.5478207322795247,marginal,angle 2.5618355674194877 rad (0.40772879394344197 turns)
0,0,neimark_sacker,1,1,0.979373235916181,0.92,0,-1.049842602190075,-2.5612211117521113,0.9328762558055007,1.042565950140444,0,-0.8366755760647064,0.5476988044690189,-0.8366755760647064,-0.5476988044690189,marginal,angle 2.561981303270631 rad (0.40775198852453715 turns)
0,0,neimark_sacker,1,1,0.991999625750505,0.9683798441156666,0,-1.018919815929097,-2.5234914630152434,0.9735796774606408,1.0161948354331618,0,-0.8367259150729787,0.5476218978869326,-0.8367259150729787,-0.5476218978869326,marginal,angle 2.5620732197442795 rad (0.4077666174856699 turns)
1,0,branch_point,1,1,0.977118040180663,0.8503843331374679,0,-1.1140974144983298,-2.6387703273711716,0.8975875780577885,1.0000000000000007,0,-0.8175671934538136,0.5351107816467127,-0.8175671934538136,-0.5351107816467127,marginal,kappa = 1: an interior branch meets the plane
1,0,branch_point,1,1,0.9850624493840588,0.9,0,-1.0727659828951444,-2.589360421628216,0.9321697517861585,0.9999999999999969,0,-0.824226819671624,0.5394424704456634,-0.824226819671624,-0.5394424704456634,marginal,kappa = 1: an interior branch meets the plane
1,0,branch_point,1,1,0.9926489090718339,0.9496623821142001,0,-1.0350321577596613,-2.5434132550566533,0.9661535561991734,1.0000000000000002,0,-0.8305815754055004,0.5435863347053695,-0.8305815754055004,-0.5435863347053695,marginal,kappa = 1: an interior branch meets the plane
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
            "2-D compressed partial": self.result("c2.h5", complete=False, tiles=4, tiles_done=1, compressed=True),
            "3-D compressed partial, 32-bit counts": self.result("c3.h5", grid=GRID_3D, complete=False, tiles=8,
                                                                tiles_done=3, compressed=True, max_bounces=70000),
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

    def test_compressed_partial_file_reads_its_stored_tiles(self):
        """A compressed partial file's tiles done are read from where its journal says, and
        any index or slice of them equals the data written; the tiles not done read invalid."""
        counts, outcome = banded_data((24, 18), 1000)
        result = self.result("cpart.h5", complete=False, tiles=12, tiles_done=5, compressed=True,
                             data=(counts, outcome))
        with h5py.File(result, "r") as f:
            tile_shape = [int(t) for t in f.attrs["tile_shape"]]
        done = np.zeros(counts.shape, dtype=bool)
        for box in tile_boxes(counts.shape, tile_shape)[:5]:
            done[box] = True
        want_counts, want_outcome = np.where(done, counts, 0), np.where(done, outcome, INVALID)
        with superball_results.Result(result) as r:
            for index in [(slice(None), slice(None)), (slice(3, 17, 2), slice(None, None, 5)), (4, slice(2, 20)),
                          (slice(None), 7), (23, 17)]:
                with self.subTest(index=index):
                    got_counts, got_outcome = r.read(index)
                    np.testing.assert_array_equal(got_counts, want_counts[index])
                    np.testing.assert_array_equal(got_outcome, want_outcome[index])

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


class BifurcationPlotTest(ScriptTestCase):
    def test_png_and_pdf_of_the_given_size(self):
        with open(self.path("branches.csv"), "w") as f:
            f.write(CONTINUE_CSV)
        process = self.run_script("bifurcation_plot.py", self.path("branches.csv"))
        self.assertEqual(process.stdout.split(), [self.path("branches.png"), self.path("branches.pdf")])
        self.assertEqual(image_size(self.path("branches.png")), bifurcation_plot.PNG_SIZE)
        with open(self.path("branches.pdf"), "rb") as f:
            self.assertEqual(f.read(5), b"%PDF-")
        self.run_script("bifurcation_plot.py", "-", "-o", self.path("small.png"), "--size", "400x300",
                        "--y", "xi,lambda,moduli", stdin=CONTINUE_CSV)
        self.assertEqual(image_size(self.path("small.png")), (400, 300))
        self.assertTrue(os.path.isfile(self.path("small.pdf")))

    def test_it_draws_branches_and_events(self):
        """The branches' colours and the event markers' colours are on the image."""
        self.run_script("bifurcation_plot.py", "-", "-o", self.path("d.png"), stdin=CONTINUE_CSV)
        seen = colours(image_array(self.path("d.png")))
        from matplotlib.colors import to_rgb

        def present(name):
            want = np.array(to_rgb(name)) * 255
            return any(np.abs(np.array(c) - want).max() <= 2 for c in seen)

        for name in ("tab:blue", "tab:orange", "tab:green", bifurcation_plot.EVENT_STYLE["branch_point"][1]):
            self.assertTrue(present(name), name)
        self.assertFalse(present("tab:red"))  # no fold in these branches

    def test_stable_solid_other_dashed(self):
        diagram = bifurcation_plot.read_csv(CONTINUE_CSV, "test")
        self.assertEqual(diagram.parameter, "alpha")
        self.assertEqual(sorted(diagram.branches), [0, 1])
        self.assertIn("e_wall 0.9", diagram.title)
        # Interior branch: never stable, one dashed run through every point.
        runs = bifurcation_plot.stretches(diagram.branches[0])
        self.assertEqual([(stable, len(points)) for stable, points in runs], [(False, 8)])
        # Corner branch: saddle up to the branch point, stable after it; the event point, where
        # the stability changes, belongs to both runs.
        runs = bifurcation_plot.stretches(diagram.branches[1])
        self.assertEqual([(stable, [p.parameter for p in points]) for stable, points in runs],
                         [(False, [0.98, 0.9850624493840583]), (True, [0.9850624493840583, 0.99, 1.0])])
        point = diagram.branches[0][4]
        self.assertEqual(point.event, "neimark_sacker")
        moduli = bifurcation_plot.quantity(point, "moduli")
        self.assertAlmostEqual(bifurcation_plot.marker_value(point, "moduli"), 1.0, places=9)
        self.assertEqual(bifurcation_plot.quantity(point, "modulus"), [max(moduli)])

    def test_event_curves_in_the_plane(self):
        diagram = bifurcation_plot.read_csv(CURVES_CSV, "test")
        self.assertIsInstance(diagram, bifurcation_plot.Curves)
        self.assertEqual(diagram.parameters, ("alpha", "e"))
        self.assertEqual([(n, points[0].event, len(points)) for n, points in sorted(diagram.curves.items())],
                         [(0, "neimark_sacker", 4), (1, "branch_point", 3)])
        self.run_script("bifurcation_plot.py", "-", "-o", self.path("c.png"), "--size", "600x500", stdin=CURVES_CSV)
        self.assertEqual(image_size(self.path("c.png")), (600, 500))
        self.assertTrue(os.path.isfile(self.path("c.pdf")))
        seen = colours(image_array(self.path("c.png")))
        from matplotlib.colors import to_rgb

        for event in ("neimark_sacker", "branch_point"):
            want = np.array(to_rgb(bifurcation_plot.EVENT_STYLE[event][1])) * 255
            self.assertTrue(any(np.abs(np.array(c) - want).max() <= 2 for c in seen), event)
        bad = CURVES_CSV.replace("0,0,neimark_sacker", "0,0,hopf", 1)
        process = self.run_script("bifurcation_plot.py", "-", stdin=bad, status=2)
        self.assertIn("hopf", process.stderr)
        bad = CURVES_CSV.replace("curve,branch,event,period,corner,alpha,e", "curve,branch,event,period,corner,alpha,g")
        process = self.run_script("bifurcation_plot.py", "-", stdin=bad, status=2)
        self.assertIn("--curve CSV", process.stderr)

    @unittest.skipUnless(HAVE_BINARY, "SUPERBALL does not name a built binary")
    def test_real_superball_output(self):
        self.run_script("bifurcation_plot.py", "-o", self.path("run.png"), "--run", "--e", "0.9", "--alpha", "0.99",
                        "--param", "alpha", "--min", "0.98", "--max", "1", "--start", "0,-1.077,-2.595")
        self.assertEqual(image_size(self.path("run.png")), bifurcation_plot.PNG_SIZE)
        process = self.run_script("bifurcation_plot.py", "--run", "--param", "alpha", status=2)
        self.assertIn("superball", process.stderr)

    def test_bad_inputs(self):
        process = self.run_script("bifurcation_plot.py", self.path("absent.csv"), status=2)
        self.assertIn("absent.csv", process.stderr)
        process = self.run_script("bifurcation_plot.py", "-", stdin="a,b,c\n1,2,3\n", status=2)
        self.assertIn("header", process.stderr)
        process = self.run_script("bifurcation_plot.py", "-", stdin='{"branches": []}', status=2)
        self.assertIn("JSON", process.stderr)
        bad = CONTINUE_CSV.replace("saddle,,,2.22", "saddle,hopf,,2.22", 1)
        process = self.run_script("bifurcation_plot.py", "-", stdin=bad, status=2)
        self.assertIn("line 4", process.stderr)
        self.assertIn("hopf", process.stderr)
        bad = CONTINUE_CSV.replace("0,1,0,0.99,", "0,1,0,zero,", 1)
        process = self.run_script("bifurcation_plot.py", "-", stdin=bad, status=2)
        self.assertIn("not a number", process.stderr)
        process = self.run_script("bifurcation_plot.py", "-", "--y", "speed", stdin=CONTINUE_CSV, status=2)
        self.assertIn("--y", process.stderr)
        process = self.run_script("bifurcation_plot.py", "-", "-o", self.path("x.jpg"), stdin=CONTINUE_CSV, status=2)
        self.assertIn(".png", process.stderr)
        self.run_script("bifurcation_plot.py", status=2)  # neither a file nor --run


if __name__ == "__main__":
    superball_testing_main()
