#!/usr/bin/python3
"""Faults around `superball explore` under mpirun: an output that cannot be written, a
disk that fills up mid-run, results truncated or corrupted on disk before --resume.
Every time: a clear message, the documented exit status (2: refused before anything
is written; 1: failure during the run), never a hang, never a file that claims
complete = 1 without being so, and never a resumed file that mixes in damaged data.

Some cases need root (a read-only bind mount, a small tmpfs); they are skipped when the
mount is not allowed. Environment: SUPERBALL (the binary), MPIEXEC (mpirun)."""
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
from superball_testing import interrupted_run, mpi_env, superball_binary  # noqa: E402

MPIEXEC = os.environ.get("MPIEXEC") or "mpirun"

SMALL_JOB = """[model]
e = 0.9
alpha = 0.9

[grid]
xi = { min = 0.0, max = 1.0, n = 200 }
U = -1.0
W = { min = -3.0, max = 3.0, n = 200 }

[run]
max_bounces = 1000
tile_points = 400
"""

# About 3 MB of results in 1024-point tiles.
# The journal every 10 ms, so that tiles are recorded done before the disk fills.
BIG_JOB = SMALL_JOB.replace("n = 200", "n = 1000").replace("tile_points = 400", "tile_points = 1024\ncheckpoint_seconds = 0.01").replace(
    "max_bounces = 1000", "max_bounces = 100")


def read_bytes(path):
    with open(path, "rb") as f:
        return f.read()


