"""`pip install .` (pyproject.toml): the package src/python/superball and its extension
superball._core, which CMake builds, as the rest of superball, for the interpreter running
this file (-DPython_EXECUTABLE=sys.executable): a conda or venv interpreter gets a module
built for it, not for the one CMake would find on its own.

A setup.py beside pyproject.toml because Debian 12's setuptools (66) cannot declare an
extension module in pyproject.toml (that came in setuptools 74, experimental): without one
the wheel would be tagged pure Python. setuptools compiles nothing here: the extension is the CMake target superball_python (the
build's flags, its kernel variants, the libraries it links) and only its file is copied into
the wheel. Environment:
    SUPERBALL_PIP_BUILD_DIR  the CMake build tree to use (default build/pip-<interpreter tag>:
                             kept, so that a second install rebuilds only what changed)
    SUPERBALL_PIP_JOBS       parallel compile jobs (default: the cores this process may use)
    SUPERBALL_PIP_CMAKE_ARGS more CMake options, split as a shell would, after setup.py's own
                             (which they override), e.g. "-DSUPERBALL_NATIVE=ON" for a module
                             compiled for this processor only (docs/building.md)
"""
import os
import re
import shlex
import shutil
import subprocess
import sys
import sysconfig

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = os.path.dirname(os.path.abspath(__file__))


def version():
    """The version CMakeLists.txt gives the project, so that both say the same."""
    with open(os.path.join(ROOT, "CMakeLists.txt"), encoding="utf-8") as f:
        found = re.search(r"project\(superball VERSION ([0-9.]+)", f.read())
    if not found:
        raise RuntimeError("no `project(superball VERSION x.y.z` in CMakeLists.txt")
    return found.group(1)


class CMakeBuild(build_ext):
    """Builds superball._core with CMake and copies it to where setuptools packs it."""

    def build_extension(self, ext):
        cmake = shutil.which("cmake")
        if cmake is None:
            raise RuntimeError("pip install superball needs cmake (Debian: .ci/install-deps installs it)")
        tag = sysconfig.get_config_var("SOABI") or f"py{sys.version_info[0]}{sys.version_info[1]}"
        build = os.environ.get("SUPERBALL_PIP_BUILD_DIR") or os.path.join(ROOT, "build", f"pip-{tag}")
        jobs = os.environ.get("SUPERBALL_PIP_JOBS") or str(len(os.sched_getaffinity(0)))
        # A new tree is configured for Ninja where it is installed: it compiles the libraries
        # side by side, where Make builds them one after the other (docs/building.md). A tree
        # configured before keeps its generator (CMake cannot change it).
        generator = []
        if shutil.which("ninja") and not os.path.exists(os.path.join(build, "CMakeCache.txt")):
            generator = ["-G", "Ninja"]
        # Only what the module needs: no tests, no benchmarks.
        subprocess.run([cmake, "-S", ROOT, "-B", build, *generator, "-DCMAKE_BUILD_TYPE=Release", f"-DPython_EXECUTABLE={sys.executable}",
                        "-DSUPERBALL_PYTHON_MODULE=ON", "-DSUPERBALL_TESTS=OFF", "-DSUPERBALL_BENCHMARKS=OFF",
                        *shlex.split(os.environ.get("SUPERBALL_PIP_CMAKE_ARGS", ""))], check=True)
        subprocess.run([cmake, "--build", build, "--target", "superball_python", "-j", jobs], check=True)
        built = os.path.join(build, "python", "superball", os.path.basename(self.get_ext_filename(ext.name)))
        if not os.path.exists(built):
            raise RuntimeError(f"CMake built no {built}: is it configured for {sys.executable}?")
        target = self.get_ext_fullpath(ext.name)
        os.makedirs(os.path.dirname(target), exist_ok=True)
        shutil.copyfile(built, target)


setup(
    version=version(),
    packages=["superball"],
    package_dir={"": "src/python"},
    package_data={"superball": ["*.pyi", "py.typed"]},
    ext_modules=[Extension("superball._core", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
    zip_safe=False,
)
