#!/usr/bin/python3
"""jobs/slurm/explore.sbatch on a real one-node Slurm cluster started on this machine
(tests/launchers/slurm_cluster.sh): a small job completes; a job stopped by SIGTERM leaves an
incomplete, resumable file that a resubmission finishes, whose rows are those of direct runs.

Run by ctest (SUPERBALL = the built binary, SUPERBALL_SOURCE_DIR = the repository), or by hand:
  SUPERBALL=build/release/src/superball /usr/bin/python3 tests/launchers/test_slurm.py -v
Skipped only when Slurm cannot run here (not root, packages cannot be installed). The cluster
is stopped at the end when this test started it; SUPERBALL_KEEP_SLURM=1 keeps it running.
"""

import os
import re
import subprocess
import sys
import tempfile
import time
import unittest

import h5py
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from superball_testing import main as superball_testing_main  # noqa: E402
from superball_testing import superball_binary, wall_impacts_per_second  # noqa: E402

SOURCE = os.path.abspath(os.environ.get("SUPERBALL_SOURCE_DIR") or os.path.join(os.path.dirname(__file__), "..", ".."))
CLUSTER = os.path.join(SOURCE, "tests", "launchers", "slurm_cluster.sh")
SBATCH_SCRIPT = os.path.join(SOURCE, "jobs", "slurm", "explore.sbatch")
TIMEOUT = 180  # seconds for any one job to start and end

TINY_JOB = """\
[model]
e = 0.9
alpha = 0.9

[grid]
coordinates = "canonical"
xi = { min = 0.0, max = 1.0, n = 48 }
U = -1.0
W = { min = -3.0, max = 3.0, n = 40 }

[run]
max_bounces = 1000
output = "out/tiny.h5"
"""

# Garwin's ball (e = alpha = 1) in a corner of launches that mostly never leave: nearly every
# point costs max_bounces iterations, set from the binary's measured speed
# (wall_impacts_per_second) so that two ranks take about `seconds`, spread over 64 tiles of a
# fraction of a second each (a stop request is honoured quickly). A fixed max_bounces made the
# job last 4 s with one kernel and 0.5 s with the AVX-512 one, too short to be stopped twice.
# 8 s: with 5 s, on a loaded machine (ctest -j2 beside other work, 2026-11-28), the first stop
# landed with 43 of the 64 tiles done, and the resubmitted run's 21 finished before the second.
def slow_job(speed, seconds=8.0):
    points = 256 * 256
    max_bounces = max(1000, int(2 * seconds * speed / points))
    return f"""\
[model]
e = 1.0
alpha = 1.0

[grid]
coordinates = "canonical"
xi = {{ min = 0.0, max = 0.1, n = 256 }}
U = -0.3
W = {{ min = -3.0, max = -2.5, n = 256 }}

[run]
max_bounces = {max_bounces}
tile_points = 1024
checkpoint_seconds = 0.2
output = "out/slow.h5"
"""


cluster_env = {}
started_here = False


def setUpModule():
    global started_here
    r = subprocess.run([CLUSTER, "start"], capture_output=True, text=True, timeout=600)
    if r.returncode == 3:
        raise unittest.SkipTest("Slurm cannot run on this machine: " + r.stderr.strip().splitlines()[-1])
    if r.returncode != 0:
        raise RuntimeError(f"{CLUSTER} start failed (exit status {r.returncode}):\n{r.stderr}")
    conf = re.search(r"^SLURM_CONF=(.*)$", r.stdout, re.M)
    if not conf:
        raise RuntimeError(f"{CLUSTER} start printed no SLURM_CONF:\n{r.stdout}{r.stderr}")
    started_here = "reusing" not in r.stderr
    cluster_env.update(os.environ)
    cluster_env.update(SLURM_CONF=conf.group(1), SUPERBALL=superball_binary())
    # The job must find its own way to mpirun's root permission (the script sets it when root).
    for var in ("OMPI_ALLOW_RUN_AS_ROOT", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "OMPI_MCA_rmaps_base_oversubscribe"):
        cluster_env.pop(var, None)


def tearDownModule():
    if started_here and os.environ.get("SUPERBALL_KEEP_SLURM") != "1":
        subprocess.run([CLUSTER, "stop"], capture_output=True, timeout=120)


