#!/usr/bin/python3
"""xarray reads superball's results as netCDF-4/CF, with each of its engines and no
options: the dimensions and coordinate values of the file's axes, the data equal to
h5py's, units and long names, outcome flags, fixed coordinates as scalar coordinates, and
among the attributes the coordinate system and the provenance (history, source with the
commit, date_created, build). On results computed by the binary under test:
a canonical slice, a volume, a physical slice and a slice swept over alpha.

Needs Debian's python3-xarray, python3-h5netcdf and python3-netcdf4
(.ci/install-deps --clients, which tests/all runs)."""
import os
import shutil
import sys
import tempfile
import unittest
import warnings

import h5py
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from superball_testing import main as superball_testing_main  # noqa: E402
from superball_testing import CLIENT_JOBS, client_results  # noqa: E402

try:
    import h5netcdf  # noqa: F401
    import netCDF4  # noqa: F401  (imported once here: Debian's build warns about numpy's ABI on import)
    import xarray as xr
except ImportError as e:  # a failure, not a skip: the test command installs them
    raise SystemExit(f"test_xarray: {e}; install the clients with .ci/install-deps --clients")

ENGINES = (None, "h5netcdf", "netcdf4")  # None: xarray's own choice
# The provenance (CF and ACDD attributes) every result carries, as `superball info` prints it.
PROVENANCE = ("history", "source", "date_created", "build")
UNITS = {"xi": "1", "U": "1", "W": "1", "x": "m", "u": "m/s", "v": "m/s", "omega": "rad/s", "alpha": "1", "e": "1"}


def h5_view(path):
    """What the file holds, read with h5py: the reference every engine is compared with."""
    with h5py.File(path, "r") as f:
        axes = [str(n) for n in f.attrs["axis_names"]]
        return {
            "axes": axes,
            "samples": {n: f[n][()] for n in axes},
            "fixed": {k[len("fixed_"):]: float(v) for k, v in f.attrs.items() if k.startswith("fixed_")},
            "wall_bounces": f["wall_bounces"][()],
            "outcome": f["outcome"][()],
            "coordinate_system": str(f.attrs["coordinate_system"]),
            "provenance": {k: text(f.attrs[k]) for k in PROVENANCE},
        }


def text(value):
    return value.decode() if isinstance(value, bytes) else str(value)


