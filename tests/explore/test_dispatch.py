#!/usr/bin/python3
"""End-to-end tests of what one portable binary decides at start-up: the counting kernel
variant (`--kernel`, SUPERBALL_KERNEL, `superball --version`), with identical result files
from every variant this processor runs, and Open MPI's point-to-point layer for runs on one
node (ob1, and no daemon for a singleton, unless the user chose)."""
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
from superball_testing import mpi_env, superball_binary  # noqa: E402

MPIEXEC = os.environ.get("MPIEXEC") or "mpirun"

# The benchmark slice's region at 200 x 150, with points of every outcome.
JOB = """[model]
e = 0.9
alpha = 0.9

[grid]
xi = { min = 0.0, max = 1.0, n = 200 }
U = -1.0
W = { min = -3.0, max = 3.0, n = 150 }

[run]
max_bounces = 1000
tile_points = 4096
"""


def env_without(*names, **extra):
    env = mpi_env()
    for name in names:
        env.pop(name, None)
    env.update(extra)
    return env


def version_report(env=None):
    r = subprocess.run([superball_binary(), "--version"], capture_output=True, text=True, env=env or env_without(
        "SUPERBALL_KERNEL"), timeout=60)
    assert r.returncode == 0, r.stderr
    return r.stdout


def runnable_variants():
    m = re.search(r"this processor runs: ([a-z0-9, ]+)", version_report())
    return [v.strip() for v in m.group(1).split(",")]