class Faults(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.binary = superball_binary()
        cls.dir = tempfile.mkdtemp(prefix="superball-faults-")
        cls.small = os.path.join(cls.dir, "small.toml")
        with open(cls.small, "w") as f:
            f.write(SMALL_JOB)
        cls.reference = os.path.join(cls.dir, "reference.h5")
        r = subprocess.run([MPIEXEC, "-n", "2", "--oversubscribe", cls.binary, "explore", cls.small, "-o", cls.reference,
                            "-q"], capture_output=True, text=True, env=mpi_env(), timeout=300)
        assert r.returncode == 0, r.stderr

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.dir, ignore_errors=True)

    def setUp(self):
        self.mounts = []

    def tearDown(self):
        for m in reversed(self.mounts):
            subprocess.run(["umount", m], capture_output=True)

    def path(self, name):
        return os.path.join(self.dir, name)

    def explore(self, job, output, *extra, ranks=2, expect=None, timeout=120):
        cmd = [MPIEXEC, "-n", str(ranks), "--oversubscribe", self.binary, "explore", job, "-o", output, "-q", *extra]
        r = subprocess.run(cmd, capture_output=True, text=True, env=mpi_env(), timeout=timeout)
        if expect is not None:
            self.assertEqual(r.returncode, expect, f"{' '.join(cmd)}\n{r.stderr}")
        return r

    def mount(self, *args):
        """Mounts as root, or skips the test."""
        target = args[-1]
        os.makedirs(target, exist_ok=True)
        r = subprocess.run(["mount", *args], capture_output=True, text=True)
        if r.returncode != 0:
            self.skipTest(f"cannot mount ({r.stderr.strip()}): needs root")
        self.mounts.append(target)

    def assert_refused(self, output, reason, *extra):
        """Exit status 2, one message naming the output and the reason, nothing written."""
        existed = os.path.exists(output)
        before = read_bytes(output) if existed and os.path.isfile(output) else None
        r = self.explore(self.small, output, *extra, expect=2)
        self.assertEqual(r.stderr.count("superball explore:"), 1, r.stderr)
        self.assertIn(output, r.stderr)
        self.assertIn(reason, r.stderr)
        self.assertNotIn("MPI_ABORT", r.stderr)
        if before is not None:
            self.assertEqual(read_bytes(output), before, "a refused run changed the file")
        elif not existed:
            self.assertFalse(os.path.exists(output))
        return r

    # --- Where the result cannot go -----------------------------------------------------

    def test_file_where_a_directory_is_expected(self):
        blocker = self.path("not-a-directory")
        open(blocker, "w").close()
        self.assert_refused(os.path.join(blocker, "out.h5"), "Not a directory")
        self.assert_refused(os.path.join(blocker, "sub", "out.h5"), "Not a directory")

    def test_directory_where_the_file_is_expected(self):
        target = self.path("a-directory.h5")
        os.makedirs(target, exist_ok=True)
        self.assert_refused(target, "is a directory")
        self.assert_refused(target, "is a directory", "--overwrite")

    def test_path_under_proc(self):
        self.assert_refused("/proc/superball-test.h5", "cannot write the result")

    def test_read_only_file_system(self):
        source, target = self.path("ro-source"), self.path("ro")
        os.makedirs(source, exist_ok=True)
        self.mount("--bind", source, target)
        r = subprocess.run(["mount", "-o", "remount,bind,ro", target], capture_output=True, text=True)
        if r.returncode != 0:
            self.skipTest(f"cannot remount read-only: {r.stderr.strip()}")
        self.assert_refused(os.path.join(target, "out.h5"), "Read-only file system")
        self.assert_refused(os.path.join(target, "sub", "out.h5"), "Read-only file system")

    # --- The disk fills up during the run ---------------------------------------------------

    def test_disk_full_mid_run(self):
        """Uncompressed, every rank writes its tiles (3 MB of them: a 1 MiB file system fills
        a third of the way); compressed, rank 0 writes them all, and the file system is
        given room for the file and half of its compressed tiles."""
        for compression in (0, 4):
            with self.subTest(compression=compression):
                self.disk_full_mid_run(compression)

    def disk_full_mid_run(self, compression):
        text = BIG_JOB.replace("[run]", f"[run]\ncompression = {compression}")
        job = self.path(f"big{compression}.toml")
        with open(job, "w") as f:
            f.write(text)
        reference = self.path(f"big-reference{compression}.h5")
        self.explore(job, reference, expect=0)
        size = "1M"
        if compression:
            empty = self.path(f"empty{compression}.h5")
            self.explore(job, empty, "--stop-after", "0", expect=1)
            start = os.path.getsize(empty + ".partial")
            size = str(-(-(start + (os.path.getsize(reference) - start) // 2) // 4096) * 4096)
        mnt = self.path(f"tmpfs{compression}")
        self.mount("-t", "tmpfs", "-o", f"size={size}", "tmpfs", mnt)
        out = os.path.join(mnt, "out.h5")
        # Before the fix the rank that failed to write waited for ever in the collective
        # close of the file while the other waited for its next tile: the timeout.
        r = self.explore(job, out, expect=1, timeout=120)
        self.assertIn("writing", r.stderr)
        self.assertIn(out + ".partial", r.stderr)
        self.assertIn("full", r.stderr)
        self.assertIn("--resume", r.stderr)
        self.assertNotIn("Segmentation fault", r.stderr)
        self.assertFalse(os.path.exists(out))  # no result, complete or not
        with h5py.File(out + ".partial", "r") as f:
            self.assertEqual(f.attrs["complete"], 0)
            done = f["progress/tile_done"][()]
            self.assertLess(done.sum(), done.size)
        # Room again: the resume checks the tiles recorded done and completes the run,
        # identical to a run that never failed.
        subprocess.run(["mount", "-o", "remount,size=16M", mnt], check=True)
        self.explore(job, out, "--resume", expect=0)
        with h5py.File(out, "r") as f, h5py.File(reference, "r") as g:
            self.assertEqual(f.attrs["complete"], 1)
            np.testing.assert_array_equal(f["wall_bounces"][()], g["wall_bounces"][()])
            np.testing.assert_array_equal(f["outcome"][()], g["outcome"][()])

    def test_disk_full_from_the_start(self):
        mnt = self.path("tmpfs-full")
        self.mount("-t", "tmpfs", "-o", "size=64k", "tmpfs", mnt)
        try:
            with open(os.path.join(mnt, "filler"), "wb") as f:
                while True:
                    f.write(b"\0" * 4096)
                    f.flush()
        except OSError:
            pass  # full
        out = os.path.join(mnt, "out.h5")
        r = self.explore(self.small, out, expect=1, timeout=120)
        self.assertIn("creating " + out + ".partial", r.stderr)
        self.assertEqual(r.stderr.count("superball explore"), 1, r.stderr)  # one message, not one per rank
        self.assertIn("full", r.stderr)
        if os.path.exists(out):  # whatever is left is not a result, let alone a complete one
            self.assertEqual(self.explore(self.small, out, "--resume").returncode, 2)

    # --- Damaged results and --resume -------------------------------------------------------

    def interrupted_copy(self, name):
        """The partial file an interrupted run of the small job leaves, every other tile done
        (taken from the reference result); returns the output path whose partial file it is."""
        out = self.path(name)
        for p in (out, out + ".partial"):
            if os.path.exists(p):
                os.remove(p)
        interrupted_run(self.binary, self.small, out, self.reference, lambda t: t % 2 == 0)
        return out

    def assert_resumed_identical(self, p):
        with h5py.File(p, "r") as f, h5py.File(self.reference, "r") as g:
            self.assertEqual(f.attrs["complete"], 1)
            np.testing.assert_array_equal(f["wall_bounces"][()], g["wall_bounces"][()])
            np.testing.assert_array_equal(f["outcome"][()], g["outcome"][()])

    def test_resume_of_an_undamaged_interrupted_file(self):
        out = self.interrupted_copy("intact.h5")
        self.explore(self.small, out, "--resume", expect=0)
        self.assert_resumed_identical(out)
        self.assertFalse(os.path.exists(out + ".partial"))

    def test_resume_refuses_a_truncated_file(self):
        for fraction in (0.5, 0.99):
            with self.subTest(fraction=fraction):
                out = self.interrupted_copy("truncated.h5")
                os.truncate(out + ".partial", int(os.path.getsize(out + ".partial") * fraction))
                self.assert_refused(out, "truncated", "--resume")

    def test_resume_refuses_a_damaged_done_tile(self):
        out = self.interrupted_copy("damaged.h5")
        partial = out + ".partial"
        with h5py.File(partial, "r") as f:
            offset = int(f["progress/tile_stored"][0][0])  # tile 0 is done: its compressed counts
        with open(partial, "r+b") as f:
            f.seek(offset + 10)
            f.write(b"\x07\x00")
        r = self.assert_refused(out, "damaged", "--resume")
        self.assertIn("tile 0", r.stderr)
        # The same file with every tile recorded done is refused too, rather than finished.
        with h5py.File(partial, "r+") as f:
            f["progress/tile_done"][...] = 1
        self.assert_refused(out, "damaged", "--resume")
        # A partial file that claims to be complete contradicts itself: refused as damaged.
        with h5py.File(partial, "r+") as f:
            f.attrs["complete"] = 1
        self.assert_refused(out, "contradicts", "--resume")
        # --overwrite starts again.
        self.explore(self.small, out, "--overwrite", expect=0)
        self.assert_resumed_identical(out)

    def test_resume_refuses_a_tile_marked_done_without_its_data(self):
        out = self.interrupted_copy("forged.h5")
        with h5py.File(out + ".partial", "r+") as f:
            # As if the done flag of tile 1 had reached the disk but not its data.
            f["progress/tile_done"][1] = 1
            f["progress/tile_checksum"][1] = 0
        self.assert_refused(out, "damaged", "--resume")

    def test_resume_never_mixes_in_overwritten_bytes(self):
        """Bytes overwritten anywhere in the partial file: the resume is refused with the
        file left as it is, or (the bytes were in a tile not yet done, or in space no
        object uses) it completes the run identical to an uninterrupted one. Never a mixture."""
        refused = 0
        # One interrupted file, copied before each damage (making it is a run and the
        # filling of half its tiles).
        out = self.interrupted_copy("overwritten.h5")
        partial = out + ".partial"
        intact = read_bytes(partial)
        for fraction in np.linspace(0.01, 0.99, 9):
            for leftover in (out, partial + ".undo"):  # a resumed run's result, a finish's undo log
                if os.path.exists(leftover):
                    os.remove(leftover)
            with open(partial, "wb") as f:
                f.write(intact)
            size = os.path.getsize(partial)
            with open(partial, "r+b") as f:
                f.seek(int(size * fraction))
                f.write(bytes((37 * i + 11) % 256 for i in range(16)))
            before = read_bytes(partial)
            r = self.explore(self.small, out, "--resume")
            with self.subTest(fraction=float(fraction)):
                if r.returncode == 0:
                    self.assert_resumed_identical(out)
                else:
                    refused += 1
                    self.assertEqual(r.returncode, 2, r.stderr)
                    self.assertNotIn("MPI_ABORT", r.stderr)
                    self.assertEqual(read_bytes(partial), before)
                    self.assertFalse(os.path.exists(out))
        self.assertGreater(refused, 0)  # some of them hit done tiles

    # --- Inputs that once went wrong --------------------------------------------------------

    def test_non_ascii_after_a_value_is_a_syntax_error(self):
        """toml++ 3.3.0 reaches TOML_UNREACHABLE on some non-ASCII characters after a value
        (marzer/tomlplusplus#190, #295; tests/fuzz/run.sh): the shipped binary must still
        report a syntax error."""
        for text in ("[run]\nmax_bounces = 1\u00e9\n", "[run]\nmax_bounces = 1\u0323\n", "[[[run]\n"):
            job = self.path("bad-toml.toml")
            with open(job, "w", encoding="utf-8") as f:
                f.write(text)
            r = subprocess.run([self.binary, "explore", job, "-o", self.path("never.h5")], capture_output=True,
                               text=True, env=mpi_env(), timeout=60)
            self.assertEqual(r.returncode, 2, r.stderr)
            self.assertIn("TOML syntax error", r.stderr)
            self.assertFalse(os.path.exists(self.path("never.h5")))

    def test_counts_above_65535_are_not_wrapped(self):
        """Near the marginally stable self-retracing motion of the elastic ball every launch
        is capped: at 70000 exactly, stored as uint32, not 70000 - 65536."""
        job = self.path("wide.toml")
        with open(job, "w") as f:
            f.write("[model]\ne = 1.0\nalpha = 1.0\n\n[grid]\nxi = { min = 0.2499, max = 0.2501, n = 3 }\nU = -0.5\n"
                    "W = -1.25\n\n[run]\nmax_bounces = 70000\n")
        out = self.path("wide.h5")
        self.explore(job, out, ranks=1, expect=0)
        with h5py.File(out, "r") as f:
            self.assertEqual(f["wall_bounces"].dtype, np.uint32)
            np.testing.assert_array_equal(f["wall_bounces"][()], [70000] * 3)
            np.testing.assert_array_equal(f["outcome"][()], [3] * 3)


if __name__ == "__main__":
    superball_testing_main()
