#!/usr/bin/python3
"""Signals to a running `mpirun -n 2 superball explore`, as a batch system or a user sends
them: every time the job ends, the file left behind is consistent (complete = 0, every
tile marked done holds exactly the data of an uninterrupted run) and `--resume` completes
it into a file identical to an uninterrupted run.

While a run goes on, its tiles and the journal of those done are in OUTPUT.partial; the
result takes its name OUTPUT only once complete.

(a) SIGTERM to every rank (what Slurm does at a time limit): clean stop, non-zero status,
    stderr says how to resume.
(b) SIGINT to rank 0 only (Ctrl-C on one process): rank 0 stops handing out tiles, the
    workers finish theirs, clean stop.
(c) a second signal while tiles are still being computed: every rank ends at once
    (status 128 + signal), no clean-stop summary, still resumable.
(d) SIGKILL of a worker rank only: mpirun aborts the others; resumable.
(e) SIGTERM (or SIGINT) to mpirun itself: Open MPI 4.1 sends every rank SIGCONT at
    once, SIGTERM a second later (a clean stop starts) and SIGKILL a second after that
    (odls_base_sigkill_timeout = 1): tiles in flight longer than that are lost, the
    resume hint may not be printed, mpirun exits 1, no rank outlives it, and the file is
    resumable. (For a clean stop, signal the ranks: Slurm's SIGTERM reaches every task;
    mpirun forwards SIGUSR1/SIGUSR2 to the ranks at once, which stop on them too.)

Environment: SUPERBALL (the binary), MPIEXEC (mpirun)."""
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import unittest

import h5py  # noqa: E402
import numpy as np  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from superball_testing import main as superball_testing_main  # noqa: E402
from superball_testing import (capped_job, descendants, killable_job, mpi_env, rank_of, read_partial,  # noqa: E402
                               running_journal, superball_binary, tile_boxes, wall_impacts_per_second)

MPIEXEC = os.environ.get("MPIEXEC") or "mpirun"


def signal_env():
    """mpi_env() with Open MPI's own second between the SIGTERM and the SIGKILL with which
    mpirun ends the ranks (ctest sets it to 0 for the other tests: tests/CMakeLists.txt)."""
    return {**mpi_env(), "OMPI_MCA_odls_base_sigkill_timeout": "1"}

# The jobs' max_bounces are set from the speed of the binary under test
# (wall_impacts_per_second), so that the runs last the same few seconds in a release build
# and under AddressSanitizer: MEDIUM (killable_job) about 2 s on two ranks; LONG
# (capped_job, 8 tiles of 100 capped points) about a second a tile.
MEDIUM_SECONDS = 2.0
TILE_SECONDS = 1.0


def alive(pid):
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


