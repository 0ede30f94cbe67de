#!/usr/bin/python3
"""Many writers (`explore --writers`, `[run] writers`) end to end under mpirun: with 8 ranks
in pseudo-nodes of 2 (--node-ranks 2) and 4 writers, the result's tiles are written by 4
processes (counted with strace, tests/scale/write_calls.sh) and its datasets equal one
rank's; a writer rank, or rank 0, killed with SIGKILL mid-run, then --resume, gives the
same datasets; a count above the nodes is capped and said; bad counts are refused."""
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time

import h5py
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from superball_testing import main as superball_testing_main  # noqa: E402
from superball_testing import (ExploreCase, descendants, killable_job, mpi_env, rank_of, running_journal,  # noqa: E402
                               wall_impacts_per_second)

SUPERBALL = os.environ.get("SUPERBALL", "superball")
MPIEXEC = os.environ.get("MPIEXEC") or "mpirun"
WRITE_CALLS = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "scale", "write_calls.sh")

JOB = """[model]
e = 0.9
alpha = 0.9

[grid]
xi = { min = 0.0, max = 1.0, n = 300 }
U = -1.0
W = { min = -3.0, max = 3.0, n = 200 }

[run]
max_bounces = 1000
tile_points = 256
alignment = 4096
"""


def datasets(path):
    with h5py.File(path, "r") as f:
        return f["wall_bounces"][()], f["outcome"][()]


class Writers(ExploreCase):
    prefix = "superball-writers-"
    killable = None  # (job, its uninterrupted result), made once for both kill tests

    @classmethod
    def tearDownClass(cls):
        if cls.killable is not None:
            shutil.rmtree(os.path.dirname(cls.killable[0]), ignore_errors=True)

    def killable_and_straight(self):
        """A job of about 2.5 s on 2 ranks and its result left alone, made on first use: the
        binary's speed measured and the straight run made once, not once a kill test."""
        if Writers.killable is None:
            shared = tempfile.mkdtemp(prefix="superball-writers-shared-")
            job = os.path.join(shared, "kill.toml")
            with open(job, "w") as f:
                f.write(killable_job(wall_impacts_per_second(SUPERBALL, shared), 2.5))
            straight = os.path.join(shared, "straight.h5")
            self.explore(job, straight, 2)
            Writers.killable = (job, straight)
        return Writers.killable

    def assert_same(self, a, b):
        for x, y in zip(datasets(a), datasets(b)):
            np.testing.assert_array_equal(x, y)

    def test_four_writers_write_from_four_processes(self):
        if shutil.which("strace") is None:
            self.skipTest("strace is missing (.ci/install-deps --bench installs it)")
        job = self.write_job(JOB)
        one = self.path("one.h5")
        self.explore(job, one, 1)
        for writers, processes in (("4", 4), ("2", 2), ("auto", 1)):
            with self.subTest(writers=writers):
                out = self.path(f"w{writers}.h5")
                r = self.explore(job, out, 8, ["--node-ranks", "2", "--writers", writers, "--stats"],
                                 wrap=(WRITE_CALLS, os.path.basename(out), "--"))
                m = re.search(r"writing_processes=(\d+)", r.stdout)
                self.assertIsNotNone(m, r.stdout)
                self.assertEqual(int(m.group(1)), processes, r.stdout)
                self.assertIn(f"writers={processes} ", r.stderr)
                self.assert_same(one, out)

    def test_more_writers_than_nodes_are_capped_and_said(self):
        job = self.write_job(JOB)
        out = self.path("capped.h5")
        cmd = [MPIEXEC, "-n", "4", "--oversubscribe", SUPERBALL, "explore", job, "-o", out, "--node-ranks", "2",
               "--writers", "5", "--stats"]
        r = subprocess.run(cmd, capture_output=True, text=True, env=mpi_env(), timeout=300)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("5 writers asked, 2 write", r.stderr)
        self.assertIn("writers=2 ", r.stderr)

    def test_bad_writer_counts_are_refused(self):
        for extra, text, key in ((["--writers", "0"], JOB, "--writers"), (["--writers", "many"], JOB, "--writers"),
                                 ([], JOB + "writers = 0\n", "[run] writers"),
                                 ([], JOB + 'writers = "all"\n', "[run] writers")):
            with self.subTest(extra=extra, key=key):
                job = self.write_job(text, "bad.toml")
                out = self.path("bad.h5")
                r = subprocess.run([SUPERBALL, "explore", job, "-o", out, *extra], capture_output=True, text=True,
                                   env=mpi_env(), timeout=60)
                self.assertEqual(r.returncode, 2, r.stderr)
                self.assertIn(key, r.stderr)
                self.assertIn("auto", r.stderr)
                self.assertFalse(os.path.exists(out) or os.path.exists(out + ".partial"))
        job = self.write_job(JOB + 'writers = "auto"\n', "auto.toml")
        r = subprocess.run([SUPERBALL, "explore", job, "-o", self.path("dry.h5"), "--dry-run", "--writers", "3"],
                           capture_output=True, text=True, env=mpi_env(), timeout=60)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("writers: 3 ", r.stdout)

    def kill_mid_run(self, rank):
        """A run of 8 ranks, 4 writers, killed (SIGKILL to rank `rank`) once a fifth of its
        tiles are recorded; --resume then equals a run left alone."""
        job, straight = self.killable_and_straight()
        out = self.path(f"killed{rank}.h5")
        partial = out + ".partial"
        flags = ["--node-ranks", "2", "--writers", "4"]
        proc = subprocess.Popen([MPIEXEC, "-n", "8", "--oversubscribe", SUPERBALL, "explore", job, "-o", out, "-q", *flags],
                                env=mpi_env(), start_new_session=True, stdout=subprocess.DEVNULL,
                                stderr=subprocess.DEVNULL)
        done, deadline = 0, time.time() + 120
        while time.time() < deadline and proc.poll() is None:
            time.sleep(0.02)
            journal = running_journal(partial)
            if journal is not None and journal.sum() >= journal.size // 5:
                done = int(journal.sum())
                break
        self.assertIsNone(proc.poll(), "the run finished before it could be killed: make the grid larger")
        victims = [pid for pid in descendants(proc.pid) if rank_of(pid) == rank]
        self.assertEqual(len(victims), 1, f"rank {rank} not found among mpirun's processes")
        os.kill(victims[0], signal.SIGKILL)
        proc.wait(timeout=120)
        self.assertNotEqual(proc.returncode, 0)
        self.assertGreater(done, 0)
        self.assertFalse(os.path.exists(out))
        with h5py.File(partial, "r") as f:
            self.assertLess(int(f["progress/tile_done"][()].sum()), f["progress/tile_done"].size)
        self.explore(job, out, 8, ["--resume", *flags])
        self.assertFalse(os.path.exists(partial))
        self.assert_same(out, straight)

    def test_writer_killed_then_resumed(self):
        self.kill_mid_run(2)  # the leader of the second pseudo-node, a writer

    def test_rank_0_killed_then_resumed(self):
        self.kill_mid_run(0)


if __name__ == "__main__":
    superball_testing_main()