class KernelDispatch(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp(prefix="superball-dispatch-")
        self.job = os.path.join(self.dir, "job.toml")
        with open(self.job, "w") as f:
            f.write(JOB)

    def tearDown(self):
        shutil.rmtree(self.dir, ignore_errors=True)

    def explore(self, output, extra=(), env=None, expect=0):
        cmd = [superball_binary(), "explore", self.job, "-o", output, *extra]
        r = subprocess.run(cmd, capture_output=True, text=True, env=env or env_without("SUPERBALL_KERNEL"), timeout=300)
        self.assertEqual(r.returncode, expect, f"{' '.join(cmd)}\n{r.stderr}")
        return r

    def results(self, path):
        with h5py.File(path, "r") as f:
            return f["wall_bounces"][()], f["outcome"][()]

    def test_version_names_the_kernel_in_use(self):
        report = version_report()
        self.assertRegex(report, r"^superball \d+\.\d+\.\d+\n")
        self.assertRegex(report, r"counting kernel: [a-z0-9]+ \([^,]+, \d+ lanes\); compiled in: ")
        self.assertIn("counting kernel: scalar;", version_report(env_without(SUPERBALL_KERNEL="scalar")))

    def test_every_variant_gives_the_same_file(self):
        variants = runnable_variants()
        self.assertTrue(variants)
        reference = os.path.join(self.dir, "scalar.h5")
        r = self.explore(reference, ["--kernel", "scalar"])
        self.assertIn("counting kernel: scalar\n", r.stderr)
        expected = self.results(reference)
        for variant in variants + ["simd"]:
            with self.subTest(variant=variant):
                out = os.path.join(self.dir, f"{variant}.h5")
                r = self.explore(out, ["--kernel", variant])
                if variant != "simd":
                    self.assertRegex(r.stderr, rf"counting kernel: {variant} \(")
                got = self.results(out)
                np.testing.assert_array_equal(got[0], expected[0])
                np.testing.assert_array_equal(got[1], expected[1])
        # The environment variable chooses when the flag does not, under mpirun too.
        out = os.path.join(self.dir, "env.h5")
        r = subprocess.run([MPIEXEC, "-n", "2", "--oversubscribe", superball_binary(), "explore", self.job, "-o", out],
                           capture_output=True, text=True, env=env_without(SUPERBALL_KERNEL=variants[0]), timeout=300)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertRegex(r.stderr, rf"counting kernel: {variants[0]} \(")
        got = self.results(out)
        np.testing.assert_array_equal(got[0], expected[0])
        np.testing.assert_array_equal(got[1], expected[1])

    def test_refusals_name_what_this_processor_runs(self):
        out = os.path.join(self.dir, "r.h5")
        accepted = "accepted here: simd (here " + runnable_variants()[-1] + "), scalar, " + ", ".join(
            runnable_variants())
        r = self.explore(out, ["--kernel", "sse9"], expect=2)
        self.assertIn("--kernel sse9: unknown kernel 'sse9'", r.stderr)
        self.assertIn(accepted, r.stderr)
        r = self.explore(out, env=env_without(SUPERBALL_KERNEL="avx1024"), expect=2)
        self.assertIn("SUPERBALL_KERNEL=avx1024: unknown kernel", r.stderr)
        self.assertFalse(os.path.exists(out))
        # A variant of this build the processor lacks (none on a processor with AVX-512).
        m = re.search(r"compiled in: ([a-z0-9, ]+);", version_report())
        missing = [v.strip() for v in m.group(1).split(",") if v.strip() not in runnable_variants()]
        for variant in missing:
            r = self.explore(out, ["--kernel", variant], expect=2)
            self.assertIn(f"this processor cannot run the {variant} kernel", r.stderr)
            self.assertIn(accepted, r.stderr)


class SingleNodeStartUp(unittest.TestCase):
    """What Open MPI does at start-up, from its own log: which point-to-point layers it
    opens (pml_base_verbose; only ob1 when superball chose it) and whether a singleton
    starts a daemon (ess_base_verbose: the daemon's "hnp" component)."""

    def setUp(self):
        self.dir = tempfile.mkdtemp(prefix="superball-startup-")
        self.job = os.path.join(self.dir, "job.toml")
        with open(self.job, "w") as f:
            f.write(JOB.replace("n = 200", "n = 8").replace("n = 150", "n = 8"))

    def tearDown(self):
        shutil.rmtree(self.dir, ignore_errors=True)

    def log(self, launcher, **env):
        out = os.path.join(self.dir, "r.h5")
        cmd = [*launcher, superball_binary(), "explore", self.job, "-o", out, "--overwrite", "-q"]
        # HOME elsewhere: no ~/.openmpi/mca-params.conf of the user running the tests.
        r = subprocess.run(cmd, capture_output=True, text=True, timeout=120,
                           env=env_without("OMPI_MCA_pml", "OMPI_MCA_ess_singleton_isolated",
                                           "OMPI_MCA_mca_base_param_files", HOME=self.dir,
                                           OMPI_MCA_pml_base_verbose="10", OMPI_MCA_ess_base_verbose="10", **env))
        self.assertEqual(r.returncode, 0, r.stderr)
        log = r.stdout + r.stderr
        if "components_open" not in log:
            self.skipTest("this MPI does not log its components (not Open MPI?)")
        return log

    def opened(self, launcher, **env):
        names = set(re.findall(r"components_open: found loaded component (\w+)", self.log(launcher, **env)))
        return names & {"ob1", "cm", "ucx", "v", "monitoring"}

    def test_singleton_and_one_node_mpirun_use_ob1(self):
        self.assertEqual(self.opened([]), {"ob1"})
        self.assertEqual(self.opened([MPIEXEC, "-n", "2", "--oversubscribe"]), {"ob1"})

    def test_singleton_starts_no_daemon(self):
        self.assertNotIn("component hnp", self.log([]))
        self.assertIn("component hnp", self.log([], OMPI_MCA_ess_singleton_isolated="0"))

    def test_singletons_started_together_all_run(self):
        """Isolated singletons share Open MPI's job family 0: without a session directory of
        their own, one that removes <tmp>/ompi.*/jf.0 as it ends makes another's start fail.
        Each gets its own under TMPDIR, gone when it ends."""
        tmp = os.path.join(self.dir, "tmp")
        os.makedirs(tmp)
        env = env_without("OMPI_MCA_pml", "OMPI_MCA_ess_singleton_isolated", "OMPI_MCA_orte_tmpdir_base",
                          HOME=self.dir, TMPDIR=tmp)
        # Short runs (a job refused for its output, which exists) end while others start:
        # the race is in the start and the end.
        existing = os.path.join(self.dir, "exists.h5")
        open(existing, "w").close()
        for _ in range(5):
            runs = [subprocess.Popen([superball_binary(), "explore", self.job, "-o", existing, "-q"], env=env,
                                     stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True) for i in range(8)]
            for r in runs:
                _, err = r.communicate(timeout=120)
                self.assertEqual(r.returncode, 2, err)
                self.assertIn("exists.h5", err)
            self.assertEqual(os.listdir(tmp), [])

    def test_the_users_choice_stands(self):
        self.assertGreater(len(self.opened([], OMPI_MCA_pml="^ucx")), 1)
        self.assertGreater(len(self.opened([MPIEXEC, "-n", "2", "--oversubscribe", "--mca", "pml", "^ucx"])), 1)
        os.makedirs(os.path.join(self.dir, ".openmpi"))
        with open(os.path.join(self.dir, ".openmpi", "mca-params.conf"), "w") as f:
            f.write("pml = ^ucx\n")
        self.assertGreater(len(self.opened([])), 1)


if __name__ == "__main__":
    superball_testing_main()
