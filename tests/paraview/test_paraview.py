#!/usr/bin/python3
"""ParaView reads superball's XDMF sidecars right, headless (xvfb-run pvbatch), with its
legacy XDMF reader and both Xdmf3 readers, on a canonical slice and a volume computed by
the binary under test: the mesh's dimensions, coordinates and bounds (a slice is a mesh
one sample thick at its fixed coordinate, not a line), the point arrays equal to h5py's
data, a Slice filter between two sample planes whose interpolated counts and outcomes
stay between their neighbours' (unsigned 16-bit counts once wrapped to ~7e8), the
sidecar opened by absolute path from another working directory and as ./NAME.xmf from
its own, and the volume read in pieces by two pvbatch ranks.

Needs Debian's paraview, python3-paraview, xvfb and xauth (.ci/install-deps --clients,
which tests/all runs). About 15 s: each pvbatch start costs 2-3 s."""
import json
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

import h5py
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from superball_testing import main as superball_testing_main  # noqa: E402
from superball_testing import client_results, mpi_env  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
READERS = ("XDMFReader", "Xdmf3ReaderS", "Xdmf3ReaderT")
MESH_ORDER = ("xi", "U", "W")  # canonical coordinates, slowest first: Z, Y, X
# The slice's file name has every XML special character and a space: the sidecar must
# escape them and the readers must find the file.
NAMES = {"slice": "slice & <co>'s \"1\".h5"}
# Lines of pvbatch's output that mean a reader failed or skipped something.
FAILURE_MARKS = ("ERR|", "XDMF Error", "Skipping", "Traceback", "terminate called", "HDF5-DIAG")


def sidecar(path):
    return os.path.splitext(path)[0] + ".xmf"


class Expected:
    """What a reader must produce for a result, from h5py: the mesh (canonical
    coordinates in order, the fixed ones one sample thick) and the data in mesh order."""

    def __init__(self, path):
        with h5py.File(path, "r") as f:
            axes = [str(n) for n in f.attrs["axis_names"]]
            fixed = {k[len("fixed_"):]: float(v) for k, v in f.attrs.items() if k.startswith("fixed_")}
            samples = {n: f[n][()] for n in axes}
            self.data = {n: f[n][()] for n in ("wall_bounces", "outcome")}
        samples.update({n: np.array([v]) for n, v in fixed.items()})
        self.mesh = [samples[n] for n in MESH_ORDER]  # Z, Y, X
        self.shape = tuple(len(s) for s in self.mesh)
        # The mesh has the data's points in the data's order: only thin dimensions are added.
        self.values = {n: v.reshape(self.shape) for n, v in self.data.items()}


