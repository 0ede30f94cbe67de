#!/usr/bin/python3
"""The datasets of the quickstart job and of a 3-D job (jobs/quick/volume.toml), compressed
and not, are what they were before the restructuring of issue 24 ("a house the next engineer
can live in"): their values' SHA-256 digests equal those recorded in dataset_digests.json,
made with the binary of commit 4397c2b (the last before it):

  /usr/bin/python3 tests/explore/test_datasets_unchanged.py --record OLD_BINARY

Compared are the values (counts as unsigned 32-bit, outcomes as unsigned 8-bit, coordinates
as float64, little-endian) and the shapes, not the files' bytes: provenance, times and the
HDF5 layout may differ. Every kernel variant computes the same values, so the digests hold
on any processor.

Run by ctest (SUPERBALL = the built binary, SUPERBALL_SOURCE_DIR = the repository), or by hand:
  SUPERBALL=build/release/src/superball /usr/bin/python3 tests/explore/test_datasets_unchanged.py -v
"""
import hashlib
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
from superball_testing import SOURCE, mpi_env, superball_binary  # noqa: E402

DIGESTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "dataset_digests.json")
MPIEXEC = os.environ.get("MPIEXEC") or "mpirun"
# name: (job file in the repository, lines added to its [run] table)
RUNS = {
    "quickstart": ("jobs/quickstart.toml", []),
    "volume": ("jobs/quick/volume.toml", []),
    "volume_uncompressed": ("jobs/quick/volume.toml", ["compression = 0"]),
}


def digests_of(path):
    """{variable: {"shape": [...], "sha256": hex}} of a result's data and coordinates."""
    out = {}
    with h5py.File(path, "r") as f:
        names = ["wall_bounces", "outcome"] + [n.decode() if isinstance(n, bytes) else str(n) for n in f.attrs["axis_names"]]
        for name in names:
            values = f[name][()]
            dtype = {"wall_bounces": "<u4", "outcome": "<u1"}.get(name, "<f8")
            data = np.ascontiguousarray(values.astype(dtype))
            out[name] = {"shape": list(values.shape), "sha256": hashlib.sha256(data.tobytes()).hexdigest()}
    return out


def explore(binary, directory, name):
    job, lines = RUNS[name]
    with open(os.path.join(SOURCE, job)) as f:
        text = f.read()
    if lines:
        assert "\n[run]\n" in text, f"{job} has no [run] table"
        text = text.replace("\n[run]\n", "\n[run]\n" + "".join(line + "\n" for line in lines), 1)
    job_path = os.path.join(directory, name + ".toml")
    with open(job_path, "w") as f:
        f.write(text)
    output = os.path.join(directory, name + ".h5")
    cmd = [MPIEXEC, "-n", "2", "--oversubscribe", binary, "explore", job_path, "-o", output, "-q"]
    r = subprocess.run(cmd, capture_output=True, text=True, env=mpi_env(), timeout=600)
    if r.returncode != 0:
        raise AssertionError(f"{' '.join(cmd)} exited {r.returncode}:\n{r.stderr}")
    return output


class DatasetsUnchanged(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.binary = superball_binary()
        cls.dir = tempfile.mkdtemp(prefix="superball-unchanged-")
        with open(DIGESTS) as f:
            cls.recorded = json.load(f)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.dir, ignore_errors=True)

    def test_every_run_is_recorded(self):
        self.assertEqual(sorted(self.recorded["runs"]), sorted(RUNS))

    def check(self, name):
        got = digests_of(explore(self.binary, self.dir, name))
        self.assertEqual(got, self.recorded["runs"][name], f"{name}: the datasets differ from those of "
                                                             f"{self.recorded['binary']}")

    def test_quickstart(self):
        self.check("quickstart")

    def test_volume(self):
        self.check("volume")

    def test_volume_uncompressed(self):
        self.check("volume_uncompressed")


def record(binary):
    """Writes dataset_digests.json from `binary`'s results."""
    directory = tempfile.mkdtemp(prefix="superball-record-")
    try:
        version = subprocess.run([binary, "--version"], capture_output=True, text=True).stdout.splitlines()[0]
        commit = subprocess.run(["git", "-C", SOURCE, "rev-parse", "--short", "HEAD"], capture_output=True,
                                text=True).stdout.strip()
        runs = {name: digests_of(explore(binary, directory, name)) for name in RUNS}
        with open(DIGESTS, "w") as f:
            json.dump({"binary": f"{version} (recorded from a build of commit {os.environ.get('RECORDED_COMMIT', commit)})",
                       "runs": runs}, f, indent=1, sort_keys=True)
            f.write("\n")
    finally:
        shutil.rmtree(directory, ignore_errors=True)


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "--record":
        record(os.path.abspath(sys.argv[2]))
    else:
        superball_testing_main()
