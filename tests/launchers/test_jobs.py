#!/usr/bin/python3
"""The job catalogue in jobs/: every quick and full job is valid, every quick job runs in
seconds to a complete result, and the launch scripts answer --help.

Run by ctest (SUPERBALL = the built binary, SUPERBALL_SOURCE_DIR = the repository), or by hand:
  SUPERBALL=build/release/src/superball /usr/bin/python3 tests/launchers/test_jobs.py -v
"""

import functools
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
from superball_testing import superball_binary, mpi_env  # noqa: E402

SOURCE = os.path.abspath(os.environ.get("SUPERBALL_SOURCE_DIR") or os.path.join(os.path.dirname(__file__), "..", ".."))
JOBS = os.path.join(SOURCE, "jobs")

# The catalogue: the same names in jobs/quick and jobs/full.
CATALOGUE = [
    "physical_x_omega",
    "physical_u_v",
    "canonical_xi_W_U-0.5",
    "canonical_xi_W_U-1",
    "canonical_xi_W_U-2",
    "canonical_U_W_xi-0.1",
    "canonical_U_W_xi-0.5",
    "canonical_xi_U_W-1",
    "canonical_xi_U_W-0",
    "boundary_xi0",
    "boundary_xi1",
    "plane_xi0",
    "plane_xi1",
    "volume",
]
# A quick job must finish in seconds on 2 cores; this bound leaves room for a loaded machine.
QUICK_SECONDS = 30
QUICK_MAX_POINTS = {2: 256 * 256, 3: 64**3}
FULL_MIN_POINTS = {2: 4096 * 4096, 3: 512**3}


@functools.lru_cache(maxsize=None)
def dry_run(job):
    """Runs `superball explore JOB --dry-run` from the repository root; returns the key: value lines."""
    r = subprocess.run([superball_binary(), "explore", job, "--dry-run"], cwd=SOURCE, capture_output=True,
                       text=True, timeout=60)
    if r.returncode != 0:
        raise AssertionError(f"{job}: --dry-run exit status {r.returncode}\n{r.stdout}{r.stderr}")
    plan = {}
    for line in r.stdout.splitlines():
        key, sep, value = line.partition(": ")
        if sep:
            plan[key] = value
    return plan


def jobs_in(folder):
    return sorted(f[:-5] for f in os.listdir(os.path.join(JOBS, folder)) if f.endswith(".toml"))


class Catalogue(unittest.TestCase):
    def test_quick_and_full_hold_the_same_jobs(self):
        self.assertEqual(jobs_in("quick"), sorted(CATALOGUE))
        self.assertEqual(jobs_in("full"), sorted(CATALOGUE))

    def test_every_job_says_what_it_makes(self):
        for folder in ("quick", "full"):
            for name in jobs_in(folder):
                with self.subTest(job=f"{folder}/{name}"):
                    with open(os.path.join(JOBS, folder, name + ".toml")) as f:
                        text = f.read()
                    header = text.split("\n\n", 1)[0]
                    self.assertTrue(all(line.startswith("#") for line in header.splitlines()), header)
                    self.assertRegex(header, r"(?i)variant: .* points; about .* s on 2 cores")


class DryRun(unittest.TestCase):
    def check_folder(self, folder, output_dir):
        """Checks every job of the folder with --dry-run; returns {name: plan} of the valid ones."""
        plans = {}
        for name in jobs_in(folder):
            with self.subTest(job=f"{folder}/{name}"):
                plan = dry_run(os.path.join("jobs", folder, name + ".toml"))
                self.assertEqual(plan["job"], "valid")
                self.assertEqual(plan["output"], f"{output_dir}/{name}.h5")
                self.assertEqual(plan["max_bounces"], "1000")
                plans[name] = plan
        return plans

    def test_quick_jobs_are_valid_and_small(self):
        for name, plan in self.check_folder("quick", "results").items():
            with self.subTest(job=name):
                axes = sum(k.startswith("axis ") for k in plan)
                self.assertLessEqual(int(plan["points"]), QUICK_MAX_POINTS[axes])

    def test_full_jobs_are_valid_and_fine(self):
        for name, plan in self.check_folder("full", "results/full").items():
            with self.subTest(job=name):
                axes = sum(k.startswith("axis ") for k in plan)
                self.assertEqual(axes, 3 if name == "volume" else 2)
                self.assertGreaterEqual(int(plan["points"]), FULL_MIN_POINTS[axes])

    def test_quick_and_full_differ_only_in_resolution(self):
        def grid(plan):
            return {k: re.sub(r"^\d+ samples", "N samples", v) for k, v in plan.items()
                    if k.startswith(("axis ", "fixed ", "model", "coordinates"))}

        for name in CATALOGUE:
            with self.subTest(job=name):
                quick = dry_run(os.path.join("jobs", "quick", name + ".toml"))
                full = dry_run(os.path.join("jobs", "full", name + ".toml"))
                self.assertEqual(grid(quick), grid(full))