class ParaView(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        for tool in ("xvfb-run", "pvbatch", "xauth"):
            if not shutil.which(tool):  # a failure, not a skip: the test command installs them
                raise AssertionError(f"{tool} not found; install the clients with .ci/install-deps --clients")
        cls.dir = tempfile.mkdtemp(prefix="superball-paraview-")
        cls.results = client_results(cls.dir, ["slice", "volume"], NAMES)
        cls.expected = {kind: Expected(path) for kind, path in cls.results.items()}

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.dir, ignore_errors=True)

    def pvbatch(self, cases, cwd, ranks=1):
        """Runs tests/paraview/pv_read.py on `cases` from `cwd`; its output per rank."""
        spec = os.path.join(self.dir, "spec.json")
        out = os.path.join(self.dir, "out.json")
        with open(spec, "w") as f:
            json.dump({"cases": cases}, f)
        script = os.path.join(HERE, "pv_read.py")
        # Debian's ParaView has no offscreen rendering: a virtual X server.
        if ranks == 1:
            cmd = ["xvfb-run", "-a", "pvbatch", script, spec, out]
        else:
            mpiexec = os.environ.get("MPIEXEC") or "mpirun"
            cmd = ["xvfb-run", "-a", mpiexec, "-n", str(ranks), "--oversubscribe", "pvbatch", "--symmetric",
                   script, spec, out]
        r = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, env=mpi_env(), timeout=300)
        output = r.stdout + r.stderr
        self.assertEqual(r.returncode, 0, output)
        self.assertFalse([line for line in output.splitlines() if any(m in line for m in FAILURE_MARKS)], output)
        paths = [out] if ranks == 1 else [f"{out}.{rank}" for rank in range(ranks)]
        pieces = []
        for path in paths:
            with open(path) as f:
                pieces.append(json.load(f))
            os.remove(path)
        return pieces[0] if ranks == 1 else pieces

    def between_planes(self, kind):
        """A plane normal to Z (xi) halfway between two samples, and the sample index below it."""
        xi = self.expected[kind].mesh[0]
        k = len(xi) // 2 - 1
        return k, {"origin": [0.0, 0.0, float(xi[k] + xi[k + 1]) / 2], "normal": [0.0, 0.0, 1.0]}

    def check_grid(self, got, kind, label):
        exp = self.expected[kind]
        nz, ny, nx = exp.shape
        self.assertEqual(got["class"], "vtkRectilinearGrid", label)
        self.assertEqual(got["extent"], [0, nx - 1, 0, ny - 1, 0, nz - 1], label)
        for axis, (coords, samples) in enumerate(zip(got["coordinates"], reversed(exp.mesh))):
            np.testing.assert_array_equal(coords, samples, f"{label}: coordinates of axis {'XYZ'[axis]}")
        z, y, x = exp.mesh
        self.assertEqual(got["bounds"], [x[0], x[-1], y[0], y[-1], z[0], z[-1]], label)
        self.assertEqual(sorted(got["arrays"]), ["outcome", "wall_bounces"], label)
        for name in ("wall_bounces", "outcome"):
            array = got["arrays"][name]
            self.assertEqual(array["type"], "int", f"{label}: {name} must be signed (interpolation)")
            np.testing.assert_array_equal(np.array(array["values"]).reshape(exp.shape), exp.values[name],
                                          f"{label}: {name}")

    def check_slice(self, got, kind, k, label):
        """Every point of the cut lies on a grid line between planes k and k + 1 of Z; its
        values lie between the two samples it interpolates."""
        exp = self.expected[kind]
        z, y, x = exp.mesh
        points = np.array(got["points"])
        _, ny, nx = exp.shape
        self.assertEqual(len(points), ny * nx, label)
        # the cut's points are single precision
        np.testing.assert_allclose(points[:, 2], (z[k] + z[k + 1]) / 2, rtol=1e-6)
        j = np.abs(points[:, 1, None] - y[None, :]).argmin(axis=1)
        i = np.abs(points[:, 0, None] - x[None, :]).argmin(axis=1)
        np.testing.assert_allclose(y[j], points[:, 1], rtol=1e-6)
        np.testing.assert_allclose(x[i], points[:, 0], rtol=1e-6)
        self.assertEqual(len(set(zip(j, i))), ny * nx, f"{label}: every grid line cut once")
        for name in ("wall_bounces", "outcome"):
            values = np.array(got["arrays"][name]["values"])
            below, above = exp.values[name][k, j, i], exp.values[name][k + 1, j, i]
            low, high = np.minimum(below, above), np.maximum(below, above)
            outside = (values < low) | (values > high)
            self.assertFalse(outside.any(), f"{label}: {name} {values[outside][:5]} outside "
                                            f"[{low[outside][:5]}, {high[outside][:5]}]")
            self.assertGreaterEqual(values.min(), exp.data[name].min(), label)
            self.assertLessEqual(values.max(), exp.data[name].max(), label)
            # the plane is not on a sample: some values really are interpolated
            if name == "wall_bounces":
                self.assertTrue((below != above).any(), f"{label}: planes {k} and {k + 1} equal: choose others")

    def test_absolute_path_from_another_directory(self):
        elsewhere = os.path.join(self.dir, "elsewhere")
        os.makedirs(elsewhere, exist_ok=True)
        cases, labels = [], []
        for kind, path in self.results.items():
            k, plane = self.between_planes(kind)
            for reader in READERS:
                cases.append({"file": sidecar(path), "reader": reader, "slice": plane})
                labels.append((kind, reader, k))
        for (kind, reader, k), got in zip(labels, self.pvbatch(cases, elsewhere)):
            label = f"{kind} with {reader}"
            self.check_grid(got, kind, label)
            self.check_slice(got["slice"], kind, k, label)

    def test_relative_name_from_its_directory(self):
        """./NAME.xmf with every reader and OpenDataFile (which picks Xdmf3ReaderS); a bare
        NAME.xmf with the legacy reader (the Xdmf3 readers look for the data file in a
        directory named NAME.xmf and abort pvpython: docs/format.md)."""
        cases, labels = [], []
        for kind, path in self.results.items():
            name = os.path.basename(sidecar(path))
            for reader in READERS + ("OpenDataFile",):
                cases.append({"file": "./" + name, "reader": reader})
                labels.append((kind, reader))
            cases.append({"file": name, "reader": "XDMFReader"})
            labels.append((kind, "XDMFReader, bare name"))
        for (kind, reader), got in zip(labels, self.pvbatch(cases, self.dir)):
            self.check_grid(got, kind, f"{kind} with {reader} from ./")

    def test_volume_in_pieces(self):
        """Two pvbatch ranks: each reads its piece of the volume (the legacy reader reads a
        hyperslab per piece; the Xdmf3 readers read the whole grid on every rank)."""
        exp = self.expected["volume"]
        cases = [{"file": sidecar(self.results["volume"]), "reader": r} for r in ("XDMFReader", "Xdmf3ReaderS")]
        pieces = self.pvbatch(cases, self.dir, ranks=2)
        for c, case in enumerate(cases):
            covered = np.zeros(exp.shape, bool)
            for rank, results in enumerate(pieces):
                got = results[c]
                x0, x1, y0, y1, z0, z1 = got["extent"]
                box = (slice(z0, z1 + 1), slice(y0, y1 + 1), slice(x0, x1 + 1))
                shape = (z1 - z0 + 1, y1 - y0 + 1, x1 - x0 + 1)
                for name in ("wall_bounces", "outcome"):
                    np.testing.assert_array_equal(np.array(got["arrays"][name]["values"]).reshape(shape),
                                                  exp.values[name][box], f"{case['reader']} rank {rank}: {name}")
                covered[box] = True
            self.assertTrue(covered.all(), case["reader"])
            if case["reader"] == "XDMFReader":  # really in pieces
                self.assertLess(np.prod([r[c]["extent"][5] - r[c]["extent"][4] + 1 for r in pieces[:1]]),
                                exp.shape[0])

    def test_sidecar_escapes_the_file_name(self):
        with open(sidecar(self.results["slice"])) as f:
            text = f.read()
        self.assertIn("slice &amp; &lt;co&gt;&apos;s &quot;1&quot;.h5:/xi", text)
        self.assertNotIn(os.path.dirname(self.results["slice"]), text)  # the bare name: the pair can move

    def test_no_sidecar_where_xdmf_cannot_name_the_result(self):
        """A colon in the file name (XDMF's FILE:PATH cannot escape it: the legacy reader
        splits the name, the Xdmf3 readers abort pvpython), or a result named .xmf (its
        sidecar would overwrite it): the result, and no sidecar."""
        where = os.path.join(self.dir, "unnamed")
        os.makedirs(where, exist_ok=True)
        paths = client_results(where, ["slice"], {"slice": "run:2.h5"})
        self.assertTrue(h5py.is_hdf5(paths["slice"]))
        self.assertFalse(os.path.exists(sidecar(paths["slice"])))
        paths = client_results(where, ["slice"], {"slice": "slice.xmf"})
        self.assertTrue(h5py.is_hdf5(paths["slice"]))


if __name__ == "__main__":
    superball_testing_main()