class Xarray(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.dir = tempfile.mkdtemp(prefix="superball-xarray-")
        cls.results = client_results(cls.dir, CLIENT_JOBS)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.dir, ignore_errors=True)

    def open(self, path, engine):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            ds = xr.open_dataset(path, engine=engine) if engine else xr.open_dataset(path)
        # e.g. an attribute or coordinate xarray cannot decode
        self.assertEqual([str(w.message) for w in caught], [], path)
        return ds

    def check(self, kind, engine, ref):
        with self.open(self.results[kind], engine) as ds:
            axes = ref["axes"]
            self.assertEqual(dict(ds.sizes), {n: len(ref["samples"][n]) for n in axes})
            self.assertFalse([d for d in ds.dims if d.startswith("phony_dim")])
            for name in ("wall_bounces", "outcome"):
                var = ds[name]
                self.assertEqual(var.dims, tuple(axes))
                self.assertEqual(var.dtype, ref[name].dtype)  # no fill value turned it into floats
                np.testing.assert_array_equal(var.values, ref[name])
                self.assertTrue(var.attrs.get("long_name"), name)
            self.assertEqual(ds["wall_bounces"].attrs.get("units"), "1")
            flags = ds["outcome"].attrs
            np.testing.assert_array_equal(flags["flag_values"], [0, 1, 2, 3])
            self.assertEqual(np.asarray(flags["flag_values"]).dtype, np.uint8)
            self.assertEqual(flags["flag_meanings"], "invalid left missed capped")
            for name in axes:  # each axis a dimension coordinate with an index
                coord = ds.coords[name]
                self.assertEqual(coord.dims, (name,))
                self.assertIn(name, ds.indexes)
                np.testing.assert_array_equal(coord.values, ref["samples"][name])
                self.assertEqual(coord.attrs.get("units"), UNITS[name], name)
                self.assertTrue(coord.attrs.get("long_name"), name)
            for name, value in ref["fixed"].items():  # each fixed coordinate a scalar coordinate
                self.assertIn(name, ds.coords)
                coord = ds.coords[name]
                self.assertEqual(coord.dims, ())
                self.assertEqual(float(coord), value)
                self.assertEqual(coord.attrs.get("units"), UNITS[name], name)
                self.assertTrue(coord.attrs.get("long_name"), name)
                # selecting a sample keeps it: the point knows where it lies
                point = ds["wall_bounces"].isel({axis: 0 for axis in axes})
                self.assertEqual(float(point.coords[name]), value)
            self.assertEqual(ds.attrs.get("coordinate_system"), ref["coordinate_system"])
            self.assertEqual(ds.attrs.get("Conventions"), "CF-1.8")
            # The provenance, as text a script prints: which program and commit, when, by which command.
            for key, value in ref["provenance"].items():
                self.assertIsInstance(ds.attrs.get(key), str, key)
                self.assertEqual(ds.attrs[key], value, key)
            self.assertRegex(ds.attrs["source"], r"^superball \S+ \(git ([0-9a-f]{12}|unknown)(, dirty)?\)$")
            self.assertRegex(ds.attrs["date_created"], r"^\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ$")
            self.assertTrue(ds.attrs["history"].startswith(ds.attrs["date_created"] + " "), ds.attrs["history"])
            self.assertIn(" explore ", ds.attrs["history"])
            return {"dims": dict(ds.sizes), "coords": {n: ds.coords[n].values for n in ds.coords}}

    def test_every_engine_reads_every_kind_of_result(self):
        for kind in CLIENT_JOBS:
            ref = h5_view(self.results[kind])
            seen = {}
            for engine in ENGINES:
                with self.subTest(kind=kind, engine=engine or "default"):
                    seen[engine] = self.check(kind, engine, ref)
            # switching engine changes nothing a script sees
            for engine in ENGINES[1:]:
                if None in seen and engine in seen:
                    self.assertEqual(seen[engine]["dims"], seen[None]["dims"], (kind, engine))
                    self.assertEqual(seen[engine]["coords"].keys(), seen[None]["coords"].keys(), (kind, engine))
                    for name, values in seen[None]["coords"].items():
                        np.testing.assert_array_equal(seen[engine]["coords"][name], values)

    def test_kinds_have_the_expected_axes(self):
        """The jobs cover what they claim: a canonical slice and volume, a physical slice, alpha as an axis."""
        expected = {"slice": (["xi", "W"], {"U"}), "volume": (["xi", "U", "W"], set()),
                    "physical": (["x", "u"], {"v", "omega"}), "swept": (["alpha", "xi", "W"], {"U"})}
        for kind, (axes, fixed) in expected.items():
            ref = h5_view(self.results[kind])
            self.assertEqual(ref["axes"], axes, kind)
            self.assertEqual(set(ref["fixed"]), fixed, kind)

    def test_selection_by_value(self):
        """The recipe of docs/format.md (Reading results): a slice of the volume by value, as region_map.py draws it."""
        with self.open(self.results["volume"], None) as ds:
            near = ds["wall_bounces"].sel(U=-1.0, method="nearest")
            self.assertEqual(near.dims, ("xi", "W"))
            k = int(np.argmin(np.abs(ds["U"].values + 1.0)))
            with h5py.File(self.results["volume"], "r") as f:
                np.testing.assert_array_equal(near.values, f["wall_bounces"][:, k, :])
            self.assertEqual(float(near.coords["U"]), float(ds["U"][k]))


if __name__ == "__main__":
    superball_testing_main()
