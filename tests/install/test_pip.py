"""`pip install --no-build-isolation .` (pyproject.toml, setup.py): in a fresh venv made with
--system-site-packages (its numpy, h5py and xarray are the system's), from a copy of the
repository as a clone has it, the module is built by CMake for the venv's interpreter and
installed with its stubs; imported from another folder it counts and opens a result. The
copy builds the module's libraries from nothing, at -O0 and with clang++ where it is installed
(.ci/install-deps --dev, which tests/all runs), through SUPERBALL_PIP_CMAKE_ARGS (setup.py): what
is tested is the installation, and every build of superball counts alike (-ffp-contract=off).
-O0 took 98 CPU-seconds where Release's -O3 took 136 (2026-11-29, `cmake --build --target
superball_python -j2` of a fresh tree, one after the other); clang at -O0 59 against GCC's 118
(2026-11-29, the same way), and the package is then built by a second compiler."""
import glob
import os
import shlex
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


class PipInstall(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        built = BUILD and os.path.isfile(os.path.join(BUILD, "CMakeCache.txt"))
        if built and cmake_cache_value(BUILD, "SUPERBALL_SANITIZE") == "ON":
            raise unittest.SkipTest("pip builds a release module; the sanitized stage does not install it")
        listed = subprocess.run(["git", "-C", SOURCE, "ls-files", "-z", "--cached", "--others", "--exclude-standard"],
                                capture_output=True)
        if listed.returncode != 0:
            raise unittest.SkipTest(f"{SOURCE} is not a git checkout: no clone to copy")
        cls.tmp = tempfile.mkdtemp(prefix="superball-pip-")
        # The files a clone has (tracked, and new ones not ignored): no build tree, no results.
        cls.clone = os.path.join(cls.tmp, "clone")
        for name in filter(None, listed.stdout.decode().split("\0")):
            source = os.path.join(SOURCE, name)
            if not os.path.isfile(source):
                continue  # deleted in the working tree
            os.makedirs(os.path.dirname(os.path.join(cls.clone, name)), exist_ok=True)
            shutil.copy2(source, os.path.join(cls.clone, name))
        cls.venv = os.path.join(cls.tmp, "venv")
        cls.env = {k: v for k, v in mpi_env().items() if not k.startswith(("SUPERBALL", "PYTHON", "LD_"))}
        cls.env["PATH"] = os.path.join(cls.venv, "bin") + ":/usr/bin:/bin"
        cls.compiler = shutil.which("clang++")
        cmake_args = ["-DCMAKE_CXX_FLAGS_RELEASE=-O0 -DNDEBUG"]
        if cls.compiler:
            cmake_args.append(f"-DCMAKE_CXX_COMPILER={cls.compiler}")
        print(f"pip builds with {cls.compiler or 'the default C++ compiler'}", file=sys.stderr)
        cls.env["SUPERBALL_PIP_CMAKE_ARGS"] = shlex.join(cmake_args)
        cls.run_in(cls.tmp, PYTHON, "-m", "venv", "--system-site-packages", cls.venv)
        cls.python = os.path.join(cls.venv, "bin", "python")
        # --no-index: nothing from the network; numpy comes from the system's site packages.
        cls.install = cls.run_in(cls.clone, cls.python, "-m", "pip", "install", "--no-build-isolation", "--no-index", ".",
                                 timeout=1800)
        cls.work = os.path.join(cls.tmp, "elsewhere")
        os.makedirs(cls.work)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    @classmethod
    def run_in(cls, where, *cmd, timeout=300):
        r = subprocess.run(list(cmd), cwd=where, capture_output=True, text=True, env=cls.env, timeout=timeout)
        assert r.returncode == 0, f"{' '.join(cmd)}\n{r.stdout[-4000:]}\n{r.stderr[-4000:]}"
        return r

    def test_installed_into_the_venv_with_its_stubs(self):
        (package,) = glob.glob(os.path.join(self.venv, "lib", "python3*", "site-packages", "superball"))
        for name in ("__init__.py", "__init__.pyi", "_core.pyi", "py.typed"):
            self.assertTrue(os.path.exists(os.path.join(package, name)), name)
        self.assertEqual(len(glob.glob(os.path.join(package, "_core*.so"))), 1)
        r = self.run_in(self.work, self.python, "-m", "pip", "show", "superball")
        self.assertIn("Name: superball", r.stdout)

    def test_cmake_args_reach_the_build(self):
        (build,) = glob.glob(os.path.join(self.clone, "build", "pip-*"))
        self.assertEqual(cmake_cache_value(build, "CMAKE_CXX_FLAGS_RELEASE"), "-O0 -DNDEBUG")
        if self.compiler:
            self.assertEqual(cmake_cache_value(build, "CMAKE_CXX_COMPILER"), self.compiler)

    def test_counts_and_opens_a_result_from_another_folder(self):
        code = ("import superball, sys\n"
                "assert superball.__file__.startswith(sys.argv[1]), superball.__file__\n"
                "print(superball.count(0.05, -1, -2, e=0.9, alpha=0.9))\n"
                "job = {'model': {'e': 0.9, 'alpha': 0.9}, 'grid': {'xi': {'min': 0.0, 'max': 1.0, 'n': 32},\n"
                "       'U': -1.0, 'W': {'min': -3.0, 'max': 3.0, 'n': 24}}}\n"
                "superball.explore(job, 'r.h5', threads=2).close()\n"
                "ds = superball.open('r.h5')\n"
                "print(ds['wall_bounces'].shape, superball.__version__)\n")
        r = self.run_in(self.work, self.python, "-c", code, self.venv)
        self.assertIn("Counts(wall_bounces=8, outcome=Outcome.left)", r.stdout)
        self.assertIn("(32, 24)", r.stdout)


if __name__ == "__main__":
    superball_testing_main()