class QuickJobsRun(unittest.TestCase):
    def test_every_quick_job_runs_in_seconds_to_a_complete_result(self):
        mpirun = os.environ.get("MPIEXEC") or "mpirun"
        with tempfile.TemporaryDirectory(prefix="superball-jobs-") as tmp:
            for name in jobs_in("quick"):
                with self.subTest(job=name):
                    out = os.path.join(tmp, name + ".h5")
                    job = os.path.join(JOBS, "quick", name + ".toml")
                    start = time.monotonic()
                    r = subprocess.run([mpirun, "-n", "2", "--oversubscribe", superball_binary(), "explore", job,
                                        "-o", out, "-q"], cwd=tmp, env=mpi_env(), capture_output=True, text=True,
                                       timeout=120)
                    seconds = time.monotonic() - start
                    self.assertEqual(r.returncode, 0, r.stderr)
                    self.assertLess(seconds, QUICK_SECONDS, f"{name} took {seconds:.1f} s: not a quick job")
                    with h5py.File(out, "r") as f:
                        self.assertEqual(int(f.attrs["complete"]), 1)
                        self.assertEqual(int(f.attrs["mpi_ranks"]), 2)
                        self.assertEqual(f.attrs["superball_file"], "result")
                        counts = f["wall_bounces"][...]
                        self.assertEqual(f["outcome"].shape, counts.shape)
                    self.assertFalse(os.path.exists(out + ".partial"))
                    # A figure worth drawing: the ranges hold several wall-bounce counts.
                    self.assertGreaterEqual(len(np.unique(counts)), 4, f"{name}: counts {np.unique(counts)}")
                    print(f"  {name}: {seconds:.2f} s", file=sys.stderr)


class Scripts(unittest.TestCase):
    def run_script(self, *args):
        return subprocess.run(list(args), cwd=SOURCE, capture_output=True, text=True, timeout=60)

    def test_local_sh_help(self):
        r = self.run_script(os.path.join(JOBS, "local.sh"), "--help")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("local.sh JOB.toml", r.stdout)

    def test_bifurcation_sh_runs_continuation_and_draws(self):
        r = self.run_script(os.path.join(JOBS, "bifurcation.sh"), "--help")
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("bifurcation.sh NAME OPTIONS", r.stdout)
        self.assertEqual(self.run_script(os.path.join(JOBS, "bifurcation.sh"), "only-a-name").returncode, 2)
        with tempfile.TemporaryDirectory() as results:
            env = {**mpi_env(), "SUPERBALL": superball_binary(), "SUPERBALL_RESULTS": results, "SUPERBALL_RANKS": "2",
                   "OMPI_MCA_rmaps_base_oversubscribe": "1"}
            r = subprocess.run([os.path.join(JOBS, "bifurcation.sh"), "corner", "--e", "0.9", "--alpha", "0.99",
                                "--param", "alpha", "--min", "0.97", "--max", "1", "--start", "0,-1.077,-2.595"],
                               cwd=SOURCE, capture_output=True, text=True, timeout=120, env=env)
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertEqual(sorted(os.listdir(results)), ["corner.csv", "corner.pdf", "corner.png"])
            with open(os.path.join(results, "corner.csv")) as f:
                text = f.read()
            self.assertIn("on 2 ranks", text)
            self.assertIn("neimark_sacker", text)
            self.assertIn("branch_point", text)

    def test_batch_scripts_help_and_syntax(self):
        for script in ("slurm/explore.sbatch", "pbs/explore.pbs"):
            with self.subTest(script=script):
                path = os.path.join(JOBS, script)
                self.assertTrue(os.access(path, os.X_OK), f"{script} is not executable")
                self.assertEqual(self.run_script("bash", "-n", path).returncode, 0)
                r = self.run_script(path, "--help")
                self.assertEqual(r.returncode, 0, r.stderr)
                self.assertIn("--resume", r.stdout)
                self.assertIn("SIGTERM", r.stdout)

    def test_sbatch_script_asks_for_the_signal_and_requeue(self):
        with open(os.path.join(JOBS, "slurm", "explore.sbatch")) as f:
            directives = [line.split()[1] for line in f if line.startswith("#SBATCH")]
        self.assertIn("--signal=B:TERM@120", directives)
        self.assertIn("--requeue", directives)


if __name__ == "__main__":
    superball_testing_main()
