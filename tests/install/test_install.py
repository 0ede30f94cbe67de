"""`cmake --install BUILD --prefix P`: what cluster users and admins get (environment modules,
Spack). The installed program, Python module, batch script and CMake package work from P
alone: run with a clean environment from elsewhere, nothing refers to the build tree, and C++
code outside the project builds against find_package(superball)."""
import glob
import os
import re
import shutil
import subprocess
import sys
import tempfile
import unittest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from superball_testing import main as superball_testing_main  # noqa: E402
from superball_testing import SOURCE, cmake_cache_value, mpi_env  # noqa: E402

BUILD = os.environ.get("SUPERBALL_BUILD_DIR", "")
PYTHON = os.environ.get("SUPERBALL_PYTHON", "/usr/bin/python3")
JOB = """[model]
e = 0.9
alpha = 0.9

[grid]
xi = { min = 0.0, max = 1.0, n = 64 }
U = -1.0
W = { min = -3.0, max = 3.0, n = 48 }

[run]
max_bounces = 1000
output = "results/installed.h5"
"""


class Installed(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        if not BUILD or not os.path.isfile(os.path.join(BUILD, "CMakeCache.txt")):
            raise unittest.SkipTest("SUPERBALL_BUILD_DIR names no build tree (ctest sets it)")
        if cmake_cache_value(BUILD, "SUPERBALL_SANITIZE") == "ON":
            # The sanitized program and module need the sanitizer's runtime preloaded: not
            # what is installed for users; the release stage tests the installation.
            raise unittest.SkipTest("a sanitized build is not installed for users")
        cls.tmp = tempfile.mkdtemp(prefix="superball-install-")
        cls.prefix = os.path.join(cls.tmp, "prefix")
        r = subprocess.run(["cmake", "--install", BUILD, "--prefix", cls.prefix], capture_output=True, text=True)
        assert r.returncode == 0, r.stdout + r.stderr
        cls.work = os.path.join(cls.tmp, "work")
        os.makedirs(cls.work)
        with open(os.path.join(cls.work, "job.toml"), "w") as f:
            f.write(JOB)
        # A clean environment: nothing of the build tree or the repository on any path.
        cls.env = {k: v for k, v in mpi_env().items() if not k.startswith(("SUPERBALL", "PYTHON", "LD_"))}
        cls.env["PATH"] = "/usr/bin:/bin"

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def run_here(self, *cmd, env=None):
        r = subprocess.run(list(cmd), cwd=self.work, capture_output=True, text=True, env=env or self.env, timeout=300)
        self.assertEqual(r.returncode, 0, f"{' '.join(cmd)}\n{r.stdout}\n{r.stderr}")
        return r

    def test_layout_and_no_reference_to_the_build_tree(self):
        python_dir = glob.glob(os.path.join(self.prefix, "lib", "python3*", "site-packages", "superball"))
        self.assertEqual(len(python_dir), 1)
        for path in ["bin/superball", "share/superball/jobs/slurm/explore.sbatch", "share/superball/jobs/pbs/explore.pbs",
                     "share/superball/analysis/region_map.py", "share/superball/analysis/superball_results.py",
                     "lib/cmake/superball/superballConfig.cmake", "include/superball/superball.hpp",
                     "lib/libsuperball_api.a", "lib/libsuperball_run.a"]:
            self.assertTrue(os.path.exists(os.path.join(self.prefix, path)), path)
        # The public header alone: no internal one is installed.
        headers = [os.path.relpath(os.path.join(d, f), self.prefix) for d, _, files in os.walk(os.path.join(self.prefix, "include"))
                   for f in files]
        self.assertEqual(headers, ["include/superball/superball.hpp"])
        for name in ("__init__.py", "__init__.pyi", "py.typed"):
            self.assertTrue(os.path.exists(os.path.join(python_dir[0], name)), name)
        binaries = [os.path.join(self.prefix, "bin", "superball")] + glob.glob(os.path.join(python_dir[0], "_core*.so"))
        self.assertEqual(len(binaries), 2)
        for b in binaries:
            dynamic = subprocess.run(["readelf", "-d", b], capture_output=True, text=True).stdout
            self.assertNotIn(os.path.realpath(BUILD), dynamic, b)  # no RPATH into the build tree
            self.assertNotIn("RPATH", dynamic.replace("RUNPATH", ""), b)

    def test_program_explores_from_the_prefix(self):
        superball = os.path.join(self.prefix, "bin", "superball")
        self.run_here(superball, "explore", "job.toml", "-q")
        r = self.run_here(superball, "info", "results/installed.h5")
        self.assertIn("history:", r.stdout)
        self.assertIn("superball explore job.toml -q", r.stdout)
        r = self.run_here(os.environ.get("MPIEXEC", "mpiexec"), "-n", "2", "--oversubscribe", superball, "explore",
                          "job.toml", "-o", "two.h5", "-q")

    def test_batch_script_finds_the_installed_program(self):
        env = dict(self.env, SLURM_NTASKS="1")
        r = self.run_here("bash", os.path.join(self.prefix, "share", "superball", "jobs", "slurm", "explore.sbatch"),
                          "job.toml", "-o", "batch.h5", "-q", env=env)
        used = re.search(r"ranks: (\S+) explore", r.stderr)
        self.assertIsNotNone(used, r.stderr)
        self.assertEqual(os.path.realpath(used.group(1)), os.path.realpath(os.path.join(self.prefix, "bin", "superball")))
        self.assertTrue(os.path.exists(os.path.join(self.work, "batch.h5")))

    def test_python_module_from_the_prefix(self):
        (python_dir,) = glob.glob(os.path.join(self.prefix, "lib", "python3*", "site-packages"))
        env = dict(self.env, PYTHONPATH=python_dir)
        code = ("import superball, sys\n"
                "assert superball.__file__.startswith(sys.argv[1]), superball.__file__\n"
                "print(superball.count(0.05, -1, -2, e=0.9, alpha=0.9))\n"
                "ds = superball.explore('job.toml', 'module.h5', threads=2)\n"
                "print(ds['wall_bounces'].shape, ds.attrs['threads'])\n")
        r = self.run_here(PYTHON, "-c", code, python_dir, env=env)
        self.assertIn("Counts(wall_bounces=8, outcome=Outcome.left)", r.stdout)
        self.assertIn("(64, 48) 2", r.stdout)

    def test_cmake_package_links_the_library(self):
        build = os.path.join(self.tmp, "consumer")
        self.run_here("cmake", "-S", os.path.join(SOURCE, "tests", "install", "consumer"), "-B", build,
                      f"-DCMAKE_PREFIX_PATH={self.prefix}", "-DCMAKE_BUILD_TYPE=Release")
        self.run_here("cmake", "--build", build, "-j2")
        superball = os.path.join(self.prefix, "bin", "superball")
        self.run_here(superball, "explore", "job.toml", "-o", "for_consumer.h5", "-q")
        r = self.run_here(os.path.join(build, "consumer"), "for_consumer.h5")
        self.assertIn("count 8 left", r.stdout)
        self.assertIn("threads 8", r.stdout)
        self.assertIn("refused: e = 1.5 is out of range", r.stdout)
        self.assertIn("points 3072", r.stdout)
        self.assertIn("complete", r.stdout)


if __name__ == "__main__":
    superball_testing_main()
