"""Shared by the Python module's tests (pytest; ctest runs each file, label python): the
module under test comes from PYTHONPATH (ctest: the build tree's python/ directory), the
command line from $SUPERBALL, MPI's launcher from $MPIEXEC."""
import os
import subprocess
import sys

import pytest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from superball_testing import SOURCE, mpi_env, superball_binary  # noqa: E402

SHARED_REFERENCE = os.path.join(SOURCE, "..", "shared", "reference")
REFERENCE = os.environ.get("SUPERBALL_REFERENCE_DIR") or os.path.join(SOURCE, "tests", "reference")


def run_cli(*args, ranks=0, check=True, timeout=300):
    """`superball ARGS` (under mpiexec -n RANKS when ranks > 0): the completed process."""
    cmd = [superball_binary(), *map(str, args)]
    if ranks:
        cmd = [os.environ.get("MPIEXEC", "mpiexec"), "-n", str(ranks), "--oversubscribe", *cmd]
    r = subprocess.run(cmd, capture_output=True, text=True, env=mpi_env(), timeout=timeout)
    if check:
        assert r.returncode == 0, f"{' '.join(cmd)}\n{r.stderr}"
    return r


@pytest.fixture(scope="session")
def superball():
    import superball as module

    return module


def pytest_sessionfinish(session, exitstatus):
    """Every test of the file skipped: exit 77, which ctest reports as skipped
    (SKIP_RETURN_CODE in tests/CMakeLists.txt), not as passed."""
    reporter = session.config.pluginmanager.get_plugin("terminalreporter")
    if exitstatus == 0 and reporter is not None and session.testscollected > 0:
        if len(reporter.stats.get("skipped", [])) == session.testscollected:
            session.exitstatus = 77
