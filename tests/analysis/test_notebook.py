"""The notebook of analysis/ (region_trajectory.ipynb) executed headless, as a user's
`jupyter-nbconvert --execute` runs it, on the Python module of the build tree; then its
figure and its numbers checked against the command line.

The notebook is copied into a scratch directory and run there, so what it writes
(region_trajectory.png and .json) never lands in the source tree.
"""

import json
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

import h5py
import nbformat
import numpy as np
from PIL import Image

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))
from superball_testing import main as superball_testing_main  # noqa: E402
from superball_testing import SOURCE, mpi_env, superball_binary  # noqa: E402

NOTEBOOK = os.path.join(SOURCE, "analysis", "region_trajectory.ipynb")


def module_dir():
    """Where the package superball of the build under test is (ctest: $SUPERBALL_BUILD_DIR)."""
    build = os.environ.get("SUPERBALL_BUILD_DIR") or os.path.join(SOURCE, "build", "release")
    path = os.path.abspath(os.path.join(build, "python"))
    if not os.path.isdir(os.path.join(path, "superball")):
        raise unittest.SkipTest(f"no Python module in {path}: build it")
    return path


def superball(*args):
    r = subprocess.run([superball_binary(), *map(str, args)], capture_output=True, text=True, env=mpi_env(),
                       timeout=300)
    if r.returncode != 0:
        raise AssertionError(f"superball {' '.join(map(str, args))}: {r.stderr}")
    return r.stdout


class NotebookTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls._tmp = tempfile.TemporaryDirectory(prefix="superball-notebook-")
        cls.dir = cls._tmp.name
        shutil.copy(NOTEBOOK, cls.dir)
        env = dict(os.environ, PYTHONPATH=module_dir(), MPLBACKEND="module://matplotlib_inline.backend_inline",
                   PYDEVD_DISABLE_FILE_VALIDATION="1")  # (a debugger warning on stderr, not a failure)
        cmd = [sys.executable, "-m", "nbconvert", "--to", "notebook", "--execute", "--ExecutePreprocessor.timeout=600",
               "--output", "executed.ipynb", "region_trajectory.ipynb"]
        cls.run_result = subprocess.run(cmd, cwd=cls.dir, capture_output=True, text=True, env=env, timeout=900)
        if cls.run_result.returncode != 0:
            raise AssertionError(f"{' '.join(cmd)} failed:\n{cls.run_result.stderr[-4000:]}")
        cls.executed = nbformat.read(os.path.join(cls.dir, "executed.ipynb"), as_version=4)
        with open(os.path.join(cls.dir, "region_trajectory.json")) as f:
            cls.numbers = json.load(f)

    @classmethod
    def tearDownClass(cls):
        cls._tmp.cleanup()

    def test_the_repository_s_notebook_carries_no_outputs(self):
        """Outputs are made by running it: stored ones would go stale and weigh on every clone."""
        for cell in nbformat.read(NOTEBOOK, as_version=4).cells:
            if cell.cell_type == "code":
                self.assertEqual(cell.outputs, [], cell.source[:60])
                self.assertIsNone(cell.execution_count)

    def test_every_cell_ran_without_error_and_the_figure_is_shown(self):
        code = [c for c in self.executed.cells if c.cell_type == "code"]
        self.assertTrue(all(c.execution_count for c in code))
        outputs = [o for c in code for o in c.outputs]
        self.assertFalse([o for o in outputs if o.output_type == "error"])
        self.assertTrue(any("image/png" in o.get("data", {}) for o in outputs), "no figure shown")
        # The dataset's provenance is printed, as xarray shows it.
        text = "".join(o.get("text", "") for o in outputs)
        self.assertIn("history: ", text)
        self.assertIn("superball.explore(", text)

    def test_the_figure(self):
        with Image.open(os.path.join(self.dir, "region_trajectory.png")) as image:
            self.assertEqual(image.size, (1400, 560))
            pixels = np.asarray(image.convert("RGB")).reshape(-1, 3)
        # A drawn map: many distinct colours (the counts' scale, the orbit, the path), not a blank page.
        self.assertGreater(len(np.unique(pixels, axis=0)), 200)

    def test_the_launch_and_its_trajectory_agree_with_the_command_line(self):
        n = self.numbers
        launch = n["launch"]
        model = ("--e", n["job"]["model"]["e"], "--alpha", n["job"]["model"]["alpha"])
        printed = superball("count", "--xi", repr(launch["xi"]), "--U", repr(launch["U"]), "--W", repr(launch["W"]),
                            *model)
        self.assertEqual(printed.strip(), f"{n['wall_bounces']} wall bounces, outcome {n['outcome']}")
        self.assertGreaterEqual(n["wall_bounces"], 5)  # the launch shows a trajectory worth drawing
        self.assertEqual(n["wall_impacts_drawn"], n["wall_bounces"])
        # The orbit: after k floor bounces, the launch has N - k wall bounces to go.
        orbit = n["orbit"]
        self.assertEqual(len(orbit["xi"]), n["wall_bounces"])
        self.assertEqual((orbit["xi"][0], orbit["U"][0], orbit["W"][0]), (launch["xi"], launch["U"], launch["W"]))
        for k in range(1, len(orbit["xi"])):
            printed = superball("count", "--xi", repr(orbit["xi"][k]), "--U", repr(orbit["U"][k]), "--W",
                                repr(orbit["W"][k]), *model)
            self.assertEqual(printed.split()[0], str(n["wall_bounces"] - k), f"orbit point {k}")

    def test_the_region_is_the_command_line_s_result(self):
        n = self.numbers
        grid, model = n["job"]["grid"], n["job"]["model"]
        axis = lambda a: f"{{ min = {a['min']!r}, max = {a['max']!r}, n = {a['n']} }}"  # noqa: E731
        job = os.path.join(self.dir, "region.toml")
        with open(job, "w") as f:
            f.write(f"[model]\ne = {model['e']!r}\nalpha = {model['alpha']!r}\n\n[grid]\n"
                    f"coordinates = \"canonical\"\nxi = {axis(grid['xi'])}\nU = {grid['U']!r}\nW = {axis(grid['W'])}\n\n"
                    f"[run]\nmax_bounces = {n['job']['run']['max_bounces']}\n")
        out = os.path.join(self.dir, "region.h5")
        superball("explore", job, "-o", out, "-q")
        with h5py.File(out, "r") as f:
            counts, outcomes, source = f["wall_bounces"][...], f["outcome"][...], f.attrs["source"]
        self.assertEqual(np.bincount(counts.ravel()).tolist(), n["histogram"])
        self.assertEqual(np.bincount(outcomes.ravel(), minlength=4).tolist(), n["outcomes"])
        # The same build and commit (the binary and the module of one build tree).
        self.assertEqual(source.decode() if isinstance(source, bytes) else source, n["source"])
        self.assertIn("superball.explore(", n["history"])


if __name__ == "__main__":
    superball_testing_main()