def run(args, cwd, timeout=TIMEOUT, check=True):
    r = subprocess.run(args, cwd=cwd, env=cluster_env, capture_output=True, text=True, timeout=timeout)
    if check and r.returncode != 0:
        raise AssertionError(f"{' '.join(args)}: exit status {r.returncode}\n{r.stdout}{r.stderr}")
    return r


def job_fields(job_id):
    """JobState, ExitCode, ... of a job as scontrol shows it (there is no accounting: no sacct)."""
    out = run(["scontrol", "show", "job", "-o", str(job_id)], cwd="/").stdout
    return dict(re.findall(r"(\w+)=(\S*)", out))


def wait_for_end(job_id):
    deadline = time.monotonic() + TIMEOUT
    while time.monotonic() < deadline:
        state = job_fields(job_id).get("JobState", "")
        if state not in ("PENDING", "CONFIGURING", "RUNNING", "COMPLETING", "REQUEUED", "SUSPENDED"):
            return job_fields(job_id)
        time.sleep(0.2)
    raise AssertionError(f"job {job_id} did not end within {TIMEOUT} s")


def tiles_done(path):
    """Tiles recorded done by the run of a result (in its partial file; 0 while there is none
    yet), as `superball info` reports them."""
    if not os.path.exists(path) and not os.path.exists(path + ".partial"):
        return 0
    r = subprocess.run([superball_binary(), "info", path], capture_output=True, text=True, timeout=60)
    m = re.search(r"^complete: +\w+ \((\d+) of \d+ tiles done\)", r.stdout, re.M)
    return int(m.group(1)) if m else 0


def read_result(path):
    """The data and attributes of a result, or of its run's partial file (with the journal)
    while the run is not complete."""
    names = ["wall_bounces", "outcome", "xi", "W"]
    if not os.path.exists(path):
        path += ".partial"
        names.append("progress/tile_done")
    with h5py.File(path, "r") as f:
        return {name: f[name][...] for name in names}, dict(f.attrs)


