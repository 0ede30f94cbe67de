#!/usr/bin/python3
"""The netCDF library's own tool reads superball's results: `ncdump -h` shows one
dimension and one coordinate variable per axis, the fixed coordinates as scalar
variables, the data over the axes in order with their attributes, and no groups;
`ncdump -v AXIS` prints the axis' samples. On results computed by the binary under test
(the kinds of tests/clients/test_xarray.py).

Needs Debian's netcdf-bin (.ci/install-deps --clients, which tests/all runs)."""
import os
import re
import shutil
import subprocess
import sys
import tempfile
import unittest

import h5py
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from superball_testing import main as superball_testing_main  # noqa: E402
from superball_testing import CLIENT_JOBS, client_results  # noqa: E402

NCDUMP = shutil.which("ncdump")


def ncdump(*args):
    r = subprocess.run([NCDUMP, *args], capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, f"ncdump {' '.join(args)}: {r.stderr}"
    return r.stdout


def section(text, name):
    """The lines of a section of ncdump's output (dimensions:, variables:)."""
    body = text.split(name + ":\n", 1)[1]
    return [line.strip() for line in re.split(r"\n(?=\S)", body, maxsplit=1)[0].splitlines() if line.strip()]


class Ncdump(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        if not NCDUMP:  # a failure, not a skip: the test command installs it
            raise AssertionError("ncdump not found; install the clients with .ci/install-deps --clients")
        cls.dir = tempfile.mkdtemp(prefix="superball-ncdump-")
        cls.results = client_results(cls.dir, CLIENT_JOBS)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.dir, ignore_errors=True)

    def test_header(self):
        for kind, path in self.results.items():
            with self.subTest(kind=kind), h5py.File(path, "r") as f:
                axes = [str(n) for n in f.attrs["axis_names"]]
                fixed = [k[len("fixed_"):] for k in f.attrs if k.startswith("fixed_")]
                counts = {np.dtype("uint16"): "ushort", np.dtype("uint32"): "uint"}[f["wall_bounces"].dtype]
                shape = f["wall_bounces"].shape
                text = ncdump("-h", path)
                self.assertNotIn("group:", text)
                self.assertNotIn("phony_dim", text)
                self.assertEqual(sorted(section(text, "dimensions")),
                                 sorted(f"{n} = {len(f[n])} ;" for n in axes))
                declarations = [line for line in section(text, "variables") if not line.startswith(("string ", ":"))
                                and ":" not in line.split("(")[0]]
                over = ", ".join(axes)
                expected = ([f"double {n}({n}) ;" for n in axes] + [f"double {n} ;" for n in fixed] +
                            [f"{counts} wall_bounces({over}) ;", f"ubyte outcome({over}) ;"])
                self.assertEqual(sorted(declarations), sorted(expected))
                self.assertEqual(tuple(len(f[n]) for n in axes), shape)
                for name in axes + fixed + ["wall_bounces"]:
                    self.assertRegex(text, rf'{name}:units = "[^"]+" ;')
                for name in axes + fixed + ["wall_bounces", "outcome"]:
                    self.assertRegex(text, rf'{name}:long_name = "[^"]+" ;')
                self.assertIn("outcome:flag_values = 0UB, 1UB, 2UB, 3UB ;", text)
                self.assertIn('outcome:flag_meanings = "invalid left missed capped" ;', text)
                for name in ("wall_bounces", "outcome"):
                    named = re.search(rf'{name}:coordinates = "([^"]*)" ;', text)
                    self.assertEqual(set(named.group(1).split()) if named else set(), set(fixed), name)
                self.assertRegex(text, r':coordinate_system = "(canonical|physical)" ;')

    def test_axis_values(self):
        for kind, path in self.results.items():
            with self.subTest(kind=kind), h5py.File(path, "r") as f:
                for name in f.attrs["axis_names"]:
                    text = ncdump("-p", "17,17", "-v", str(name), path)
                    values = re.search(rf"\n {name} = ([^;]*);", text).group(1)
                    printed = np.array([float(v) for v in values.replace("\n", " ").split(",")])
                    np.testing.assert_array_equal(printed, f[name][()])


if __name__ == "__main__":
    superball_testing_main()
