"""Helpers shared by the Python end-to-end tests: where the binary is, the environment
mpirun needs, the processes below mpirun, and how fast the binary under test is."""
import os
import subprocess
import unittest

SOURCE = os.environ.get("SUPERBALL_SOURCE_DIR") or os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def superball_binary():
    """The binary under test: $SUPERBALL (set by ctest), else a build of this repository."""
    path = os.environ.get("SUPERBALL")
    if path:
        return os.path.abspath(path)
    for build in ("build/release", "build/native"):
        candidate = os.path.join(SOURCE, build, "src", "superball")
        if os.access(candidate, os.X_OK):
            return candidate
    raise unittest.SkipTest("no superball binary: set SUPERBALL")


def mpi_env():
    """The environment for mpirun: Open MPI refuses to run as root unless told."""
    env = dict(os.environ)
    if os.geteuid() == 0:
        env.update(OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    return env


def descendants(pid):
    """Every process below `pid`: Open MPI puts its ranks in process groups of their own,
    so signalling mpirun's group does not reach them."""
    children = {}
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                with open(f"/proc/{entry}/stat") as f:
                    ppid = int(f.read().rsplit(")", 1)[1].split()[1])
            except (OSError, IndexError, ValueError):
                continue
            children.setdefault(ppid, []).append(int(entry))
    found, todo = [], [pid]
    while todo:
        for child in children.get(todo.pop(), []):
            found.append(child)
            todo.append(child)
    return found


# Every point capped: around the marginally stable self-retracing motion (0.25, -0.5,
# -1.25) of the dissipation-free model.
_CALIBRATION_JOB = """[model]
e = 1.0
alpha = 1.0

[grid]
xi = { min = 0.24, max = 0.26, n = 2 }
U = -0.5
W = { min = -1.27, max = -1.23, n = 2 }

[run]
max_bounces = %d
"""


def wall_impacts_per_second(binary, directory):
    """Wall impacts per second of one rank of `binary`, from the summary of a run in which
    every point is capped (max_bounces raised until it takes a quarter of a second). Tests
    that must stop a run part-way size their jobs with it, so that the runs last the same
    few seconds in a release build and under AddressSanitizer."""
    job, out = os.path.join(directory, "calibrate.toml"), os.path.join(directory, "calibrate.h5")
    max_bounces = 100000
    while True:
        with open(job, "w") as f:
            f.write(_CALIBRATION_JOB % max_bounces)
        r = subprocess.run([binary, "explore", job, "-o", out, "--overwrite"], capture_output=True, text=True,
                           env=mpi_env(), timeout=300)
        assert r.returncode == 0, r.stderr
        seconds = float(r.stderr.split("done: 4 points computed in ")[1].split()[0])
        if seconds >= 0.25 or max_bounces >= 10**9:
            return 4 * max_bounces / max(seconds, 0.01)
        max_bounces *= 4