class Signals(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.binary = superball_binary()
        cls.dir = tempfile.mkdtemp(prefix="superball-signals-")
        cls.references = {}
        speed = wall_impacts_per_second(cls.binary, cls.dir)
        print(f"calibrated: {speed:.3g} wall impacts per second", file=sys.stderr)
        # MEDIUM: about 11000 of its 90000 points are capped; LONG: 100 capped points a tile.
        cls.jobs = {"medium": killable_job(speed, MEDIUM_SECONDS),
                    "long": capped_job(max(1000, int(TILE_SECONDS * speed / 100)), n_xi=20, n_W=40, tile_points=100)}

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.dir, ignore_errors=True)

    def path(self, name):
        return os.path.join(self.dir, name)

    def job(self, name):
        path = self.path(name + ".toml")
        if not os.path.exists(path):
            with open(path, "w") as f:
                f.write(self.jobs[name])
        return path

    def explore(self, job, output, *extra, expect=0):
        cmd = [MPIEXEC, "-n", "2", "--oversubscribe", self.binary, "explore", job, "-o", output, "-q", *extra]
        r = subprocess.run(cmd, capture_output=True, text=True, env=signal_env(), timeout=600)
        self.assertEqual(r.returncode, expect, f"{' '.join(cmd)}\n{r.stderr}")
        return r

    def reference(self, job):
        """An uninterrupted run of `job` (once per job)."""
        if job not in self.references:
            out = self.path(os.path.basename(job) + ".reference.h5")
            self.explore(job, out)
            with h5py.File(out, "r") as f:
                self.references[job] = (f["wall_bounces"][()], f["outcome"][()])
        return self.references[job]

    def start(self, job, output):
        """mpirun in a session of its own; its stderr goes to a file (no pipe to fill)."""
        self.stderr_path = output + ".stderr"
        stderr = open(self.stderr_path, "w")
        cmd = [MPIEXEC, "-n", "2", "--oversubscribe", self.binary, "explore", job, "-o", output, "-q"]
        proc = subprocess.Popen(cmd, env=signal_env(), start_new_session=True, stdout=subprocess.DEVNULL, stderr=stderr)
        stderr.close()
        return proc

    def ranks(self, proc):
        """{rank: pid} of the two ranks below mpirun, once both are up."""
        deadline = time.time() + 60
        while time.time() < deadline:
            found = {}
            for pid in descendants(proc.pid):
                r = rank_of(pid)
                if r is not None:
                    found[r] = pid
            if len(found) == 2:
                return found
            self.assertIsNone(proc.poll(), "mpirun ended before its ranks were seen")
            time.sleep(0.02)
        self.fail("the ranks did not start")

    def wait_for_tiles(self, proc, output, fraction):
        """Until at least `fraction` of the tiles (and at least one) are recorded done."""
        deadline = time.time() + 300
        while time.time() < deadline:
            if proc.poll() is not None:
                with open(self.stderr_path) as f:
                    self.fail(f"the run ended (status {proc.returncode}) before it could be interrupted:\n{f.read()}")
            done = running_journal(output + ".partial")
            if done is not None and done.sum() >= max(1, fraction * done.size):
                return int(done.sum())
            time.sleep(0.05)
        self.fail("no progress")

    def finish(self, proc, ranks):
        """Waits for mpirun; returns (status, stderr) after checking no rank outlived it."""
        status = proc.wait(timeout=300)
        deadline = time.time() + 10
        while any(alive(pid) for pid in ranks.values()) and time.time() < deadline:
            time.sleep(0.05)
        self.assertFalse([pid for pid in ranks.values() if alive(pid)], "a rank outlived mpirun")
        with open(self.stderr_path) as f:
            return status, f.read()

    def assert_consistent_and_resumable(self, job, output):
        """No result yet; the partial file: complete = 0, each tile recorded done holds the
        reference's data; --resume then completes the run, identical to the reference."""
        wb_ref, oc_ref = self.reference(job)
        self.assertFalse(os.path.exists(output), "an interrupted run under the result's name")
        with h5py.File(output + ".partial", "r") as f:
            self.assertEqual(f.attrs["complete"], 0)
            done = f["progress/tile_done"][()]
            self.assertTrue(set(np.unique(done)) <= {0, 1})
            self.assertLess(int(done.sum()), done.size, "every tile done: nothing was interrupted")
            wb, oc, _ = read_partial(output + ".partial")
            tile_shape = [int(n) for n in f.attrs["tile_shape"]]
            for t, box in enumerate(tile_boxes(wb.shape, tile_shape)):
                if done[t]:
                    np.testing.assert_array_equal(wb[box], wb_ref[box], f"tile {t}")
                    np.testing.assert_array_equal(oc[box], oc_ref[box], f"tile {t}")
        # Without --resume an interrupted run is left alone.
        r = self.explore(job, output, expect=2)
        self.assertIn("--resume", r.stderr)
        self.explore(job, output, "--resume")
        self.assertFalse(os.path.exists(output + ".partial"))
        with h5py.File(output, "r") as f:
            self.assertEqual(f.attrs["complete"], 1)
            np.testing.assert_array_equal(f["wall_bounces"][()], wb_ref)
            np.testing.assert_array_equal(f["outcome"][()], oc_ref)

    def test_a_sigterm_to_every_rank(self):
        job, out = self.job("medium"), self.path("a.h5")
        self.reference(job)
        proc = self.start(job, out)
        ranks = self.ranks(proc)
        self.wait_for_tiles(proc, out, 0.1)
        for pid in ranks.values():
            os.kill(pid, signal.SIGTERM)
        status, stderr = self.finish(proc, ranks)
        self.assertNotEqual(status, 0, stderr)
        self.assertIn("stopped by a signal", stderr)
        self.assertIn("--resume", stderr)
        self.assertIn("interrupted:", stderr)  # the summary of a clean stop
        self.assert_consistent_and_resumable(job, out)

    def test_b_sigint_to_rank_0_only(self):
        job, out = self.job("medium"), self.path("b.h5")
        self.reference(job)
        proc = self.start(job, out)
        ranks = self.ranks(proc)
        self.wait_for_tiles(proc, out, 0.1)
        os.kill(ranks[0], signal.SIGINT)
        status, stderr = self.finish(proc, ranks)
        self.assertNotEqual(status, 0, stderr)
        self.assertIn("stopped by a signal", stderr)
        self.assertIn("--resume", stderr)
        self.assert_consistent_and_resumable(job, out)

    def test_c_second_signal_stops_at_once(self):
        job, out = self.job("long"), self.path("c.h5")
        self.reference(job)
        proc = self.start(job, out)
        ranks = self.ranks(proc)
        # Right after the first tiles, both ranks are just into their next ones.
        self.wait_for_tiles(proc, out, 0.0)
        for pid in ranks.values():
            os.kill(pid, signal.SIGTERM)
        time.sleep(0.05)
        for pid in ranks.values():
            os.kill(pid, signal.SIGTERM)
        status, stderr = self.finish(proc, ranks)
        self.assertEqual(status, 128 + signal.SIGTERM, stderr)
        self.assertIn("second signal, stopping now", stderr)
        self.assertNotIn("interrupted:", stderr)  # no clean stop: the tiles in flight were dropped
        self.assert_consistent_and_resumable(job, out)

    def test_d_sigkill_of_a_worker(self):
        job, out = self.job("medium"), self.path("d.h5")
        self.reference(job)
        proc = self.start(job, out)
        ranks = self.ranks(proc)
        self.wait_for_tiles(proc, out, 0.1)
        os.kill(ranks[1], signal.SIGKILL)
        status, stderr = self.finish(proc, ranks)  # mpirun ends rank 0 too
        self.assertNotEqual(status, 0, stderr)
        self.assert_consistent_and_resumable(job, out)

    def test_e_sigterm_to_mpirun(self):
        # Long tiles: more work left than Open MPI's two-second grace can finish.
        job, out = self.job("long"), self.path("e.h5")
        self.reference(job)
        proc = self.start(job, out)
        ranks = self.ranks(proc)
        self.wait_for_tiles(proc, out, 0.0)
        os.kill(proc.pid, signal.SIGTERM)
        started = time.time()
        status, stderr = self.finish(proc, ranks)
        # SIGCONT at once, SIGTERM a second later, SIGKILL a second after that.
        self.assertLess(time.time() - started, 30)
        self.assertNotEqual(status, 0, stderr)
        self.assert_consistent_and_resumable(job, out)


if __name__ == "__main__":
    superball_testing_main()