class SlurmExplore(unittest.TestCase):
    def setUp(self):
        self._tmp = tempfile.TemporaryDirectory(prefix="superball-slurm-")
        self.tmp = self._tmp.name
        os.chmod(self.tmp, 0o755)

    def tearDown(self):
        self._tmp.cleanup()

    def write(self, name, text):
        with open(os.path.join(self.tmp, name), "w") as f:
            f.write(text)

    def log(self, job_id):
        try:
            with open(os.path.join(self.tmp, f"slurm-{job_id}.out")) as f:
                return f.read()
        except FileNotFoundError:
            return f"(no slurm-{job_id}.out)"

    def submit(self, job, *sbatch_options):
        """Submits explore.sbatch on JOB from the temporary directory; returns the job id."""
        r = run(["sbatch", "--parsable", "-n", "2", *sbatch_options, SBATCH_SCRIPT, job], cwd=self.tmp)
        return int(r.stdout.strip().split(";")[0])

    def submit_and_wait(self, job):
        r = run(["sbatch", "--parsable", "--wait", "-n", "2", SBATCH_SCRIPT, job], cwd=self.tmp, check=False)
        job_id = int(r.stdout.strip().splitlines()[0].split(";")[0])
        return r.returncode, job_id

    def interrupt(self, job, scancel_options, tiles_before):
        """Submits JOB, signals it once more tiles than TILES_BEFORE are on disk, waits for its end."""
        out = os.path.join(self.tmp, "out", "slow.h5")
        job_id = self.submit(job)
        deadline = time.monotonic() + TIMEOUT
        while tiles_done(out) <= tiles_before:
            state = job_fields(job_id).get("JobState")
            if state not in ("PENDING", "CONFIGURING", "RUNNING"):
                self.fail(f"job {job_id} ended ({state}) before it could be stopped:\n{self.log(job_id)}")
            self.assertLess(time.monotonic(), deadline, "no tile done in time")
            time.sleep(0.1)
        run(["scancel", *scancel_options, "--signal=TERM", str(job_id)], cwd=self.tmp)
        return job_id, wait_for_end(job_id)

    def test_small_job_completes(self):
        self.write("tiny.toml", TINY_JOB)
        status, job_id = self.submit_and_wait("tiny.toml")
        log = self.log(job_id)
        self.assertEqual(status, 0, log)
        fields = job_fields(job_id)
        self.assertEqual(fields["JobState"], "COMPLETED", log)
        self.assertEqual(fields["ExitCode"], "0:0")
        self.assertIn("explore.sbatch: done: out/tiny.h5", log)

        # The job's relative output lands in the submit directory, laid out as SPEC.md section 5.
        data, attrs = read_result(os.path.join(self.tmp, "out", "tiny.h5"))
        self.assertEqual(int(attrs["complete"]), 1)
        self.assertEqual(int(attrs["mpi_ranks"]), 2)
        self.assertEqual(data["wall_bounces"].shape, (48, 40))
        self.assertEqual(data["wall_bounces"].dtype, np.uint16)
        self.assertEqual(data["outcome"].shape, (48, 40))
        self.assertEqual(data["outcome"].dtype, np.uint8)
        self.assertFalse(os.path.exists(os.path.join(self.tmp, "out", "tiny.h5.partial")))
        self.assertTrue(np.all(np.isin(data["outcome"], (1, 2))), "every start valid, none capped")
        self.assertGreater(len(np.unique(data["wall_bounces"])), 3)

    def test_stopped_job_resumes_on_resubmission(self):
        slow_job_text = slow_job(wall_impacts_per_second(superball_binary(), self.tmp))
        self.write("slow.toml", slow_job_text)
        out = os.path.join(self.tmp, "out", "slow.h5")

        # Stopped the way the time limit does it (--signal=B:TERM: only the batch shell is
        # signalled, and the script passes SIGTERM on to the ranks).
        job_id, fields = self.interrupt("slow.toml", ["--batch"], 0)
        log = self.log(job_id)
        self.assertEqual((fields["JobState"], fields["ExitCode"]), ("FAILED", "1:0"), log)
        self.assertIn("stopped by a signal", log)
        self.assertIn("resubmit the same command to continue", log)
        data, attrs = read_result(out)
        self.assertEqual(int(attrs["complete"]), 0)
        first_stop = int(np.count_nonzero(data["progress/tile_done"]))
        self.assertTrue(0 < first_stop < data["progress/tile_done"].size, first_stop)
        info = run([superball_binary(), "info", out], cwd=self.tmp).stdout
        self.assertRegex(info, r"complete: +no \(\d+ of 64 tiles done\)")

        # Resubmitted, and stopped again as scancel --full does (every process of the job).
        job_id, fields = self.interrupt("slow.toml", ["--full"], first_stop)
        log = self.log(job_id)
        self.assertIn("adding --resume", log)
        self.assertIn(fields["JobState"], ("FAILED", "CANCELLED"), log)
        data, attrs = read_result(out)
        self.assertEqual(int(attrs["complete"]), 0)
        self.assertGreater(int(np.count_nonzero(data["progress/tile_done"])), first_stop)

        # Resubmitted once more: it finishes.
        status, job_id = self.submit_and_wait("slow.toml")
        log = self.log(job_id)
        self.assertEqual(status, 0, log)
        self.assertEqual(job_fields(job_id)["JobState"], "COMPLETED")
        self.assertIn("adding --resume", log)
        data, attrs = read_result(out)
        self.assertEqual(int(attrs["complete"]), 1)
        self.assertEqual(int(attrs["mpi_ranks"]), 2)

        # Same data as uninterrupted runs of its first, middle and last rows (a whole run takes
        # the 16 s of one core the three interrupted ones took together): each row is a job of
        # its own at that row's xi, as the file stores it (the same double, so the same launches).
        for i in (0, 127, 255):
            xi = float(data["xi"][i])
            self.write("row.toml", slow_job_text.replace("xi = { min = 0.0, max = 0.1, n = 256 }", f"xi = {xi!r}")
                       .replace('output = "out/slow.h5"', 'output = "row.h5"'))
            row = os.path.join(self.tmp, "row.h5")
            if os.path.exists(row):
                os.remove(row)
            subprocess.run([superball_binary(), "explore", "row.toml", "-q"], cwd=self.tmp, env=cluster_env, check=True,
                           capture_output=True, timeout=TIMEOUT)
            expected, _ = read_result(row)
            np.testing.assert_array_equal(expected["W"], data["W"])
            for name in ("wall_bounces", "outcome"):
                np.testing.assert_array_equal(data[name][i], expected[name].reshape(-1), err_msg=f"{name}, row {i}")

        # A further resubmission has nothing to do and succeeds.
        status, job_id = self.submit_and_wait("slow.toml")
        self.assertEqual(status, 0, self.log(job_id))
        self.assertIn("nothing to do", self.log(job_id))


if __name__ == "__main__":
    superball_testing_main()
